// bvh.cpp: binned-SAH BVH builder (see bvh.h for the node encoding) and the C++ entry points of
// the traversal the GPU runs (shaders/shared/bvh_traverse.h).
#include "scene/bvh.h"

#include "../../shaders/shared/bvh_traverse.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <glm/gtc/packing.hpp>
#include <limits>
#include <stdexcept>
#include <system_error>
#include <thread>

namespace nusselt {
namespace {

using shared::BvhNode;
using shared::BvhNodeBoxes;

constexpr float kInf = std::numeric_limits<float>::infinity();
// SAH bins per axis: 32 is within a percent or two of a full sweep on typical meshes.
constexpr int kBins = 32;
// Cost of visiting one node relative to testing one triangle, as the GLSL traversal runs on a CPU
// device (the BVH's users: --traversal auto takes ray queries on GPUs). By the arithmetic alone a
// node visit (two boxes, 48 bytes compressed) and a triangle test (48 bytes, a few cross products) are about
// even, but on lavapipe a visit is an iteration of a loop whose lanes diverge (stack, nearer
// child, the leaf loops), where a leaf's triangles are tested by every lane in step. Measured
// (bench render, 3 interleaved repeats; docs/performance.md): 4 with leaves of up to 32 triangles
// against 1 with leaves of up to 8 gives the Cornell boxes (32 triangles: one node, two leaves)
// 1.25x the samples/s, the dragon (100k), the materials scene (44k) and the glass box (5k) the
// same within the repeats' spread.
constexpr float kTraversalCost = 4.0f;
// Subtrees at least this large are built on their own thread (below that a thread costs more
// than it saves).
constexpr std::uint32_t kParallelMinTriangles = 32 * 1024;

struct Aabb {
  glm::vec3 lo{kInf};
  glm::vec3 hi{-kInf};

  void grow(glm::vec3 p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  // Half the surface area (the factor 2 cancels in every SAH ratio). 0 for an empty box, so
  // that empty bins never produce a NaN; double, because scenes spanning 1e20 overflow a float.
  double halfArea() const {
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return 0.0;
    const glm::dvec3 d = glm::dvec3(hi) - glm::dvec3(lo);
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

// One triangle as the builder sees it: its box and its original index. Prims are partitioned in
// place, so every pass over a node's range reads memory sequentially (indirection through an
// index array made the 2M-triangle build cache-bound). 32 bytes.
struct Prim {
  glm::vec3 lo;
  std::uint32_t id;
  glm::vec3 hi;
  std::uint32_t pad;
  // Halves first: lo + hi overflows for coordinates beyond 1.7e38.
  glm::vec3 centre() const { return lo * 0.5f + hi * 0.5f; }
};

// A child reference as its parent stores it.
struct ChildRef {
  std::uint32_t index = INVALID_INDEX;
  std::uint32_t count = 0;  // > 0: leaf
  Aabb box;
};

struct LocalStats {
  std::uint32_t leaves = 0;
  std::uint32_t maxDepth = 0;
  std::uint32_t maxLeafSize = 0;

  void merge(const LocalStats& o) {
    leaves += o.leaves;
    maxDepth = std::max(maxDepth, o.maxDepth);
    maxLeafSize = std::max(maxLeafSize, o.maxLeafSize);
  }
};

struct Split {
  bool valid = false;
  int axis = 0;
  int bin = 0;  // prims with bin index < bin go left
  std::uint32_t countLeft = 0, countRight = 0;
  double cost = kInf;  // SAH cost of splitting, in units of one triangle test
};

// Inner-node levels a subtree of n triangles needs under pure median splitting: the number of
// levels below a node of n triangles before every part fits in a leaf.
std::uint32_t medianLevels(std::uint32_t n) {
  std::uint32_t levels = 0;
  std::uint64_t capacity = kBvhMaxLeafSize;
  while (capacity < n) {
    capacity *= 2;
    ++levels;
  }
  return levels;
}

// The bin of a centre coordinate. One function for binning and partitioning so that both see
// bit-identical results.
// Clamps in float before converting: casting a NaN or out-of-range float to int is undefined.
inline int binOf(float c, float cmin, float scale) {
  const float f = (c - cmin) * scale;
  return f > 0.0f ? (f < static_cast<float>(kBins) ? static_cast<int>(f) : kBins - 1) : 0;
}

class Builder {
 public:
  Builder(Prim* prims, std::uint32_t parallelDepth) : prims_(prims), parallelDepth_(parallelDepth) {}

  // Builds the subtree of prims [begin, end) whose root sits at `depth` (number of inner nodes
  // above it). Inner nodes are appended to `out` with indices relative to `out`; leaf indices are
  // absolute positions in the prim array. Returns how the parent refers to it.
  ChildRef build(std::uint32_t begin, std::uint32_t end, std::uint32_t depth,
                 std::vector<BvhNodeBoxes>& out, LocalStats& stats) const {
    const std::uint32_t n = end - begin;
    ChildRef ref;
    Aabb centres;
    for (std::uint32_t i = begin; i < end; ++i) {
      ref.box.grow(prims_[i].lo);
      ref.box.grow(prims_[i].hi);
      centres.grow(prims_[i].centre());
    }

    Split split;
    if (n >= 2) split = findSahSplit(begin, end, ref.box, centres);
    // SAH may peel off one triangle per level (e.g. exponentially spaced input): accept its split
    // only while both children can still reach leaf size by median splits within the depth cap.
    const bool sahFits = split.valid && depth + 1 + medianLevels(split.countLeft) <= kBvhMaxDepth &&
                         depth + 1 + medianLevels(split.countRight) <= kBvhMaxDepth;

    if (n <= kBvhMaxLeafSize && (n == 1 || !sahFits || static_cast<double>(n) <= split.cost)) {
      ref.index = begin;
      ref.count = n;
      stats.leaves++;
      stats.maxDepth = std::max(stats.maxDepth, depth);
      stats.maxLeafSize = std::max(stats.maxLeafSize, n);
      return ref;
    }

    std::uint32_t mid = begin;
    if (sahFits) {
      const float cmin = centres.lo[split.axis];
      const float scale = binScale(centres, split.axis);
      const int axis = split.axis, bin = split.bin;
      Prim* m = std::partition(prims_ + begin, prims_ + end, [&](const Prim& p) {
        return binOf(p.centre()[axis], cmin, scale) < bin;
      });
      mid = static_cast<std::uint32_t>(m - prims_);
    }
    // (The count check is paranoia: binOf is deterministic, so the partition reproduces the
    // binning; if it ever did not, the depth reasoning above would not hold for this split.)
    if (!sahFits || mid - begin != split.countLeft) {
      // No usable SAH split (coincident centres, or the depth cap is near): split at the median
      // along the longest centre axis. With coincident centres this is a split by index; either
      // way both halves shrink by half, which is what keeps the depth bounded.
      glm::vec3 ext = centres.hi - centres.lo;
      const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
      mid = begin + n / 2;
      std::nth_element(prims_ + begin, prims_ + mid, prims_ + end, [axis](const Prim& a, const Prim& b) {
        return a.centre()[axis] < b.centre()[axis];
      });
    }

    const std::uint32_t nodeIndex = static_cast<std::uint32_t>(out.size());
    out.emplace_back();
    ref.index = nodeIndex;
    ref.count = 0;

    ChildRef left, right;
    std::vector<BvhNodeBoxes> rightNodes;
    LocalStats rightStats;
    std::exception_ptr error;
    std::thread worker;
    if (depth < parallelDepth_ && n >= kParallelMinTriangles) {
      // Right subtree on another thread into its own node array, appended after the left subtree:
      // the same depth-first layout as a serial build, so the result is thread-count independent.
      try {
        worker = std::thread([&] {
          try {
            right = build(mid, end, depth + 1, rightNodes, rightStats);
          } catch (...) {
            error = std::current_exception();
          }
        });
      } catch (const std::system_error&) {
        // No thread to be had (resource limits): build this subtree serially instead.
      }
    }
    if (worker.joinable()) {
      try {
        left = build(begin, mid, depth + 1, out, stats);
      } catch (...) {
        worker.join();
        throw;
      }
      worker.join();
      if (error) std::rethrow_exception(error);
      const std::uint32_t offset = static_cast<std::uint32_t>(out.size());
      for (BvhNodeBoxes& node : rightNodes) {
        if (node.link.z == 0 && node.link.x != INVALID_INDEX) node.link.x += offset;
        if (node.link.w == 0 && node.link.y != INVALID_INDEX) node.link.y += offset;
      }
      if (right.count == 0) right.index += offset;
      out.insert(out.end(), rightNodes.begin(), rightNodes.end());
      stats.merge(rightStats);
    } else {
      left = build(begin, mid, depth + 1, out, stats);
      right = build(mid, end, depth + 1, out, stats);
    }
    // `out` may have grown: index, don't hold a reference across the recursion.
    out[nodeIndex] = makeNode(left, right);
    return ref;
  }

  static BvhNodeBoxes makeNode(const ChildRef& a, const ChildRef& b) {
    BvhNodeBoxes node;
    node.min0 = glm::vec4(a.box.lo, 0.0f);
    node.max0 = glm::vec4(a.box.hi, 0.0f);
    node.min1 = glm::vec4(b.box.lo, 0.0f);
    node.max1 = glm::vec4(b.box.hi, 0.0f);
    node.link = glm::uvec4(a.index, b.index, a.count, b.count);
    return node;
  }

 private:
  static float binScale(const Aabb& centres, int axis) {
    const float extent = centres.hi[axis] - centres.lo[axis];
    // 0 (axis skipped) when flat, or when the extent overflows (coordinates near the float limit).
    return extent > 0.0f && std::isfinite(extent) ? static_cast<float>(kBins) / extent : 0.0f;
  }

  Split findSahSplit(std::uint32_t begin, std::uint32_t end, const Aabb& box, const Aabb& centres) const {
    struct Bin {
      Aabb box;
      std::uint32_t count = 0;
    };
    std::array<std::array<Bin, kBins>, 3> bins{};
    std::array<float, 3> scale{}, cmin{};
    for (int a = 0; a < 3; ++a) {
      scale[a] = binScale(centres, a);
      cmin[a] = centres.lo[a];
    }
    for (std::uint32_t i = begin; i < end; ++i) {
      const Prim& p = prims_[i];
      const glm::vec3 c = p.centre();
      for (int a = 0; a < 3; ++a) {
        Bin& bin = bins[a][binOf(c[a], cmin[a], scale[a])];
        bin.box.lo = glm::min(bin.box.lo, p.lo);
        bin.box.hi = glm::max(bin.box.hi, p.hi);
        bin.count++;
      }
    }

    Split best;
    double bestWeighted = kInf;  // sum of area * count over both sides
    for (int a = 0; a < 3; ++a) {
      if (scale[a] == 0.0f) continue;  // flat along this axis: every prim is in bin 0
      // Sweep from the right: rightArea[b], rightCount[b] describe bins [b, kBins).
      std::array<double, kBins> rightArea{};
      std::array<std::uint32_t, kBins> rightCount{};
      Aabb acc;
      std::uint32_t count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bins[a][b].box);
        count += bins[a][b].count;
        rightArea[b] = acc.halfArea();
        rightCount[b] = count;
      }
      acc = Aabb();
      count = 0;
      for (int b = 1; b < kBins; ++b) {
        acc.grow(bins[a][b - 1].box);
        count += bins[a][b - 1].count;
        if (count == 0 || rightCount[b] == 0) continue;
        const double weighted = acc.halfArea() * count + rightArea[b] * rightCount[b];
        if (weighted < bestWeighted) {
          bestWeighted = weighted;
          best.valid = true;
          best.axis = a;
          best.bin = b;
          best.countLeft = count;
          best.countRight = rightCount[b];
        }
      }
    }
    if (best.valid) {
      const double area = std::max(box.halfArea(), std::numeric_limits<double>::min());
      best.cost = kTraversalCost + bestWeighted / area;
    }
    return best;
  }

  Prim* prims_;
  std::uint32_t parallelDepth_;
};

// The SAH cost of the tree (its exact boxes: the stored ones may round out to inf near the float
// limit).
double computeSahCost(const std::vector<BvhNodeBoxes>& nodes) {
  auto halfArea = [](glm::vec4 lo, glm::vec4 hi) {
    Aabb b;
    b.lo = glm::vec3(lo);
    b.hi = glm::vec3(hi);
    return b.halfArea();
  };
  const BvhNodeBoxes& root = nodes[0];
  Aabb rootBox;
  rootBox.lo = glm::min(glm::vec3(root.min0), glm::vec3(root.min1));
  rootBox.hi = glm::max(glm::vec3(root.max0), glm::vec3(root.max1));
  const double rootArea = std::max(rootBox.halfArea(), std::numeric_limits<double>::min());
  double cost = 0.0;
  std::vector<std::pair<std::uint32_t, double>> stack{{0u, rootArea}};
  while (!stack.empty()) {
    auto [index, area] = stack.back();
    stack.pop_back();
    cost += kTraversalCost * area / rootArea;
    const BvhNodeBoxes& node = nodes[index];
    const std::uint32_t child[2] = {node.link.x, node.link.y};
    const std::uint32_t count[2] = {node.link.z, node.link.w};
    const double childArea[2] = {halfArea(node.min0, node.max0), halfArea(node.min1, node.max1)};
    for (int c = 0; c < 2; ++c) {
      if (count[c] > 0) {
        cost += count[c] * childArea[c] / rootArea;
      } else if (child[c] != INVALID_INDEX) {
        stack.push_back({child[c], childArea[c]});
      }
    }
  }
  return cost;
}

}  // namespace

namespace {

// A bound as bvhDecodeNode computes it from half h (bits) at origin o and scale s.
float decodeBound(float o, std::uint32_t h, float s) { return o + glm::unpackHalf1x16(static_cast<glm::uint16>(h)) * s; }

// The half (bits, >= 0) whose decoded bound is the largest not above v (lower bounds) or the
// smallest not below v (upper bounds). No subnormal halves: a device may flush them to 0 (which
// would lower an upper bound), so a lower bound takes 0 and an upper one the smallest normal.
std::uint32_t encodeBound(float v, float o, float s, bool upper) {
  constexpr std::uint32_t kInfBits = 0x7c00u, kMinNormal = 0x0400u;
  std::uint32_t h = glm::packHalf1x16(static_cast<float>((double(v) - double(o)) / double(s)));
  if (h & 0x8000u) h = 0;  // a negative offset (rounding): start from 0
  if (h > kInfBits) h = kInfBits;
  if (upper) {
    while (h < kInfBits && decodeBound(o, h, s) < v) ++h;
    while (h > 0 && decodeBound(o, h - 1, s) >= v) --h;
    if (h > 0 && h < kMinNormal) h = kMinNormal;
  } else {
    while (h > 0 && decodeBound(o, h, s) > v) --h;
    while (h + 1 < kInfBits && decodeBound(o, h + 1, s) <= v) ++h;
    if (h < kMinNormal) h = 0;
  }
  return h;
}

}  // namespace

shared::BvhNode encodeBvhNode(const shared::BvhNodeBoxes& n) {
  const glm::vec3 lo[2] = {glm::vec3(n.min0), glm::vec3(n.min1)};
  const glm::vec3 hi[2] = {glm::vec3(n.max0), glm::vec3(n.max1)};
  // An inverted box (an empty slot) stays inverted: +inf lower, -inf upper halves.
  const bool empty[2] = {glm::any(glm::greaterThan(lo[0], hi[0])), glm::any(glm::greaterThan(lo[1], hi[1]))};
  glm::vec3 origin(0.0f);
  if (!empty[0] || !empty[1]) origin = empty[0] ? lo[1] : empty[1] ? lo[0] : glm::min(lo[0], lo[1]);
  double extent = 0.0;
  for (int c = 0; c < 2; ++c)
    for (int k = 0; k < 3 && !empty[c]; ++k) extent = std::max(extent, double(hi[c][k]) - double(origin[k]));
  // Scale 2^e >= the extent, so that the halves lie in [0, 1] (where they are finest); e >= -100
  // keeps every product h * 2^e a normal float (the smallest normal half is 2^-14).
  int e = -100;
  while (e < 127 && std::ldexp(1.0, e) < extent) ++e;
  const float scale = static_cast<float>(std::ldexp(1.0, e));
  auto pack = [](std::uint32_t a, std::uint32_t b) { return a | (b << 16); };
  glm::uvec4 child[2];
  for (int c = 0; c < 2; ++c) {
    std::uint32_t h[6];
    for (int k = 0; k < 3; ++k) {
      h[k] = empty[c] ? 0x7c00u : encodeBound(lo[c][k], origin[k], scale, false);
      h[3 + k] = empty[c] ? 0xfc00u : encodeBound(hi[c][k], origin[k], scale, true);
    }
    child[c] = glm::uvec4(pack(h[0], h[1]), pack(h[2], h[3]), pack(h[4], h[5]), c == 0 ? n.link.x : n.link.y);
  }
  if (n.link.z > 0x3fu || n.link.w > 0x3fu) throw std::logic_error("BVH leaf of more than 63 triangles");
  shared::BvhNode out;
  out.origin = glm::uvec4(shared::floatBitsToUint(origin.x), shared::floatBitsToUint(origin.y),
                          shared::floatBitsToUint(origin.z), std::uint32_t(e + 127) | (n.link.z << 8) | (n.link.w << 14));
  out.child0 = child[0];
  out.child1 = child[1];
  return out;
}

Bvh buildBvh(const std::vector<glm::vec3>& positions) {
  const auto start = std::chrono::steady_clock::now();
  Bvh bvh;
  const std::uint32_t count = static_cast<std::uint32_t>(positions.size() / 3);
  if (count == 0) return bvh;

  std::vector<Prim> prims(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const glm::vec3 &a = positions[3 * i], &b = positions[3 * i + 1], &c = positions[3 * i + 2];
    prims[i].lo = glm::min(a, glm::min(b, c));
    prims[i].hi = glm::max(a, glm::max(b, c));
    prims[i].id = i;
    prims[i].pad = 0;
  }

  // Spawn threads on the top levels only: 2^parallelDepth subtrees, about twice the core count,
  // so that uneven SAH splits still keep every core busy.
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::uint32_t parallelDepth = 0;
  while ((1u << parallelDepth) < 2 * cores && parallelDepth < 8) ++parallelDepth;
  if (cores == 1) parallelDepth = 0;

  Builder builder(prims.data(), parallelDepth);
  LocalStats stats;
  std::vector<BvhNodeBoxes> nodes;
  nodes.reserve(count / 2 + 1);
  ChildRef root = builder.build(0, count, 0, nodes, stats);
  if (root.count > 0) {
    // The whole scene fits in one leaf: the root (always an inner node) gets it as child0 and an
    // empty slot as child1 (inverted box, INVALID_INDEX, count 0; see bvh.h).
    nodes.push_back(Builder::makeNode(root, ChildRef()));
    stats.maxDepth = 1;
  }
  bvh.nodes.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) bvh.nodes[i] = encodeBvhNode(nodes[i]);

  bvh.triangleOrder.resize(count);
  for (std::uint32_t i = 0; i < count; ++i) bvh.triangleOrder[i] = prims[i].id;

  bvh.stats.nodes = static_cast<std::uint32_t>(bvh.nodes.size());
  bvh.stats.leaves = stats.leaves;
  bvh.stats.maxDepth = stats.maxDepth;
  bvh.stats.maxLeafSize = stats.maxLeafSize;
  bvh.stats.sahCost = computeSahCost(nodes);
  bvh.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return bvh;
}

// ---- Reference traversal: the shared one of shaders/shared/bvh_traverse.h ----------------------

namespace {

bool callFilter(const void* context, std::uint32_t tri, float b1, float b2, glm::vec3 origin, glm::vec3 dir) {
  return (*static_cast<const BvhHitFilter*>(context))(tri, b1, b2, origin, dir);
}

// Points the calling thread's g_bvhHost at this scene for the lifetime of the object.
class HostScope {
 public:
  HostScope(const Bvh& bvh, const std::vector<glm::vec3>& positions, const BvhHitFilter& passes) {
    m_host.nodes = bvh.nodes.data();
    m_host.nodeCount = static_cast<std::uint32_t>(bvh.nodes.size());
    m_host.positions = positions.data();
    m_host.triangleOrder = bvh.triangleOrder.data();
    if (passes) {
      m_host.passes = callFilter;
      m_host.passesContext = &passes;
    }
    m_previous = shared::g_bvhHost;
    shared::g_bvhHost = &m_host;
  }
  ~HostScope() { shared::g_bvhHost = m_previous; }
  HostScope(const HostScope&) = delete;
  HostScope& operator=(const HostScope&) = delete;

 private:
  shared::BvhHost m_host;
  shared::BvhHost* m_previous = nullptr;
};

}  // namespace

bool intersectTriangle(glm::vec3 origin, glm::vec3 dir, glm::vec3 v0, glm::vec3 e1, glm::vec3 e2,
                       float tmin, float tmax, float& t, float& b1, float& b2) {
  shared::GpuTriangle tri;
  tri.v0 = glm::vec4(v0, 0.0f);
  tri.e1 = glm::vec4(e1, 0.0f);
  tri.e2 = glm::vec4(e2, 0.0f);
  float tt, u, v;
  if (!shared::bvhHitTriangle(origin, dir, tri, tmin, tmax, tt, u, v)) return false;
  t = tt;
  b1 = u;
  b2 = v;
  return true;
}

bool bvhClosestHit(const Bvh& bvh, const std::vector<glm::vec3>& positions, glm::vec3 origin,
                   glm::vec3 dir, float tmin, float tmax, float& t, std::uint32_t& tri,
                   const BvhHitFilter& passes) {
  HostScope scope(bvh, positions, passes);
  float tt, b1, b2;
  std::uint32_t index;
  if (!shared::traceClosest(origin, dir, tmin, tmax, tt, b1, b2, index)) return false;
  t = tt;
  tri = index;
  return true;
}

bool bvhAnyHit(const Bvh& bvh, const std::vector<glm::vec3>& positions, glm::vec3 origin, glm::vec3 dir,
               float tmin, float tmax, const BvhHitFilter& passes) {
  HostScope scope(bvh, positions, passes);
  return shared::traceAny(origin, dir, tmin, tmax);
}

std::vector<std::uint32_t> mortonOrder(const std::vector<glm::vec3>& positions) {
  const std::size_t n = positions.size() / 3;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  std::vector<glm::vec3> centroid(n);
  for (std::size_t i = 0; i < n; ++i) {
    centroid[i] = (positions[3 * i] + positions[3 * i + 1] + positions[3 * i + 2]) / 3.0f;
    lo = glm::min(lo, centroid[i]);
    hi = glm::max(hi, centroid[i]);
  }
  // Spread the 10 low bits of v to every third bit.
  auto spread = [](std::uint32_t v) {
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
  };
  const glm::vec3 extent = hi - lo;
  std::vector<std::uint64_t> keyed(n);  // code in the high 32 bits, index in the low: one sort, ties by index
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t q[3];
    for (int a = 0; a < 3; ++a) {
      float f = extent[a] > 0.0f ? (centroid[i][a] - lo[a]) / extent[a] : 0.0f;
      q[a] = static_cast<std::uint32_t>(std::min(std::max(f, 0.0f), 1.0f) * 1023.0f);
    }
    std::uint32_t code = (spread(q[0]) << 2) | (spread(q[1]) << 1) | spread(q[2]);
    keyed[i] = (std::uint64_t(code) << 32) | i;
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(keyed[i]);
  return order;
}

}  // namespace nusselt
