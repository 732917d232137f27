// bvh.h: the CPU builder of the bounding volume hierarchy the GPU traverses, and the C++ entry
// points of that traversal (shaders/shared/bvh_traverse.h, one source for both builds).
//
// Node encoding (shared::BvhNodeBoxes, shaders/shared/layout.h): a node stores the boxes of both of
// its children; link = (child0, child1, count0, count1). Stored as shared::BvhNode (48 bytes: the
// boxes as half floats relative to the node, rounded outwards; encodeBvhNode below), which the
// traversal decodes (bvhDecodeNode) into this form.
//   - count > 0: the child is a leaf holding triangles [child, child + count) of the reordered
//     triangle array (position i holds original triangle triangleOrder[i]); count <= kBvhMaxLeafSize.
//   - count == 0 and child != INVALID_INDEX: the child is the inner node nodes[child].
//   - count == 0 and child == INVALID_INDEX: an empty slot. Its box is inverted (min = +inf,
//     max = -inf); the traversal's slab test picks the entry/exit plane by the sign of the ray
//     direction, so an inverted box always yields entry = +inf > exit = -inf and is never entered.
//     Only the root of a one-leaf tree has an empty slot (child1).
// nodes[0] is the root and is always an inner node (when there is at least one triangle).
// Nodes are laid out depth first: an inner child0 is usually the next node (cache locality).
//
// Depth: a leaf's depth is the number of inner nodes above it (children of the root have depth
// 1). The builder guarantees stats.maxDepth <= kBvhMaxDepth = BVH_STACK_SIZE - 2, which bounds
// the GPU traversal stack (it holds at most one deferred node per level).
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "../../shaders/shared/layout.h"

namespace nusselt {

// Leaves never hold more triangles than this: the GPU leaf loop is bounded by it.
constexpr std::uint32_t kBvhMaxLeafSize = 32;
// The deepest leaf allowed (see above).
constexpr std::uint32_t kBvhMaxDepth = BVH_STACK_SIZE - 2;

struct BvhBuildStats {
  std::uint32_t nodes = 0;        // inner nodes (== Bvh::nodes.size())
  std::uint32_t leaves = 0;       // non-empty leaves
  std::uint32_t maxDepth = 0;     // deepest leaf, <= kBvhMaxDepth
  std::uint32_t maxLeafSize = 0;  // <= kBvhMaxLeafSize
  double seconds = 0.0;           // wall-clock build time
  // SAH cost of the tree: sum over inner nodes of area/rootArea (traversal cost 1) plus sum over
  // leaves of count * area/rootArea (intersection cost 1). Useful to compare builder changes.
  double sahCost = 0.0;
};

struct Bvh {
  std::vector<shared::BvhNode> nodes;   // nodes[0] is the root; empty for an empty scene
  std::vector<std::uint32_t> triangleOrder;  // new position i holds original triangle triangleOrder[i]
  BvhBuildStats stats;
};

// The stored form of a node (shared::BvhNode, layout.h: 48 bytes, child boxes as half floats
// relative to the node, rounded outwards: every decoded box (bvhDecodeNode) contains the exact one,
// an inverted box stays inverted). Leaf counts above 63 throw std::logic_error.
shared::BvhNode encodeBvhNode(const shared::BvhNodeBoxes& node);

// positions: 3 per triangle (world space), all finite. Binned SAH (32 bins on each axis) with
// SAH leaf termination, falling back to a median split where SAH would exceed the depth cap and
// to an index split where all centroids coincide. Large inputs build their top subtrees on
// several threads. The result does not depend on the number of threads.
Bvh buildBvh(const std::vector<glm::vec3>& positions);

// The triangles (3 positions each) sorted along a Morton curve of their centroids (10 bits per
// axis over the bounding box of the centroids; ties keep their order): position i holds original
// triangle order[i]. A spatially coherent order for builders that split the primitives in the
// order given (Mesa 25.0's lavapipe builds its acceleration structures by halving the primitive
// range), and for the locality of per-triangle data. Linear-time codes plus one sort.
std::vector<std::uint32_t> mortonOrder(const std::vector<glm::vec3>& positions);

// ---- Reference traversal (tests only) -----------------------------------------------------------
// Whether a candidate hit counts: triangle tri (an index into the reordered array), barycentrics
// (b1, b2) of v1 and v2, the ray. The GPU's rule is alphaPasses (stage_common.glsl); its C++ twin
// for a scene is AlphaTester (src/render/texture_table.h).
using BvhHitFilter = std::function<bool(std::uint32_t tri, float b1, float b2, glm::vec3 origin, glm::vec3 dir)>;

// traceClosest of shaders/shared/bvh_traverse.h (the code the GPU runs without ray queries) over
// this BVH. positions are the ORIGINAL (not reordered) positions given to buildBvh; tri is
// returned as an index into the reordered array (as on the GPU): the original triangle is
// bvh.triangleOrder[tri]. Returns the nearest hit with tmin < t < tmax that `passes` accepts
// (every hit without it: an opaque scene; with the scene's AlphaTester: MASK and BLEND as the GPU
// traversal of a scene with alpha, HAS_ALPHA); t and tri are left unchanged on a miss.
bool bvhClosestHit(const Bvh& bvh, const std::vector<glm::vec3>& positions, glm::vec3 origin,
                   glm::vec3 dir, float tmin, float tmax, float& t, std::uint32_t& tri,
                   const BvhHitFilter& passes = nullptr);

// traceAny of shaders/shared/bvh_traverse.h (shadow rays): whether a hit with tmin < t < tmax
// that `passes` accepts exists.
bool bvhAnyHit(const Bvh& bvh, const std::vector<glm::vec3>& positions, glm::vec3 origin, glm::vec3 dir,
               float tmin, float tmax, const BvhHitFilter& passes = nullptr);

// Moller-Trumbore against one triangle (v0, e1 = v1 - v0, e2 = v2 - v0), both faces: the GPU's
// bvhHitTriangle (shared/bvh_traverse.h). Exposed so that tests can brute-force with the same arithmetic.
bool intersectTriangle(glm::vec3 origin, glm::vec3 dir, glm::vec3 v0, glm::vec3 e1, glm::vec3 e2,
                       float tmin, float tmax, float& t, float& b1, float& b2);

}  // namespace nusselt
