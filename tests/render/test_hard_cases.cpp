// Numerical hard cases (issue 8). Each test is named after what it provokes. Every render must
// come out without a NaN or Inf pixel; samples that would have been non-finite are dropped and
// counted by the accumulate stage (RenderStats::nonFiniteSamples, the EXR header's count), and
// the count must be 0 wherever the input is valid. Quadtree-sampler bound violations
// (RenderStats::samplerBoundViolations) are asserted to be 0 in every render. Images are tiny
// (<= 16x16): a case's cost is lavapipe creating the renderer's pipelines (~4 s per renderer
// here, not cached across renderers by Mesa 22.3) and, for the catalogue, building the quadtrees.
//
// HardSetsOfTheCatalogue runs every model of the catalogue (18 non-delta, plus mirror and
// dielectric) with its hard parameter set at grazing view and light angles, MIS / NEE / BSDF. Each
// case prints its setup time (pipelines, quadtree build) and per-mode render time ("[ hard set ]"
// lines). Asserted per render: nonFiniteSamples 0, samplerBoundViolations 0, samplerTrialFailures 0.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "../support/test_support.h"
#include "../unit/test_quadtree_chi2.h"
#include "scene/gltf_loader.h"

using namespace nusselt;

namespace {

// Lambert materials: the catalogue's parameter, and emission.
Material lambert(float rho, glm::vec3 emission = glm::vec3(0.0f), const char* name = "lambert") {
  return catalogueMaterial("lambert", {{"rho", ParamValue::num(rho)}}, name, emission);
}

Material withModel(const std::string& model, const NamedParams& params) {
  return catalogueMaterial(model, params, model);
}

std::uint32_t addMaterial(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return std::uint32_t(s.materials.size() - 1);
}

using test::addQuad;

// Axis-aligned box of half size h around `centre`; normals point inwards (a room) or outwards (a
// solid). faceMaterial[k] for the faces -x, +x, -y, +y, -z, +z.
void addBox(Scene& s, glm::vec3 centre, float h, bool inward, const std::uint32_t faceMaterial[6]) {
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int k = 0; k < 6; ++k) {
    glm::vec3 out = axes[k / 2] * (k % 2 ? 1.0f : -1.0f);  // outward normal of this face
    glm::vec3 n = inward ? -out : out;
    glm::vec3 u = axes[(k / 2 + 1) % 3], v = glm::cross(n, u);  // cross(u, v) = n
    glm::vec3 c = centre + out * h;
    addQuad(s, c + h * (-u - v), c + h * (u - v), c + h * (u + v), c + h * (-u + v), faceMaterial[k]);
  }
}

void addBox(Scene& s, glm::vec3 centre, float h, bool inward, std::uint32_t material) {
  const std::uint32_t m[6] = {material, material, material, material, material, material};
  addBox(s, centre, h, inward, m);
}

Camera perspective(glm::vec3 position, glm::vec3 forward, glm::vec3 up, float yfov = 1.2f) {
  Camera c;
  c.position = position;
  c.forward = glm::normalize(forward);
  c.up = glm::normalize(up - glm::dot(up, c.forward) * c.forward);
  c.yfov = yfov;
  return c;
}

RenderSettings tiny(std::uint32_t spp = 32, std::uint32_t maxDepth = 4, std::uint32_t seed = 1) {
  RenderSettings r;
  r.width = r.height = 16;
  r.spp = spp;
  r.maxDepth = maxDepth;
  r.seed = seed;
  return r;
}

// The invariants of every render: finite pixels and variances, no sampler bound violation, no
// BVH stack overflow, no validation message. Returns the non-finite sample count (recorded in
// the test's XML output as well).
std::uint64_t expectSane(const test::Rendered& r, const char* what) {
  int bad = 0;
  for (float v : r.image.rgb)
    if (!std::isfinite(v) || v < 0) ++bad;
  EXPECT_EQ(bad, 0) << what << ": pixel values that are NaN, Inf or negative";
  bad = 0;
  for (float v : r.image.variance)
    if (!std::isfinite(v) || v < 0) ++bad;
  EXPECT_EQ(bad, 0) << what << ": variances that are NaN, Inf or negative";
  EXPECT_EQ(r.stats.samplerBoundViolations, 0u) << what;
  EXPECT_EQ(r.stats.bvhStackOverflows, 0u) << what;
  EXPECT_EQ(test::validationMessages(), 0u) << what;
  ::testing::Test::RecordProperty(std::string("nonFiniteSamples_") + what, std::to_string(r.stats.nonFiniteSamples));
  return r.stats.nonFiniteSamples;
}

double meanOf(const Image& img, int channel = -1) {
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < img.rgb.size(); ++i)
    if (channel < 0 || int(i % 3) == channel) sum += img.rgb[i], ++n;
  return sum / n;
}

// ---- glTF built in memory (for the loader path) ----

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = std::uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= bytes[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? t[v & 63] : '=';
  }
  return out;
}

// A triangle list with per-vertex normals, one Lambert material (NUSSELT_brdf), a point light above and a
// camera looking down at the origin.
Scene loadTriangles(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals) {
  std::vector<unsigned char> bin(positions.size() * 24);
  std::memcpy(bin.data(), positions.data(), positions.size() * 12);
  std::memcpy(bin.data() + positions.size() * 12, normals.data(), normals.size() * 12);
  const std::string n = std::to_string(positions.size()), half = std::to_string(positions.size() * 12);
  std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1,2]}],
    "nodes":[{"mesh":0},{"translation":[0,0,3],"extensions":{"KHR_lights_punctual":{"light":0}}},
             {"camera":0,"translation":[0,0,4]}],
    "cameras":[{"type":"perspective","perspective":{"yfov":1.0,"znear":0.01}}],
    "extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","intensity":10}]}},
    "extensionsUsed":["KHR_lights_punctual","NUSSELT_brdf"],
    "materials":[{"extensions":{"NUSSELT_brdf":{"model":"lambert","params":{"rho":0.5}}}}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"material":0}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":)" +
                     n + R"(,"type":"VEC3"},{"bufferView":1,"componentType":5126,"count":)" + n +
                     R"(,"type":"VEC3"}],
    "bufferViews":[{"buffer":0,"byteLength":)" + half + R"(},{"buffer":0,"byteOffset":)" + half +
                     R"(,"byteLength":)" + half + R"(}],
    "buffers":[{"byteLength":)" + std::to_string(bin.size()) +
                     R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) + R"("}]})";
  return loadSceneFromMemory(reinterpret_cast<const unsigned char*>(json.data()), json.size(), "hard_case.gltf");
}

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

}  // namespace

// ---- Non-finite input ----

// The loader drops triangles with a NaN or Inf corner (and counts them); NaN/Inf/zero normals fall
// back to the geometric normal. What remains renders without a single non-finite sample.
TEST(HardCases, NanAndInfVerticesAndNormalsThroughTheLoader) {
  const glm::vec3 up(0, 0, 1);
  std::vector<glm::vec3> p, n;
  auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 na, glm::vec3 nb, glm::vec3 nc) {
    p.insert(p.end(), {a, b, c});
    n.insert(n.end(), {na, nb, nc});
  };
  // Two good floor triangles whose normals are NaN, Inf and zero.
  tri({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {kNaN, 0, 1}, {0, kInf, 0}, {0, 0, 0});
  tri({-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, up, {-kInf, kNaN, 1}, up);
  // Bad positions: NaN, +Inf, -Inf, and a corner so large the cross product overflows.
  tri({kNaN, 0, 0}, {1, 0, 0}, {0, 1, 0}, up, up, up);
  tri({0, 0, 0}, {kInf, 0, 0}, {0, 1, 0}, up, up, up);
  tri({0, 0, 0}, {1, 0, 0}, {0, -kInf, 0}, up, up, up);
  tri({0, 0, 0}, {3e38f, 0, 0}, {0, 3e38f, 0}, up, up, up);
  Scene s = loadTriangles(p, n);
  EXPECT_EQ(s.triangleCount(), 2u);
  EXPECT_EQ(s.droppedTriangles, 4u);
  for (const glm::vec3& v : s.normals) {
    ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
    EXPECT_NEAR(glm::length(v), 1.0f, 1e-5f);
  }
  test::Rendered r = test::render(s, tiny());
  EXPECT_EQ(expectSane(r, "loader"), 0u);
  EXPECT_GT(meanOf(r.image), 0.0);
}

// A Scene built directly (not through the loader) breaks the contract "unit shading normals" with
// NaN and Inf normals on one quad. The renderer must still write a finite image: such samples are
// dropped and counted, or the normal is repaired; the other quad is unaffected either way.
TEST(HardCases, NanAndInfShadingNormalsInADirectScene) {
  Scene s;
  std::uint32_t m = addMaterial(s, lambert(0.5f));
  addQuad(s, {-2, -2, 0}, {0, -2, 0}, {0, 2, 0}, {-2, 2, 0}, m);  // left half: good normals
  addQuad(s, {0, -2, 0}, {2, -2, 0}, {2, 2, 0}, {0, 2, 0}, m);    // right half: broken below
  const glm::vec3 broken[6] = {{kNaN, kNaN, kNaN}, {0, 0, kInf}, {kInf, -kInf, 0}, {kNaN, 0, 1}, {0, 0, 0}, {0, 0, -kInf}};
  for (int k = 0; k < 6; ++k) s.normals[6 + k] = broken[k];
  PunctualLight l;
  l.position = {0, 0, 2};
  l.intensity = glm::vec3(4.0f);
  s.lights.push_back(l);
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.position = {0, 0, 5};
  s.camera.forward = {0, 0, -1};
  s.camera.up = {0, 1, 0};
  s.camera.xmag = s.camera.ymag = 2.0f;
  RenderSettings settings = tiny(16, 1);
  test::Rendered r = test::render(s, settings);
  std::uint64_t dropped = expectSane(r, "direct");
  EXPECT_LE(dropped, std::uint64_t(settings.spp) * settings.width * settings.height / 2 + settings.spp * settings.height)
      << "only samples that hit the broken quad may be dropped";
  // The good half, away from the seam, is lit (rho/pi I cos / d^2 > 0) in every pixel. Which image
  // half it is depends on the camera convention, so take the better of the two.
  int positive[2] = {0, 0}, count = 0;
  for (int y = 0; y < r.image.height; ++y)
    for (int x = 0; x < r.image.width / 2 - 1; ++x) {
      positive[0] += r.image.rgb[3 * (y * r.image.width + x)] > 0.0f;
      positive[1] += r.image.rgb[3 * (y * r.image.width + r.image.width - 1 - x)] > 0.0f;
      ++count;
    }
  EXPECT_EQ(std::max(positive[0], positive[1]), count) << "the quad with valid normals is not lit everywhere";
}

// ---- Degenerate geometry ----

// Zero-area triangles (repeated corners, collinear corners, and a corner 1e-30 off the line,
// whose float cross product underflows) are dropped by the loader; sliver triangles (1e-6 wide,
// aspect ratio 1e6) are kept and must shade like the floor they tile.
TEST(HardCases, ZeroAreaAndSliverTriangles) {
  const glm::vec3 up(0, 0, 1);
  std::vector<glm::vec3> p, n;
  auto tri = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    p.insert(p.end(), {a, b, c});
    n.insert(n.end(), {up, up, up});
  };
  tri({0, 0, 0}, {0, 0, 0}, {0, 0, 0});
  tri({0, 0, 0}, {1, 0, 0}, {1, 0, 0});
  tri({0, 0, 0}, {1, 1, 0}, {2, 2, 0});
  tri({0, 0, 0}, {1, 0, 0}, {0.5f, 1e-30f, 0});
  // The floor [-1, 1]^2 as a fan from (-1, -1) whose last triangles are slivers.
  std::vector<glm::vec3> rim = {{1, -1, 0}, {1, 0.999999f, 0}, {1, 1, 0}, {0.999999f, 1, 0}, {-1, 1, 0}};
  for (std::size_t k = 0; k + 1 < rim.size(); ++k) tri({-1, -1, 0}, rim[k], rim[k + 1]);
  Scene slivers = loadTriangles(p, n);
  EXPECT_EQ(slivers.droppedTriangles, 4u);
  EXPECT_EQ(slivers.triangleCount(), 4u);
  Scene plain = loadTriangles({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                              std::vector<glm::vec3>(6, up));
  test::Rendered a = test::render(slivers, tiny(64, 2, 1));
  test::Rendered b = test::render(plain, tiny(64, 2, 2));
  EXPECT_EQ(expectSane(a, "slivers"), 0u);
  EXPECT_EQ(expectSane(b, "plain"), 0u);
  std::string msg = test::compareImagesStatistically(a.image, b.image, 0.01, 0.01, 4);
  EXPECT_TRUE(msg.empty()) << msg;
}

// ---- Scale ----

// A closed room (Lambert walls, an emissive ceiling) with a solid block in it, at scales from
// 1e-4 to 1e6. Radiance does not depend on the scale of a closed configuration, so every image
// must agree with the unit-scale one (ray offsets, BVH boxes and light pdfs are all scale-
// dependent code).
TEST(HardCases, SceneScales1em4To1e6) {
  auto room = [](float scale) {
    Scene s;
    std::uint32_t wall = addMaterial(s, lambert(0.5f));
    std::uint32_t ceiling = addMaterial(s, lambert(0.5f, glm::vec3(2.0f), "ceiling"));
    const std::uint32_t faces[6] = {wall, wall, wall, wall, wall, ceiling};
    addBox(s, glm::vec3(0.0f), scale, true, faces);
    addBox(s, glm::vec3(0.3f, 0.1f, -0.7f) * scale, 0.3f * scale, false, wall);
    s.hasCamera = true;
    s.camera = perspective(glm::vec3(-0.2f, -0.5f, 0.4f) * scale, {0.3f, 0.5f, -1.0f}, {0, 1, 0});
    return s;
  };
  const RenderSettings base = tiny(48, 3, 1);
  test::Rendered ref = test::render(room(1.0f), base);
  EXPECT_EQ(expectSane(ref, "scale1"), 0u);
  std::uint32_t seed = 2;
  for (float scale : {1e-4f, 1e-3f, 1e-2f, 1e3f, 1e6f}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    RenderSettings settings = base;
    settings.seed = seed++;
    test::Rendered r = test::render(room(scale), settings);
    EXPECT_EQ(expectSane(r, "scaled"), 0u);
    std::string msg = test::compareImagesStatistically(r.image, ref.image, 0.01, 0.01, 4);
    EXPECT_TRUE(msg.empty()) << msg;
  }
}

// ---- Camera placement ----

// The camera inside a solid block (outward normals, lit from outside) and exactly on a wall of
// a room: rays start on or behind surfaces. Inside the closed block no light arrives.
TEST(HardCases, CameraInsideGeometry) {
  Scene s;
  std::uint32_t m = addMaterial(s, lambert(0.8f));
  addBox(s, glm::vec3(0.0f), 1.0f, false, m);
  PunctualLight l;
  l.position = {3, 2, 1};
  l.intensity = glm::vec3(50.0f);
  s.lights.push_back(l);
  s.hasCamera = true;
  s.camera = perspective(glm::vec3(0.1f, 0.2f, 0.3f), {1, 0.3f, -0.2f}, {0, 0, 1}, 2.5f);
  // One renderer, the camera moved between images (pipeline creation is most of the cost).
  const RenderSettings settings = tiny(8, 4);
  Renderer renderer(test::context(), s, settings);
  RenderStats before = renderer.stats();
  auto next = [&] {
    renderer.render(renderer.samplesDone() + settings.spp);
    test::Rendered r{renderer.image(true), renderer.stats(), renderer.summary()};
    r.stats.nonFiniteSamples -= before.nonFiniteSamples;
    r.stats.samplerBoundViolations -= before.samplerBoundViolations;
    r.stats.bvhStackOverflows -= before.bvhStackOverflows;
    before = renderer.stats();
    return r;
  };
  test::Rendered inside = next();
  EXPECT_EQ(expectSane(inside, "inside"), 0u);
  EXPECT_EQ(meanOf(inside.image), 0.0) << "light leaked into a closed box";

  // Camera on the +x face of the block, looking out and looking along the face.
  for (glm::vec3 forward : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(-1, 0, 0)}) {
    renderer.setCamera(perspective(glm::vec3(1.0f, 0.0f, 0.0f), forward, {0, 0, 1}));
    test::Rendered on = next();
    EXPECT_EQ(expectSane(on, "onSurface"), 0u);
  }
}

// ---- Dynamic range ----

// Emitters of radiance 1e6 and 1e-6 side by side (rho = 0, seen directly) over a Lambert floor
// lit by both: the dim one must come out as exactly 1e-6 next to pixels of 1e6, and the floor's
// estimate must stay finite.
TEST(HardCases, Emitters1e6Next1em6) {
  Scene s;
  std::uint32_t bright = addMaterial(s, lambert(0.0f, glm::vec3(1e6f), "bright"));
  std::uint32_t dim = addMaterial(s, lambert(0.0f, glm::vec3(1e-6f), "dim"));
  std::uint32_t floor = addMaterial(s, lambert(0.5f));
  // Ceiling at z = 1 facing down: bright for x < 0, dim for x > 0. Floor at z = 0 facing up.
  addQuad(s, {-1, -1, 1}, {-1, 1, 1}, {0, 1, 1}, {0, -1, 1}, bright);
  addQuad(s, {0, -1, 1}, {0, 1, 1}, {1, 1, 1}, {1, -1, 1}, dim);
  addQuad(s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, floor);
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.position = {0, 0, 0.5f};
  s.camera.forward = {0, 0, 1};
  s.camera.up = {0, 1, 0};
  s.camera.xmag = s.camera.ymag = 1.0f;
  test::Rendered up = test::render(s, tiny(16, 3));
  EXPECT_EQ(expectSane(up, "lookingUp"), 0u);
  // Away from the seam column every pixel sees one emitter only: exactly 1e6 or exactly 1e-6.
  const Image& img = up.image;
  int brightPixels = 0, dimPixels = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (x == img.width / 2 - 1 || x == img.width / 2) continue;  // the seam columns mix both
      float v = img.rgb[3 * (y * img.width + x)];
      if (std::fabs(v - 1e6f) <= 1e6f * 1e-6f) ++brightPixels;
      else if (std::fabs(v - 1e-6f) <= 1e-6f * 1e-5f) ++dimPixels;
      else ADD_FAILURE() << "pixel " << x << "," << y << " = " << v << ", expected 1e6 or 1e-6";
    }
  EXPECT_EQ(brightPixels, img.height * (img.width / 2 - 1));
  EXPECT_EQ(dimPixels, img.height * (img.width / 2 - 1));

  s.camera.position = {0, 0, 0.9f};
  s.camera.forward = {0, 0, -1};
  test::Rendered down = test::render(s, tiny(16, 3));
  EXPECT_EQ(expectSane(down, "lookingDown"), 0u);
  EXPECT_GT(meanOf(down.image), 1e3);
}

// ---- Path length ----

// rho = 1 (lambert's catalogue hard set) inside a closed emissive room: every vertex adds Le and
// nothing is absorbed, so a path capped at maxDepth carries exactly (maxDepth + 1) Le in
// expectation. Provokes the depth cap on every path, at depths 0 to 48.
TEST(HardCases, PathsHittingTheDepthCap) {
  Scene s;
  const NamedParams& hard = hardParams(*findModel("lambert"));
  Material m = withModel("lambert", hard);
  m.emission = glm::vec3(1.0f);
  addBox(s, glm::vec3(0.0f), 1.0f, true, addMaterial(s, m));
  s.hasCamera = true;
  s.camera = perspective({0.1f, -0.2f, 0.3f}, {0.2f, 1, -0.4f}, {0, 0, 1});
  for (std::uint32_t depth : {0u, 1u, 5u, 48u}) {
    SCOPED_TRACE("maxDepth " + std::to_string(depth));
    RenderSettings settings = tiny(32, depth, depth + 1);
    test::Rendered r = test::render(s, settings);
    EXPECT_EQ(expectSane(r, "depthCap"), 0u);
    const double expected = depth + 1.0;
    const int n = r.image.width * r.image.height;
    double sum = 0, var = 0;
    for (int i = 0; i < n; ++i) sum += r.image.rgb[3 * i], var += r.image.variance[3 * i];
    const double mean = sum / n, se = std::sqrt(var) / n;
    // A 5-sigma bound on the image mean (the per-pixel variance estimates are pooled).
    EXPECT_LT(std::fabs(mean - expected), 5 * se + 1e-4 * expected) << mean << " +- " << se;
  }
}

// ---- Grazing incidence ----

// A Lambert floor under directional lights at elevations 0, 1e-6 and 1e-3 rad and a point light
// 1e-5 above the floor far away: irradiance E sin(elevation) with cos -> 0, and shadow rays that
// skim the surface. Every pixel of the directional cases is rho/pi E sin(elevation).
TEST(HardCases, PunctualLightsAtGrazing) {
  auto floorScene = [] {
    Scene s;
    addQuad(s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, addMaterial(s, lambert(0.5f)));
    s.hasCamera = true;
    s.camera.orthographic = true;
    s.camera.position = {0, 0, 1};
    s.camera.forward = {0, 0, -1};
    s.camera.up = {0, 1, 0};
    s.camera.xmag = s.camera.ymag = 1.0f;
    return s;
  };
  for (double elevation : {0.0, 1e-6, 1e-3, 0.5}) {
    SCOPED_TRACE("elevation " + std::to_string(elevation));
    Scene s = floorScene();
    PunctualLight l;
    l.type = LightType::Directional;
    l.direction = glm::vec3(-float(std::cos(elevation)), 0.0f, -float(std::sin(elevation)));
    l.intensity = glm::vec3(3.0f);
    s.lights.push_back(l);
    test::Rendered r = test::render(s, tiny(4, 1));
    EXPECT_EQ(expectSane(r, "directional"), 0u);
    const double expected = 0.5 / M_PI * 3.0 * std::sin(elevation);
    for (float v : r.image.rgb) ASSERT_NEAR(v, expected, 1e-4 * expected + 1e-30);
  }
  // Point and spot lights skimming the floor from its edge.
  Scene s = floorScene();
  PunctualLight point;
  point.position = {-1.5f, 0.0f, 1e-5f};
  point.intensity = glm::vec3(1e4f);
  s.lights.push_back(point);
  PunctualLight spot;
  spot.type = LightType::Spot;
  spot.position = {0.0f, -3.0f, 1e-4f};
  spot.direction = glm::normalize(glm::vec3(0.0f, 1.0f, -1e-5f));
  spot.intensity = glm::vec3(1e4f);
  s.lights.push_back(spot);
  test::Rendered r = test::render(s, tiny(8, 2));
  EXPECT_EQ(expectSane(r, "pointAndSpot"), 0u);
  EXPECT_GT(meanOf(r.image), 0.0);
}

// ---- Delta models ----

// An emitter sealed inside a glass block (dielectric, eta 1.5) over a Lambert floor: light leaves
// only through refraction (no shadow ray crosses glass), paths bounce inside by total internal
// reflection. The image must be finite, lit, and carry no dropped sample.
TEST(HardCases, LightInsideGlass) {
  Scene s;
  std::uint32_t glass = addMaterial(s, withModel("dielectric", {{"eta", ParamValue::num(1.5)}}));
  std::uint32_t lamp = addMaterial(s, lambert(0.0f, glm::vec3(50.0f), "lamp"));
  std::uint32_t floor = addMaterial(s, lambert(0.7f));
  addBox(s, glm::vec3(0, 0, 0.6f), 0.5f, false, glass);
  addBox(s, glm::vec3(0, 0, 0.6f), 0.1f, false, lamp);
  addQuad(s, {-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}, floor);
  PunctualLight inside;  // a punctual light inside the glass too: its shadow rays are all blocked
  inside.position = {0.2f, 0.2f, 0.6f};
  inside.intensity = glm::vec3(10.0f);
  s.lights.push_back(inside);
  s.hasCamera = true;
  s.camera = perspective({0, -3, 2.5f}, {0, 3, -2}, {0, 0, 1}, 1.0f);
  test::Rendered r = test::render(s, tiny(32, 12));
  EXPECT_EQ(expectSane(r, "glass"), 0u);
  EXPECT_GT(meanOf(r.image), 0.0);
}

// ---- The catalogue's hard parameter sets ----

// Every model of the catalogue with its hard set (extreme shininess, tiny lobes, grazing-heavy
// Fresnel) on a large floor seen from 0.1 above it: the image rows below the horizon see the
// floor at view angles from 78.5 deg to within 0.1 deg of 90 deg. It is lit by a 1 x 1 area light
// 1.5 above (which the far floor sees at 80-89 deg) and by a point light 1e-3 above the floor
// (89.98 deg at 3 units) whose mirror reflection is in view, under a uniform sky of radiance 0.5;
// rendered under MIS, NEE only and BSDF sampling only (one renderer, setLighting between them). Asserted per render: no NaN/Inf pixel or variance, nonFiniteSamples == 0,
// samplerBoundViolations == 0, no BVH overflow or validation message, and samplerTrialFailures
// == 0.
namespace {

struct HardCase {
  const char* model;
  std::uint32_t thetaTables = 90, phiTables = 16;
};

class HardSetsOfTheCatalogue : public ::testing::TestWithParam<HardCase> {};

// Tables: the renderer's default 90 theta tables; the anisotropic hard sets (ward ax != ay,
// ashikhmin_shirley nu != nv, schlick p < 1, poulin_fournier) with 4 phi tables instead of 16 (360
// trees instead of 1440: at 16, poulin_fournier's case took 92 s in a full ctest run). The sampler
// is exact with any table count; the chi-square suites test the default 16.
const HardCase kHardCases[] = {
    {"lambert"}, {"phong_specular"}, {"phong"}, {"lewis"}, {"blinn"}, {"torrance_sparrow"}, {"ward", 90, 4},
    {"ashikhmin_shirley", 90, 4}, {"lafortune"}, {"minnaert"}, {"oren_nayar"}, {"schlick", 90, 4}, {"strauss"},
    {"beard_maxwell"}, {"htsg"}, {"poulin_fournier", 90, 4}, {"coupled"}, {"gltf_pbr"},
    // Delta models (no quadtree, never light-sampled): Fresnel at grazing incidence.
    {"mirror"}, {"dielectric"},
};

// The scene of HardSetsOfTheCatalogue (below) for one model's hard set.
Scene grazingScene(const ModelSpec& spec) {
  Scene s;
  // The lamp is the same material plus emission: one shade pipeline and one quadtree set per case
  // (lavapipe compiles each shade pipeline for seconds; that, not the render, is the case's cost).
  Material floor = withModel(spec.name, hardParams(spec));
  Material lamp = floor;
  lamp.name = "lamp";
  lamp.emission = glm::vec3(5.0f);
  addQuad(s, {-200, -200, 0}, {200, -200, 0}, {200, 200, 0}, {-200, 200, 0}, addMaterial(s, floor));
  addQuad(s, {-0.5f, -0.5f, 1.5f}, {-0.5f, 0.5f, 1.5f}, {0.5f, 0.5f, 1.5f}, {0.5f, -0.5f, 1.5f}, addMaterial(s, lamp));
  PunctualLight l;
  l.position = {3.0f, 0.0f, 1e-3f};
  l.intensity = glm::vec3(100.0f);
  s.lights.push_back(l);
  s.hasCamera = true;
  // Rows from 0.1 rad above the horizon to 0.2 rad below it (yfov 0.3 around 0.05 rad down).
  s.camera = perspective({-3.0f, 0.0f, 0.1f}, {1, 0, -0.05f}, {0, 0, 1}, 0.3f);
  // A uniform sky: BSDF-sampled directions that escape carry light (the mirror and the glass
  // reflect it at grazing; the sharp lobes would otherwise see almost nothing).
  s.background = glm::vec3(0.5f);
  return s;
}

}  // namespace

TEST_P(HardSetsOfTheCatalogue, GrazingViewAndLights) {
  const HardCase& c = GetParam();
  const ModelSpec* spec = findModel(c.model);
  ASSERT_NE(spec, nullptr);
  Scene s = grazingScene(*spec);
  RenderSettings settings = tiny(8, 4);
  settings.samplerThetaTables = c.thetaTables;
  settings.samplerPhiTables = c.phiTables;
  const auto t0 = std::chrono::steady_clock::now();
  // One renderer (pipelines and trees built once), the three estimators in turn.
  Renderer renderer(test::context(), s, settings);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const SceneSummary& summary = renderer.summary();
  std::printf("[ hard set ] %-17s setup %6.2f s (pipelines %.2f s; %u trees of %ux%u tables in %.2f s, cache hits %u)\n",
              spec->name.c_str(), setup, summary.pipelineSeconds, summary.samplerTrees, c.thetaTables,
              summary.samplerTrees / c.thetaTables, summary.samplerSeconds, summary.samplerCacheHits);
  RenderStats before = renderer.stats();
  for (LightingMode mode : {LightingMode::Mis, LightingMode::NeeOnly, LightingMode::BsdfOnly}) {
    SCOPED_TRACE(lightingModeName(mode));
    const auto r0 = std::chrono::steady_clock::now();
    renderer.setLighting(mode);
    renderer.render(renderer.samplesDone() + settings.spp);
    test::Rendered r{renderer.image(true), renderer.stats(), summary};
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
    // This mode's counts: the renderer's statistics accumulate over the three.
    r.stats.nonFiniteSamples -= before.nonFiniteSamples;
    r.stats.samplerBoundViolations -= before.samplerBoundViolations;
    r.stats.samplerTrialFailures -= before.samplerTrialFailures;
    r.stats.bvhStackOverflows -= before.bvhStackOverflows;
    before = renderer.stats();
    const std::string what = spec->name + "_" + lightingModeName(mode);
    EXPECT_EQ(expectSane(r, what.c_str()), 0u) << "nonFiniteSamples";
    std::printf("[ hard set ] %-17s %-5s %6.2f s  mean %.3g  nonFinite %llu  boundViolations %llu  trialFailures %llu\n",
                spec->name.c_str(), lightingModeName(mode), seconds, meanOf(r.image),
                static_cast<unsigned long long>(r.stats.nonFiniteSamples),
                static_cast<unsigned long long>(r.stats.samplerBoundViolations),
                static_cast<unsigned long long>(r.stats.samplerTrialFailures));
    ::testing::Test::RecordProperty("samplerTrialFailures_" + what, std::to_string(r.stats.samplerTrialFailures));
    EXPECT_EQ(r.stats.samplerTrialFailures, 0u) << spec->name;
  }
  std::printf("[ hard set ] %-17s total %6.2f s\n", spec->name.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  std::fflush(stdout);
}

INSTANTIATE_TEST_SUITE_P(Catalogue, HardSetsOfTheCatalogue, ::testing::ValuesIn(kHardCases),
                         [](const ::testing::TestParamInfo<HardCase>& info) { return std::string(info.param.model); });
