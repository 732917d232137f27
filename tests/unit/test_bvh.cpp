// test_bvh.cpp: the BVH builder's structural invariants (every triangle once, boxes contain their
// triangles, bounded depth and leaf size) and the reference traversal against brute force.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "../../shaders/shared/alpha.h"
#include "../../shaders/shared/bvh_traverse.h"
#include "render/texture_table.h"
#include "scene/bvh.h"
#include "scene/scene.h"
#include "../support/alpha_layers.h"

namespace nusselt {
namespace {

using shared::BvhNodeBoxes;

constexpr float kInf = std::numeric_limits<float>::infinity();

glm::vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (;;) {
    glm::vec3 v(n(rng), n(rng), n(rng));
    float l = glm::length(v);
    if (l > 1e-3f) return v / l;
  }
}

// n triangles with vertices near random centres in [-1, 1]^3, edge lengths up to `size`.
std::vector<glm::vec3> randomSoup(std::uint32_t n, float size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> p;
  p.reserve(3 * n);
  for (std::uint32_t i = 0; i < n; ++i) {
    glm::vec3 c(u(rng), u(rng), u(rng));
    for (;;) {
      glm::vec3 a = c + size * glm::vec3(u(rng), u(rng), u(rng));
      glm::vec3 b = c + size * glm::vec3(u(rng), u(rng), u(rng));
      glm::vec3 d = c + size * glm::vec3(u(rng), u(rng), u(rng));
      if (glm::length(glm::cross(b - a, d - a)) > 1e-6f * size * size) {
        p.insert(p.end(), {a, b, d});
        break;
      }
    }
  }
  return p;
}

std::vector<glm::vec3> uvSphere(int stacks, int slices, float radius) {
  auto at = [&](int i, int j) {
    float theta = 3.14159265f * static_cast<float>(i) / static_cast<float>(stacks);
    float phi = 6.28318531f * static_cast<float>(j % slices) / static_cast<float>(slices);
    return radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  std::vector<glm::vec3> p;
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      glm::vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (i != 0) p.insert(p.end(), {a, b, d});               // poles: skip zero-area triangles
      if (i != stacks - 1) p.insert(p.end(), {b, c, d});
    }
  }
  return p;
}

bool bruteForce(const std::vector<glm::vec3>& p, glm::vec3 o, glm::vec3 d, float tmin, float tmax, float& t,
                std::uint32_t& tri) {
  bool found = false;
  float best = tmax;
  for (std::uint32_t i = 0; i < p.size() / 3; ++i) {
    float tt, b1, b2;
    if (intersectTriangle(o, d, p[3 * i], p[3 * i + 1] - p[3 * i], p[3 * i + 2] - p[3 * i], tmin, best, tt, b1,
                          b2)) {
      best = tt;
      tri = i;
      found = true;
    }
  }
  if (found) t = best;
  return found;
}

bool contains(glm::vec4 lo, glm::vec4 hi, glm::vec3 p) {
  return lo.x <= p.x && lo.y <= p.y && lo.z <= p.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
}

// Every structural promise of bvh.h.
void checkStructure(const Bvh& bvh, const std::vector<glm::vec3>& p) {
  const std::uint32_t count = static_cast<std::uint32_t>(p.size() / 3);
  // buildBvh's contract: finite input (a test generator that overflows would prove nothing).
  for (const glm::vec3& v : p) ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
  ASSERT_EQ(bvh.triangleOrder.size(), count);
  std::vector<int> seen(count, 0);
  for (std::uint32_t o : bvh.triangleOrder) {
    ASSERT_LT(o, count);
    seen[o]++;
  }
  for (std::uint32_t i = 0; i < count; ++i) ASSERT_EQ(seen[i], 1) << "triangle " << i;
  if (count == 0) {
    EXPECT_TRUE(bvh.nodes.empty());
    return;
  }
  ASSERT_FALSE(bvh.nodes.empty());
  EXPECT_EQ(bvh.stats.nodes, bvh.nodes.size());

  std::vector<int> nodeVisits(bvh.nodes.size(), 0);
  std::vector<int> triangleCovered(count, 0);
  std::uint32_t leaves = 0, maxDepth = 0, maxLeaf = 0, emptySlots = 0;
  // A node with the boxes (as the traversal decodes them) of its ancestors' slots that lead to it:
  // every one must contain every vertex below (the decoded boxes need not nest: each is rounded
  // outwards on its own).
  struct Item {
    std::uint32_t node, depth;
    std::vector<std::pair<glm::vec4, glm::vec4>> boxes;
  };
  std::vector<Item> stack{{0, 0, {}}};
  nodeVisits[0] = 1;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    const BvhNodeBoxes n = shared::bvhDecodeNode(bvh.nodes[it.node]);
    const std::uint32_t child[2] = {n.link.x, n.link.y};
    const std::uint32_t cnt[2] = {n.link.z, n.link.w};
    const glm::vec4 lo[2] = {n.min0, n.min1}, hi[2] = {n.max0, n.max1};
    for (int c = 0; c < 2; ++c) {
      const std::uint32_t depth = it.depth + 1;
      if (cnt[c] > 0) {
        ASSERT_LE(cnt[c], kBvhMaxLeafSize);
        ASSERT_LE(std::uint64_t(child[c]) + cnt[c], count);
        leaves++;
        maxDepth = std::max(maxDepth, depth);
        maxLeaf = std::max(maxLeaf, cnt[c]);
        for (std::uint32_t i = child[c]; i < child[c] + cnt[c]; ++i) {
          triangleCovered[i]++;
          const std::uint32_t o = bvh.triangleOrder[i];
          for (int v = 0; v < 3; ++v) {
            ASSERT_TRUE(contains(lo[c], hi[c], p[3 * o + v])) << "node " << it.node;
            for (const auto& [alo, ahi] : it.boxes) ASSERT_TRUE(contains(alo, ahi, p[3 * o + v])) << "node " << it.node;
          }
        }
      } else if (child[c] == INVALID_INDEX) {
        // Empty slot: only the root of a one-leaf tree, with an inverted box.
        emptySlots++;
        EXPECT_EQ(it.node, 0u);
        EXPECT_EQ(lo[c].x, kInf);
        EXPECT_EQ(hi[c].x, -kInf);
      } else {
        ASSERT_LT(child[c], bvh.nodes.size());
        ASSERT_EQ(nodeVisits[child[c]], 0) << "node reached twice";
        nodeVisits[child[c]] = 1;
        Item next{child[c], depth, it.boxes};
        next.boxes.push_back({lo[c], hi[c]});
        stack.push_back(std::move(next));
      }
    }
  }
  for (std::size_t i = 0; i < nodeVisits.size(); ++i) ASSERT_EQ(nodeVisits[i], 1) << "orphan node " << i;
  for (std::uint32_t i = 0; i < count; ++i) ASSERT_EQ(triangleCovered[i], 1) << "position " << i;
  EXPECT_LE(emptySlots, 1u);
  EXPECT_EQ(bvh.stats.leaves, leaves);
  EXPECT_EQ(bvh.stats.maxDepth, maxDepth);
  EXPECT_EQ(bvh.stats.maxLeafSize, maxLeaf);
  ASSERT_LE(maxDepth, kBvhMaxDepth);
  ASSERT_LE(maxDepth, static_cast<std::uint32_t>(BVH_STACK_SIZE - 2));
  EXPECT_GT(bvh.stats.sahCost, 0.0);
}

// Traces `rays` against the BVH and brute force: same hit/miss, and same triangle or same t.
void checkRays(const Bvh& bvh, const std::vector<glm::vec3>& p, const std::vector<std::pair<glm::vec3, glm::vec3>>& rays,
               float tmin = 0.0f) {
  int hits = 0;
  for (const auto& [o, d] : rays) {
    float tb = 0, tr = 0;
    std::uint32_t ib = 0, ir = 0;
    bool hb = bvhClosestHit(bvh, p, o, d, tmin, kInf, tb, ib);
    bool hr = bruteForce(p, o, d, tmin, kInf, tr, ir);
    ASSERT_EQ(hb, hr) << "o=(" << o.x << "," << o.y << "," << o.z << ") d=(" << d.x << "," << d.y << "," << d.z
                      << ")";
    // The shadow-ray traversal (traceAny): a hit exists exactly when the closest one does, none
    // lies before the closest (same triangle arithmetic as brute force), and the closest itself
    // is found when the interval just includes it.
    ASSERT_EQ(bvhAnyHit(bvh, p, o, d, tmin, kInf), hr);
    if (hr) {
      ASSERT_FALSE(bvhAnyHit(bvh, p, o, d, tmin, tr)) << "t=" << tr;
      ASSERT_TRUE(bvhAnyHit(bvh, p, o, d, tmin, std::nextafter(tr, kInf))) << "t=" << tr;
    }
    if (!hb) continue;
    hits++;
    ASSERT_LT(ib, bvh.triangleOrder.size());
    const std::uint32_t orig = bvh.triangleOrder[ib];
    EXPECT_TRUE(orig == ir || std::abs(tb - tr) <= 1e-5f * std::abs(tr))
        << "bvh t=" << tb << " tri " << orig << " brute t=" << tr << " tri " << ir;
  }
  // A test whose rays all miss would prove nothing.
  EXPECT_GT(hits, 0);
}

// Rays from random points of a box towards random directions, a third of them axis-aligned
// (zero direction components exercise the slab test's inf handling).
std::vector<std::pair<glm::vec3, glm::vec3>> randomRays(int n, float extent, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<std::pair<glm::vec3, glm::vec3>> rays;
  for (int i = 0; i < n; ++i) {
    glm::vec3 o(u(rng), u(rng), u(rng));
    glm::vec3 d = randomUnit(rng);
    if (i % 3 == 0) {
      int axis = static_cast<int>(rng() % 3);
      d = glm::vec3(0.0f);
      d[axis] = (rng() & 1) ? 1.0f : -1.0f;
    } else if (i % 3 == 1) {
      d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) * 0.5f - o);  // aimed inward
    }
    rays.push_back({o, d});
  }
  return rays;
}

// The stored node (48 bytes, half-float child boxes relative to the node): every decoded box
// contains the exact one, lies within the rounding the encoding allows of it (one half step of the
// node's scale 2^e <= 2 x extent, plus float rounding of the sum), an empty slot stays inverted, and
// the links survive. Boxes over many magnitudes: far from the origin, tiny, flat, near the float limit.
TEST(Bvh, EncodedNodesContainTheirBoxesTightly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float offsets[] = {0.0f, 1.0f, -3.5f, 1e4f, -2e7f, 1e30f};
  const float sizes[] = {0.0f, 1e-20f, 1e-6f, 1e-3f, 1.0f, 1e5f, 1e36f};
  int checked = 0;
  for (float off : offsets)
    for (float size : sizes)
      for (int trial = 0; trial < 40; ++trial) {
        BvhNodeBoxes n{};
        glm::vec3 lo[2], hi[2];
        for (int c = 0; c < 2; ++c)
          for (int k = 0; k < 3; ++k) {
            float a = off + size * u(rng), b = off + size * u(rng);
            lo[c][k] = std::min(a, b);
            hi[c][k] = std::max(a, b);
          }
        const bool emptySlot = trial % 10 == 9;
        n.min0 = glm::vec4(lo[0], 0.0f);
        n.max0 = glm::vec4(hi[0], 0.0f);
        n.min1 = emptySlot ? glm::vec4(kInf) : glm::vec4(lo[1], 0.0f);
        n.max1 = emptySlot ? glm::vec4(-kInf) : glm::vec4(hi[1], 0.0f);
        n.link = glm::uvec4(12345u + trial, emptySlot ? INVALID_INDEX : 7u, trial % 33, emptySlot ? 0u : 32u);
        const BvhNodeBoxes d = shared::bvhDecodeNode(encodeBvhNode(n));
        ASSERT_EQ(d.link, n.link);
        double extent = 0.0;
        glm::vec3 origin = emptySlot ? lo[0] : glm::min(lo[0], lo[1]);
        for (int c = 0; c < (emptySlot ? 1 : 2); ++c)
          for (int k = 0; k < 3; ++k) extent = std::max(extent, double(hi[c][k]) - double(origin[k]));
        const glm::vec4 dlo[2] = {d.min0, d.min1}, dhi[2] = {d.max0, d.max1};
        for (int c = 0; c < 2; ++c) {
          if (c == 1 && emptySlot) {
            EXPECT_EQ(dlo[1], glm::vec4(kInf, kInf, kInf, 0.0f));
            EXPECT_EQ(dhi[1], glm::vec4(-kInf, -kInf, -kInf, 0.0f));
            continue;
          }
          for (int k = 0; k < 3; ++k) {
            const double ulps = 2.0 * std::max(double(std::nextafter(std::fabs(hi[c][k]), kInf) - std::fabs(hi[c][k])),
                                               double(std::nextafter(std::fabs(lo[c][k]), kInf) - std::fabs(lo[c][k])));
            const double tol = std::ldexp(extent, -9) + ulps + std::ldexp(1.0, -110);
            ASSERT_LE(dlo[c][k], lo[c][k]) << "off " << off << " size " << size << " trial " << trial;
            ASSERT_GE(dhi[c][k], hi[c][k]) << "off " << off << " size " << size << " trial " << trial;
            ASSERT_LE(double(lo[c][k]) - double(dlo[c][k]), tol) << "off " << off << " size " << size;
            ASSERT_LE(double(dhi[c][k]) - double(hi[c][k]), tol) << "off " << off << " size " << size;
            ++checked;
          }
        }
      }
  EXPECT_EQ(checked, 6 * 7 * 40 * 6 - 6 * 7 * 4 * 3);
  BvhNodeBoxes big{};
  big.link = glm::uvec4(0u, 1u, 64u, 0u);
  EXPECT_THROW(encodeBvhNode(big), std::logic_error);
}

TEST(Bvh, EmptyInput) {
  Bvh bvh = buildBvh({});
  EXPECT_TRUE(bvh.nodes.empty());
  EXPECT_TRUE(bvh.triangleOrder.empty());
  float t;
  std::uint32_t tri;
  EXPECT_FALSE(bvhClosestHit(bvh, {}, glm::vec3(0), glm::vec3(0, 0, 1), 0.0f, kInf, t, tri));
}

TEST(Bvh, OneTriangleHasRootWithEmptySlot) {
  std::vector<glm::vec3> p = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  Bvh bvh = buildBvh(p);
  checkStructure(bvh, p);
  ASSERT_EQ(bvh.nodes.size(), 1u);
  const BvhNodeBoxes root = shared::bvhDecodeNode(bvh.nodes[0]);
  EXPECT_EQ(root.link.x, 0u);
  EXPECT_EQ(root.link.z, 1u);
  EXPECT_EQ(root.link.y, INVALID_INDEX);
  EXPECT_EQ(root.link.w, 0u);
  EXPECT_EQ(bvh.stats.maxDepth, 1u);
  float t;
  std::uint32_t tri;
  ASSERT_TRUE(bvhClosestHit(bvh, p, glm::vec3(0, 0, 5), glm::vec3(0, 0, -1), 0.0f, kInf, t, tri));
  EXPECT_FLOAT_EQ(t, 5.0f);
  EXPECT_EQ(tri, 0u);
  // Back face too (no culling), and axis-aligned rays that would cross the empty slot's
  // "everything" interval if the slab test used min/max of both planes.
  ASSERT_TRUE(bvhClosestHit(bvh, p, glm::vec3(0, 0, -5), glm::vec3(0, 0, 1), 0.0f, kInf, t, tri));
  EXPECT_FALSE(bvhClosestHit(bvh, p, glm::vec3(5, 5, 5), glm::vec3(0, 0, -1), 0.0f, kInf, t, tri));
  EXPECT_FALSE(bvhClosestHit(bvh, p, glm::vec3(0, 0, 5), glm::vec3(0, 0, -1), 0.0f, 4.0f, t, tri));
}

TEST(Bvh, SmallCountsMatchBruteForce) {
  for (std::uint32_t n = 1; n <= 20; ++n) {
    auto p = randomSoup(n, 0.5f, 100 + n);
    Bvh bvh = buildBvh(p);
    checkStructure(bvh, p);
    checkRays(bvh, p, randomRays(300, 1.5f, n));
  }
}

TEST(Bvh, RandomSoupMatchesBruteForce) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    auto p = randomSoup(4000, seed == 3 ? 0.5f : 0.05f, seed);
    Bvh bvh = buildBvh(p);
    checkStructure(bvh, p);
    checkRays(bvh, p, randomRays(3000, 1.2f, seed * 7));
  }
}

TEST(Bvh, UvSphereMatchesBruteForce) {
  auto p = uvSphere(48, 96, 1.0f);
  Bvh bvh = buildBvh(p);
  checkStructure(bvh, p);
  // From inside (every ray hits) and from outside aimed near the sphere.
  checkRays(bvh, p, randomRays(2000, 0.5f, 11));
  checkRays(bvh, p, randomRays(2000, 3.0f, 12));
  std::printf("[ sphere ] %zu triangles: %u nodes, %u leaves, depth %u, max leaf %u, SAH %.2f\n", p.size() / 3,
              bvh.stats.nodes, bvh.stats.leaves, bvh.stats.maxDepth, bvh.stats.maxLeafSize, bvh.stats.sahCost);
}

// A grid of axis-aligned quads in z = 0 traced by axis-aligned rays: flat boxes, zero direction
// components and rays through shared edges and vertices.
TEST(Bvh, FlatGridWithAxisAlignedRays) {
  std::vector<glm::vec3> p;
  const int n = 32;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      glm::vec3 a(i, j, 0), b(i + 1, j, 0), c(i + 1, j + 1, 0), d(i, j + 1, 0);
      p.insert(p.end(), {a, b, c, a, c, d});
    }
  }
  Bvh bvh = buildBvh(p);
  checkStructure(bvh, p);
  // Origins on the grid's outer max edges (x or y == n) are left out: there a zero-component ray
  // lies in the max face of the boxes and is treated as outside (bvh.cpp, kMinDirection).
  std::vector<std::pair<glm::vec3, glm::vec3>> rays;
  for (int i = 0; i < 4 * n; ++i) {
    for (int j = 0; j <= 4 * n; j += 3) {
      glm::vec3 o(0.25f * i, 0.25f * j, 2.0f);
      rays.push_back({o, {0, 0, -1}});
      rays.push_back({o * glm::vec3(1, 1, -1), {0, 0, 1}});
      rays.push_back({o, glm::normalize(glm::vec3(0.0f, 0.3f, -1.0f))});
    }
  }
  checkRays(bvh, p, rays);
}

// All centroids identical: SAH sees no split; the builder must split by index and terminate.
TEST(Bvh, IdenticalCentroidsTerminate) {
  std::mt19937 rng(5);
  std::vector<glm::vec3> p;
  const std::uint32_t n = 100000;
  for (std::uint32_t i = 0; i < n; ++i) {
    glm::vec3 a = randomUnit(rng), b = randomUnit(rng);
    glm::vec3 c = -(a + b);  // centroid exactly... near the origin; boxes differ
    p.insert(p.end(), {a, b, c});
  }
  // And the strict version: the same triangle n times (every box and centroid equal).
  std::vector<glm::vec3> same;
  for (std::uint32_t i = 0; i < n; ++i) same.insert(same.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  for (const auto* input : {&p, &same}) {
    Bvh bvh = buildBvh(*input);
    checkStructure(bvh, *input);
    std::printf("[ centroids ] %u nodes, depth %u, %.3f s\n", bvh.stats.nodes, bvh.stats.maxDepth, bvh.stats.seconds);
  }
  Bvh bvh = buildBvh(same);
  float t;
  std::uint32_t tri;
  ASSERT_TRUE(bvhClosestHit(bvh, same, glm::vec3(0.2f, 0.2f, 1.0f), glm::vec3(0, 0, -1), 0.0f, kInf, t, tri));
  EXPECT_FLOAT_EQ(t, 1.0f);
}

// Geometrically growing triangles along a line: SAH peels one triangle off per level, which
// would give depth ~n without the cap.
TEST(Bvh, AdversarialDepthIsCapped) {
  const std::uint32_t n = 100000;
  std::vector<glm::vec3> exponential, harmonic;
  for (std::uint32_t i = 0; i < n; ++i) {
    // 1e-32 .. 3e37: ~70 decades (in double: 1.0016^i alone overflows a float).
    float x = static_cast<float>(1e-32 * std::pow(1.0016, static_cast<double>(i)));
    float s = 0.4f * x * 0.0016f;
    exponential.insert(exponential.end(), {{x, 0, 0}, {x + s, s, 0}, {x, s, s}});
    float h = 1.0f / static_cast<float>(i + 1);
    float sh = 0.2f * h * h;
    harmonic.insert(harmonic.end(), {{h, 0, 0}, {h + sh, sh, 0}, {h, 0, sh}});
  }
  for (const auto* input : {&exponential, &harmonic}) {
    Bvh bvh = buildBvh(*input);
    checkStructure(bvh, *input);
    EXPECT_LE(bvh.stats.maxDepth, kBvhMaxDepth);
    std::printf("[ adversarial ] depth %u (cap %u), %u nodes, %.3f s\n", bvh.stats.maxDepth, kBvhMaxDepth,
                bvh.stats.nodes, bvh.stats.seconds);
    // A handful of rays along the line against brute force.
    std::vector<std::pair<glm::vec3, glm::vec3>> rays;
    std::mt19937 rng(9);
    for (int i = 0; i < 40; ++i) {
      const std::uint32_t k = rng() % n;
      glm::vec3 a = (*input)[3 * k], b = (*input)[3 * k + 1], c = (*input)[3 * k + 2];
      glm::vec3 centre = (a + b + c) / 3.0f;
      // Both shapes have normal (1, -1, 1) / sqrt(3) (a cross product of the tiny ones underflows).
      glm::vec3 normal = (input == &exponential ? 1.0f : -1.0f) * glm::normalize(glm::vec3(1, -1, 1));
      if (input == &harmonic) normal = glm::normalize(glm::cross(b - a, c - a));
      float dist = glm::length(b - a) * 3.0f;
      rays.push_back({centre + dist * normal, -normal});
    }
    rays.push_back({glm::vec3(-1, 0.0f, 0.0f), glm::vec3(1, 0, 0)});
    checkRays(bvh, *input, rays);
  }
}

// Coordinates near the float limit: box extents and centre sums overflow to inf; the builder must
// neither produce NaN bins nor undefined float-to-int conversions (UBSan watches the latter).
TEST(Bvh, HugeCoordinates) {
  std::vector<glm::vec3> p = randomSoup(500, 0.05f, 31);
  std::mt19937 rng(32);
  std::uniform_real_distribution<float> u(1e38f, 3.3e38f);
  for (int i = 0; i < 500; ++i) {
    glm::vec3 c((i & 1) ? u(rng) : -u(rng), (i & 2) ? u(rng) : -u(rng), u(rng) * 1e-30f);
    p.insert(p.end(), {c, c + glm::vec3(1e33f, 0, 0), c + glm::vec3(0, 1e33f, 0)});
  }
  Bvh bvh = buildBvh(p);
  checkStructure(bvh, p);
  checkRays(bvh, p, randomRays(300, 1.2f, 33));
}

TEST(Bvh, DepthBoundHoldsOnLargeSoup) {
  auto p = randomSoup(200000, 0.02f, 77);
  Bvh bvh = buildBvh(p);
  checkStructure(bvh, p);
  checkRays(bvh, p, randomRays(200, 1.2f, 78));
}

// Sanitized builds run ~30x slower: they skip the million-triangle timing.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// mortonOrder (the triangle order handed to acceleration-structure builders): a permutation; on
// triangles whose centroids lie on a line in shuffled order, the order along the line (a Morton
// curve restricted to one axis is monotonic); an empty scene gives an empty order.
TEST(Bvh, MortonOrder) {
  auto p = randomSoup(5000, 0.01f, 7u);
  std::vector<std::uint32_t> order = mortonOrder(p);
  ASSERT_EQ(order.size(), 5000u);
  std::vector<bool> seen(5000, false);
  for (std::uint32_t i : order) {
    ASSERT_LT(i, 5000u);
    EXPECT_FALSE(seen[i]) << "triangle " << i << " twice";
    seen[i] = true;
  }
  std::vector<std::uint32_t> slot(1000);
  for (std::uint32_t i = 0; i < 1000; ++i) slot[i] = (i * 617u) % 1000u;  // 617 is prime to 1000: a shuffle
  std::vector<glm::vec3> line;
  for (std::uint32_t i = 0; i < 1000; ++i) {
    float x = float(slot[i]);
    line.insert(line.end(), {glm::vec3(x, 0, 0), glm::vec3(x + 0.1f, 1, 0), glm::vec3(x + 0.2f, 0, 1)});
  }
  order = mortonOrder(line);
  ASSERT_EQ(order.size(), 1000u);
  for (std::uint32_t k = 1; k < 1000; ++k) EXPECT_LE(slot[order[k - 1]], slot[order[k]]) << "at " << k;
  EXPECT_TRUE(mortonOrder({}).empty());
}

// Build times (printed, not asserted: the machine running the tests varies).
TEST(Bvh, BuildTimes) {
  for (std::uint32_t n : {100000u, 1000000u}) {
    if (kSanitized && n > 100000u) continue;
    auto p = randomSoup(n, 0.01f, n);
    Bvh bvh = buildBvh(p);
    ASSERT_EQ(bvh.triangleOrder.size(), n);
    EXPECT_LE(bvh.stats.maxDepth, kBvhMaxDepth);
    std::printf("[ build ] %u triangles: %.3f s, %u nodes, %u leaves, depth %u, max leaf %u, SAH %.2f\n", n,
                bvh.stats.seconds, bvh.stats.nodes, bvh.stats.leaves, bvh.stats.maxDepth, bvh.stats.maxLeafSize,
                bvh.stats.sahCost);
  }
}


// The twin with the scene's AlphaTester (the GPU rule, shared/alpha.h) against brute force with
// the same filter, on rays from z = 1 down through the layers (slightly tilted, so that BLEND's hash
// sees varied rays): both find the same triangle; where the texture's alpha is 1 (x < 0 at
// z = 0) every ray stops on the MASK layer, where it is 0 none does; of the rays through the mask,
// the BLEND layer stops a fraction that a binomial z-test (significance 0.001) holds at 0.3, and
// the others reach the opaque layer. Without the filter every ray stops at z = 0 (the old twin).
TEST(Bvh, ClosestHitAppliesAlphaAsTheGpuDoes) {
  const Scene s = test::alphaLayers();
  const Bvh bvh = buildBvh(s.positions);
  const AlphaTester alpha(s, bvh.triangleOrder);
  const BvhHitFilter passes = [&](std::uint32_t tri, float b1, float b2, glm::vec3 o, glm::vec3 d) {
    return alpha(tri, b1, b2, o, d);
  };
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> u(-0.8f, 0.8f), tilt(-0.05f, 0.05f);
  int through = 0, blendStops = 0;
  const int n = 4000;
  for (int k = 0; k < n; ++k) {
    glm::vec3 o(u(rng), u(rng), 1.0f);
    if (std::fabs(o.x) < 0.1f) continue;  // keep the tilted rays on one side of the mask's edge
    const glm::vec3 d = glm::normalize(glm::vec3(tilt(rng), tilt(rng), -1.0f));
    float t = 0;
    std::uint32_t tri = 0;
    ASSERT_TRUE(bvhClosestHit(bvh, s.positions, o, d, 0.0f, kInf, t, tri, passes)) << o.x << " " << o.y << " " << d.x << " " << d.y;
    // Brute force over the reordered triangles with the same filter.
    float tb = kInf;
    std::uint32_t ib = INVALID_INDEX;
    for (std::uint32_t i = 0; i < bvh.triangleOrder.size(); ++i) {
      const std::uint32_t q = bvh.triangleOrder[i];
      float tt, b1, b2;
      if (intersectTriangle(o, d, s.positions[3 * q], s.positions[3 * q + 1] - s.positions[3 * q],
                            s.positions[3 * q + 2] - s.positions[3 * q], 0.0f, tb, tt, b1, b2) &&
          passes(i, b1, b2, o, d)) {
        tb = tt;
        ib = i;
      }
    }
    ASSERT_EQ(tri, ib) << "ray " << k;
    const std::uint32_t layer = s.triangleMaterial[bvh.triangleOrder[tri]];
    if (o.x < 0) {
      EXPECT_EQ(layer, 0u) << "ray " << k;
    } else {
      EXPECT_NE(layer, 0u) << "ray " << k;
      ++through;
      if (layer == 1) ++blendStops;
    }
    float t0 = 0;
    std::uint32_t tri0 = 0;
    ASSERT_TRUE(bvhClosestHit(bvh, s.positions, o, d, 0.0f, kInf, t0, tri0));
    EXPECT_EQ(s.triangleMaterial[bvh.triangleOrder[tri0]], 0u);
  }
  ASSERT_GT(through, 1000);
  const double p = 0.3, z = (blendStops - p * through) / std::sqrt(through * p * (1 - p));
  EXPECT_LT(std::fabs(z), 3.29) << blendStops << " of " << through << " rays stopped on the BLEND layer";
}

}  // namespace
}  // namespace nusselt
