// test_traversal.cpp: the ray-query traversal against the GLSL BVH as its oracle (stage trace_tool
// compiled both ways, shaders/shared/trace.glsl): on the same random rays, the same closest hits
// (triangle, t, barycentrics within float tolerances) and the same any-hit answers, on the Cornell
// box and the 100k-triangle dragon; the BVH's shared leaf loads against per-lane loads (the same
// hits bit for bit); and the fallback to the BVH on a device without ray queries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "../support/alpha_layers.h"
#include "../support/test_support.h"
#include "render/device_scene.h"
#include "render/material_table.h"
#include "render/renderer.h"
#include "render/texture_table.h"
#include "scene/bvh.h"
#include "util/error.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

// Float tolerance between two traversals of the same triangles, as a distance in world space
// relative to |o| + t (the magnitude of the operands of a hit at distance t from origin o). Both
// compute t and the barycentrics in float from the same vertices but by different formulas (Moller-
// Trumbore against the driver's test), each within a few ulps of that magnitude (more at grazing
// incidence): 2^-14 leaves a factor of ~500 over one ulp (2^-23). It bounds the difference of the
// hit points (t along the ray, and the barycentrics mapped onto the triangle: small triangles have
// proportionally imprecise barycentrics), and how close to an edge of its triangle a hit must lie
// for the other traversal to be allowed to miss it (only there can the two tests round apart).
constexpr double kRelTol = 1.0 / 16384;

struct Ray {
  glm::vec3 o, d;
  float tmax;
};

struct Hit {
  bool closest = false, any = false;
  float t = 0, b1 = 0, b2 = 0;
  std::uint32_t tri = INVALID_INDEX;
};

// The scene's bounding box, inflated by 10 %: its centre c and half extents h; its diagonal.
float inflatedBox(const Scene& scene, glm::vec3& c, glm::vec3& h) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : scene.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  c = 0.5f * (lo + hi);
  h = 0.55f * (hi - lo);
  return glm::length(hi - lo);
}

// Three kinds of rays with the scene's bounding box B (inflated by 10 %): from random points in B
// in uniform directions (unbounded: closest hit or escape), segments between two random points of
// B (bounded: shadow rays through the scene), and rays leaving random points of random triangles
// (offset along the normal by 1e-4 of the scene size) into the hemisphere of that normal, as the
// path tracer's bounces do.
std::vector<Ray> randomRays(const Scene& scene, std::uint32_t n, std::uint32_t seed) {
  glm::vec3 c, h;
  const float size = inflatedBox(scene, c, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  auto inBox = [&] { return c + h * glm::vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1); };
  auto sphere = [&] {
    for (;;) {
      glm::vec3 v(g(rng), g(rng), g(rng));
      float l = glm::length(v);
      if (l > 1e-3f) return v / l;
    }
  };
  std::vector<Ray> rays(n);
  const std::uint32_t tris = static_cast<std::uint32_t>(scene.triangleCount());
  for (std::uint32_t i = 0; i < n; ++i) {
    Ray& r = rays[i];
    switch (i % 3) {
      case 0:
        r = {inBox(), sphere(), 3.0e38f};
        break;
      case 1: {
        glm::vec3 a = inBox(), b = inBox();
        float l = glm::length(b - a);
        r = {a, (b - a) / l, l};
        break;
      }
      default: {
        std::uint32_t k = std::min(tris - 1, static_cast<std::uint32_t>(u(rng) * float(tris)));
        glm::vec3 p0 = scene.positions[3 * k], p1 = scene.positions[3 * k + 1], p2 = scene.positions[3 * k + 2];
        float s = u(rng), t = u(rng);
        if (s + t > 1) s = 1 - s, t = 1 - t;
        glm::vec3 nrm = glm::normalize(glm::cross(p1 - p0, p2 - p0));
        if (u(rng) < 0.5f) nrm = -nrm;
        glm::vec3 d = sphere();
        if (glm::dot(d, nrm) < 0) d = -d;
        r = {p0 + s * (p1 - p0) + t * (p2 - p0) + 1e-4f * size * nrm, d, 3.0e38f};
      }
    }
  }
  return rays;
}

// Both queries of `module` (trace_tool or trace_tool_rq; with _a the alpha test, which needs the
// scene's materials and the specialization constants `spec`) on every ray.
std::vector<Hit> trace(vk::Context& ctx, const DeviceScene& scene, const std::vector<Ray>& rays, const char* module,
                       const MaterialTable* materials = nullptr, const std::vector<std::uint32_t>& spec = {}) {
  const std::uint32_t n = static_cast<std::uint32_t>(rays.size());
  StageGlobals globals(ctx, STAGE_PUSH_BYTES);
  Globals& g = globals.host();
  scene.fillGlobals(g);
  if (materials) materials->fillGlobals(g);
  vk::Buffer origin = vk::createBuffer(ctx, n * 16ull, 0, true, "ray origin");
  vk::Buffer direction = vk::createBuffer(ctx, n * 16ull, 0, true, "ray direction");
  vk::Buffer hit = vk::createBuffer(ctx, n * 16ull, 0, true, "hit");
  vk::Buffer info = vk::createBuffer(ctx, n * 16ull, 0, true, "hit info");
  vk::Buffer stats = vk::createBuffer(ctx, STAT_COUNT * 4, 0, true, "statistics");
  std::memset(stats.mapped, 0, STAT_COUNT * 4);
  auto* o = static_cast<glm::vec4*>(origin.mapped);
  auto* d = static_cast<glm::vec4*>(direction.mapped);
  for (std::uint32_t i = 0; i < n; ++i) {
    o[i] = glm::vec4(rays[i].o, rays[i].tmax);
    d[i] = glm::vec4(rays[i].d, 0.0f);
  }
  g.shadowOrigin = origin.address;
  g.shadowDirection = direction.address;
  g.pathHit = hit.address;
  g.pathInfo = info.address;
  g.stats = stats.address;
  globals.upload();
  vk::ComputePipeline pipe = vk::createComputePipeline(ctx, globals.layout(), module, spec);
  VkCommandBuffer cmd = vk::beginOneShot(ctx);
  VkDescriptorSet set = globals.set();
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, globals.layout(), 0, 1, &set, 0, nullptr);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.pipeline);
  TraceToolConstants pc{};
  pc.count = n;
  vkCmdPushConstants(cmd, globals.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(cmd, (n + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, 1, 1);
  vk::endOneShot(ctx, cmd);
  std::vector<Hit> out(n);
  auto* h = static_cast<const glm::vec4*>(hit.mapped);
  auto* f = static_cast<const glm::uvec4*>(info.mapped);
  for (std::uint32_t i = 0; i < n; ++i) {
    out[i].any = f[i].x != 0;
    out[i].closest = f[i].y != 0;
    out[i].t = h[i].x;
    out[i].b1 = h[i].y;
    out[i].b2 = h[i].z;
    out[i].tri = shared::floatBitsToUint(h[i].w);
  }
  EXPECT_EQ(static_cast<const std::uint32_t*>(stats.mapped)[STAT_BVH_STACK_OVERFLOW], 0u) << module;
  vk::destroyComputePipeline(ctx, pipe);
  for (vk::Buffer* b : {&origin, &direction, &hit, &info, &stats}) vk::destroyBuffer(ctx, *b);
  return out;
}

// World-space distance from the hit's point to the nearest edge of its triangle: barycentric b_i
// times the triangle's height over the edge opposite vertex i.
double edgeDistance(const Hit& h, const GpuTriangle& t) {
  glm::dvec3 e1(t.e1), e2(t.e2);
  double area2 = glm::length(glm::cross(e1, e2));
  double b0 = 1.0 - h.b1 - h.b2;
  return std::min({b0 * area2 / glm::length(e2 - e1), double(h.b1) * area2 / glm::length(e2),
                   double(h.b2) * area2 / glm::length(e1)});
}

// World-space distance between the points that two barycentric pairs name on one triangle.
double pointDistance(const Hit& a, const Hit& b, const GpuTriangle& t) {
  return glm::length(double(a.b1 - b.b1) * glm::dvec3(t.e1) + double(a.b2 - b.b2) * glm::dvec3(t.e2));
}

void compareTraversals(const std::string& relative, std::uint32_t n, std::uint32_t seed) {
  vk::Context& ctx = test::context();
  if (!ctx.rayQuery) GTEST_SKIP() << ctx.deviceName << " has no ray queries: nothing to compare";
  Scene scene = test::loadTestScene(relative);
  TraversalStructures both;
  both.bvh = true;
  both.accelerationStructures = true;
  DeviceScene device(ctx, scene, both);  // one triangle order for both traversals
  std::vector<Ray> rays = randomRays(scene, n, seed);
  std::vector<Hit> bvh = trace(ctx, device, rays, "trace_tool");
  std::vector<Hit> rq = trace(ctx, device, rays, "trace_tool_rq");
  std::vector<GpuTriangle> tris(scene.triangleCount());
  vk::downloadBuffer(ctx, device.triangleBuffer(), tris.data(), tris.size() * sizeof(GpuTriangle));

  std::uint32_t hits = 0, misses = 0, same = 0, edge = 0, tieAtT = 0, atTmax = 0, unexplained = 0, anyDiffer = 0;
  double worstT = 0, worstB = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Hit &a = bvh[i], &b = rq[i];
    const Ray& r = rays[i];
    const double scale = glm::length(r.o) + (a.closest ? a.t : b.t);
    const double tol = kRelTol * scale;
    // Each traversal agrees with itself: any-hit is closest-hit's existence (the tool uses one interval).
    if (a.any != a.closest || b.any != b.closest) ++anyDiffer;
    (a.closest ? hits : misses)++;
    if (a.closest == b.closest && (!a.closest || a.tri == b.tri)) {
      if (a.closest) {
        const double dp = pointDistance(a, b, tris[a.tri]);
        worstT = std::max(worstT, std::abs(double(a.t) - b.t) / scale);
        worstB = std::max(worstB, dp / scale);
        if (std::abs(double(a.t) - b.t) > tol || dp > tol) {
          ++unexplained;
          ADD_FAILURE() << relative << " ray " << i << ": triangle " << a.tri << " at t " << a.t << " vs " << b.t
                        << ", barycentrics (" << a.b1 << ", " << a.b2 << ") vs (" << b.b1 << ", " << b.b2 << ")";
        }
      }
      ++same;
      continue;
    }
    // They differ. Explained when both hit different triangles at the same distance (a shared
    // edge or vertex, or coincident faces), or the nearer hit lies at an edge of its triangle (the
    // other test rounded it out), or at the end of a bounded ray (t ~ tmax: one rounded it in).
    if (a.closest && b.closest && std::abs(double(a.t) - b.t) <= tol) {
      ++tieAtT;
      continue;
    }
    const Hit& nearer = !b.closest || (a.closest && a.t < b.t) ? a : b;
    if (edgeDistance(nearer, tris[nearer.tri]) <= tol) {
      ++edge;
      continue;
    }
    if (r.tmax < 1e38f && std::abs(double(nearer.t) - r.tmax) <= tol) {
      ++atTmax;
      continue;
    }
    ++unexplained;
    if (unexplained <= 10)
      ADD_FAILURE() << relative << " ray " << i << " (o " << r.o.x << " " << r.o.y << " " << r.o.z << ", d " << r.d.x
                    << " " << r.d.y << " " << r.d.z << ", tmax " << r.tmax << "): BVH "
                    << (a.closest ? "hits triangle " + std::to_string(a.tri) + " at t " + std::to_string(a.t) : "misses")
                    << ", ray query "
                    << (b.closest ? "hits triangle " + std::to_string(b.tri) + " at t " + std::to_string(b.t) : "misses");
  }
  std::printf("%s: %u rays, %u hits and %u misses (BVH); identical %u, differing at a shared edge or tie %u, at an "
              "edge %u, at tmax %u, unexplained %u; worst |dt| and |dp| / (|o| + t) %.3g, %.3g\n",
              relative.c_str(), n, hits, misses, same, tieAtT, edge, atTmax, unexplained, worstT, worstB);
  EXPECT_EQ(unexplained, 0u);
  EXPECT_EQ(anyDiffer, 0u) << "traceAny and traceClosest disagree on the same interval";
  // Not vacuous: the rays must both hit and miss in numbers.
  EXPECT_GT(hits, n / 4);
  EXPECT_GT(misses, n / 50);
}

}  // namespace

// Bundles of 8 rays (a subgroup on lavapipe) from one random point of the scene's box (inflated by
// 10 %), with directions within ~3 degrees of one uniform direction: coherent rays, which visit
// the same leaves, as the camera's and the light's rays of a small scene do.
std::vector<Ray> bundleRays(const Scene& scene, std::uint32_t n, std::uint32_t seed) {
  glm::vec3 c, h;
  inflatedBox(scene, c, h);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<Ray> rays(n);
  glm::vec3 o(0.0f), axis(0.0f, 0.0f, 1.0f);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (i % 8 == 0) {
      o = c + h * glm::vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1);
      axis = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)) + glm::vec3(1e-6f));
    }
    glm::vec3 d = glm::normalize(axis + 0.05f * glm::vec3(g(rng), g(rng), g(rng)));
    rays[i] = {o, d, 3.0e38f};
  }
  return rays;
}

// The GLSL BVH with its shared leaf loads (trace_tool) against the same traversal with every lane
// loading its own triangles (trace_tool_lanes): both must find the same hits bit for bit, closest
// and any, on random rays and on coherent bundles (which take the shared loads).
void compareLeafLoads(const std::string& relative, std::uint32_t n, std::uint32_t seed) {
  vk::Context& ctx = test::context();
  Scene scene = test::loadTestScene(relative);
  TraversalStructures bvhOnly;
  bvhOnly.bvh = true;
  bvhOnly.accelerationStructures = false;
  DeviceScene device(ctx, scene, bvhOnly);
  std::vector<Ray> rays = randomRays(scene, n, seed);
  const std::vector<Ray> bundles = bundleRays(scene, n, seed + 1);
  rays.insert(rays.end(), bundles.begin(), bundles.end());
  const std::vector<Hit> shared = trace(ctx, device, rays, "trace_tool");
  const std::vector<Hit> lanes = trace(ctx, device, rays, "trace_tool_lanes");
  std::uint32_t differ = 0, bundleHits = 0, bundleMisses = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit &a = shared[i], &b = lanes[i];
    const bool same = a.closest == b.closest && a.any == b.any && a.tri == b.tri &&
                      std::memcmp(&a.t, &b.t, sizeof a.t) == 0 && std::memcmp(&a.b1, &b.b1, sizeof a.b1) == 0 &&
                      std::memcmp(&a.b2, &b.b2, sizeof a.b2) == 0;
    if (!same && ++differ <= 10)
      ADD_FAILURE() << relative << " ray " << i << (i >= n ? " (bundle)" : "") << ": shared loads "
                    << (a.closest ? "hit triangle " + std::to_string(a.tri) + " at t " + std::to_string(a.t) : "miss")
                    << " (any " << a.any << "), per-lane loads "
                    << (b.closest ? "hit triangle " + std::to_string(b.tri) + " at t " + std::to_string(b.t) : "miss")
                    << " (any " << b.any << ")";
    if (i >= n) (a.closest ? bundleHits : bundleMisses)++;
  }
  std::printf("%s: %zu rays (%u in bundles: %u hits, %u misses), %u differ\n", relative.c_str(), rays.size(), n,
              bundleHits, bundleMisses, differ);
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(bundleHits, n / 4);  // not vacuous
}

TEST(Traversal, RayQueryMatchesBvhCornellBox) { compareTraversals("scenes/cornell-box.glb", 240000, 21u); }

TEST(Traversal, RayQueryMatchesBvhDragon) { compareTraversals("scenes/dragon/dragon.gltf", 240000, 22u); }

TEST(Traversal, SharedLeafLoadsMatchPerLaneLoadsCornellBox) { compareLeafLoads("scenes/cornell-box.glb", 120000, 23u); }

TEST(Traversal, SharedLeafLoadsMatchPerLaneLoadsDragon) { compareLeafLoads("scenes/dragon/dragon.gltf", 120000, 24u); }

// A device without ray queries (Mesa 22.3's lavapipe; here: a context that does not enable them)
// renders with the BVH under auto, and refuses --traversal rayquery with a clear message.
TEST(Traversal, FallsBackWithoutRayQueries) {
  vk::Context ctx;
  vk::ContextOptions o;
  o.validation = test::context().validation;
  o.rayQuery = false;
  vk::createContext(ctx, o);
  EXPECT_FALSE(ctx.rayQuery);
  EXPECT_EQ(resolveTraversal(ctx, Traversal::Auto), Traversal::Bvh);
  EXPECT_EQ(resolveTraversal(ctx, Traversal::Bvh), Traversal::Bvh);
  try {
    resolveTraversal(ctx, Traversal::RayQuery);
    ADD_FAILURE() << "--traversal rayquery accepted without ray queries";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not offer ray queries"), std::string::npos) << e.what();
  }
  {
    RenderSettings s;
    s.width = s.height = 16;
    s.spp = 1;
    s.sampler = SamplerKind::Cosine;
    Scene scene = test::loadTestScene("scenes/cornell-box.glb");
    Renderer r(ctx, scene, s);
    EXPECT_EQ(r.settings().traversal, Traversal::Bvh);
    r.renderPass();
    Image img = r.image();
    double sum = 0;
    for (float v : img.rgb) sum += v;
    EXPECT_GT(sum, 0.0);
  }
  EXPECT_EQ(ctx.validationMessages.load(), 0u);
  vk::destroyContext(ctx);
}

// The C++ twin's alpha test (bvhClosestHit with the scene's AlphaTester) against the GPU's
// (trace_tool_a: the GLSL BVH with HAS_ALPHA, and trace_tool_rq_a with ray queries when the device
// has them) on tests/support/alpha_layers.h (MASK, BLEND and opaque layers): rays from z = 1 down
// through the layers, kept 1e-3 away from every triangle edge on each layer (where float rounding
// may pick another triangle, and BLEND's hash, which takes the triangle index, another answer).
// Every ray must give the same triangle, and t within 1e-6 relative; the rays must stop on every
// layer (the MASK's opaque half, the BLEND layer and the opaque one behind it).
TEST(Traversal, AlphaTestOfTheCppTwinMatchesTheGpu) {
  vk::Context& ctx = test::context();
  const Scene scene = test::alphaLayers();
  TraversalStructures structures;
  structures.bvh = true;
  structures.accelerationStructures = ctx.rayQuery;
  DeviceScene device(ctx, scene, structures);
  RenderSettings settings;
  settings.sampler = SamplerKind::Cosine;  // no sampling tables: only the materials and textures matter
  MaterialTable materials(ctx, scene, settings);
  const Bvh bvh = buildBvh(scene.positions);  // the same order as the device's (deterministic build)
  const AlphaTester alpha(scene, bvh.triangleOrder);
  const BvhHitFilter passes = [&](std::uint32_t tri, float b1, float b2, glm::vec3 o, glm::vec3 d) {
    return alpha(tri, b1, b2, o, d);
  };
  // Away from the quads' edges (a 0.25 grid) and their diagonals (x - x0 = y - y0) on each layer.
  auto clear = [](glm::vec3 o, glm::vec3 d) {
    for (float z : {0.0f, -1.0f, -2.0f}) {
      const glm::vec3 p = o + d * ((z - o.z) / d.z);
      const float fx = p.x / 0.25f - std::floor(p.x / 0.25f), fy = p.y / 0.25f - std::floor(p.y / 0.25f);
      if (std::min({fx, 1 - fx, fy, 1 - fy}) * 0.25f < 1e-3f || std::fabs(fx - fy) * 0.25f < 1e-3f) return false;
    }
    return true;
  };
  std::mt19937 rng(43);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f), tilt(-0.05f, 0.05f);
  std::vector<Ray> rays;
  while (rays.size() < 20000) {
    const glm::vec3 o(u(rng), u(rng), 1.0f);
    const glm::vec3 d = glm::normalize(glm::vec3(tilt(rng), tilt(rng), -1.0f));
    if (clear(o, d)) rays.push_back({o, d, 3.0e38f});
  }
  // Constants 7, 8, 9 (stage_common.glsl): no environment, textures, alpha.
  const std::vector<std::uint32_t> spec{0, 0, 0, 0, 0, 0, 0, 0u, 1u, 1u};
  std::vector<const char*> modules{"trace_tool_a"};
  if (ctx.rayQuery) modules.push_back("trace_tool_rq_a");
  for (const char* module : modules) {
    const std::vector<Hit> gpu = trace(ctx, device, rays, module, &materials, spec);
    std::uint32_t layerHits[3] = {0, 0, 0}, differ = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      float t = 0;
      std::uint32_t tri = INVALID_INDEX;
      const bool hit = bvhClosestHit(bvh, scene.positions, rays[i].o, rays[i].d, 0.0f, rays[i].tmax, t, tri, passes);
      const Hit& h = gpu[i];
      if (hit != h.closest || (hit && (tri != h.tri || std::fabs(t - h.t) > 1e-6f * t)) || h.any != h.closest) {
        if (++differ <= 10)
          ADD_FAILURE() << module << " ray " << i << ": C++ " << (hit ? "triangle " + std::to_string(tri) : "miss")
                        << " at t " << t << ", GPU " << (h.closest ? "triangle " + std::to_string(h.tri) : "miss")
                        << " at t " << h.t << (h.any != h.closest ? " (any-hit disagrees)" : "");
        continue;
      }
      if (hit) ++layerHits[scene.triangleMaterial[bvh.triangleOrder[tri]]];
    }
    std::printf("%s: %zu rays; MASK %u, BLEND %u, opaque %u hits; %u differ\n", module, rays.size(), layerHits[0],
                layerHits[1], layerHits[2], differ);
    EXPECT_EQ(differ, 0u) << module;
    for (std::uint32_t n : layerHits) EXPECT_GT(n, rays.size() / 20) << module;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
