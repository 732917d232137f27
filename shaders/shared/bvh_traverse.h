// bvh_traverse.h: ray/scene intersection against the BVH of src/scene/bvh.cpp, one source for
// both builds: the GPU traversal (included by shared/trace.glsl after layout.h and alphaPasses
// when there are no ray queries) and its C++ twin bvhClosestHit / bvhAnyHit (src/scene/bvh.cpp),
// which the tests use as the reference. The node encoding is documented in src/scene/bvh.h.
//
// What differs between the builds is behind macros, as in quadtree.h:
//   BVH_LOCALS        declarations the traversal needs (GLSL: local copies of the buffer
//                     references; C++: the host scene of the calling thread, g_bvhHost)
//   BVH_EMPTY()       the scene has no triangle (there is no node 0)
//   BVH_NODE(i)       node i
//   BVH_TRIANGLE(i)   the GpuTriangle at position i of the reordered triangle array (C++: made
//                     from the original positions, v0 and the two edges as DeviceScene uploads)
//   BVH_PASSES(i, b1, b2, origin, dir)  the hit filter: the alpha test of MASK/BLEND materials
//                     (GLSL: alphaPasses when HAS_ALPHA; C++: the host's filter, if any; both
//                     apply shared/alpha.h)
//   BVH_COUNT_STACK_OVERFLOW()  GLSL: STAT_BVH_STACK_OVERFLOW; C++: the host's counter
//
// Shape of the loop (lavapipe truncates loops after 65,535 iterations per invocation, so keep
// the iteration count low and the loops simple): one iteration per inner node visited. Each
// iteration tests both child boxes of the node, intersects leaf children on the spot (<= 32
// triangles each), then descends into the nearer inner child, deferring the farther one on a
// fixed-size stack. The stack holds at most one node per level and the builder caps the depth
// at BVH_STACK_SIZE - 2, so it cannot overflow; if it ever did, the overflow is counted and the
// traversal stops with what it found. When a whole subgroup tests one leaf, its lanes share the
// loads of its triangles (bvhLeafShared below; docs/performance.md, "Shared leaf loads").

#ifndef NUSSELT_BVH_TRAVERSE_H
#define NUSSELT_BVH_TRAVERSE_H
#include "layout.h"

#ifdef __cplusplus
SHARED_BEGIN
// The scene a C++ traversal reads: set g_bvhHost before calling traceClosest / traceAny.
struct BvhHost {
  const BvhNode* nodes = nullptr;
  uint nodeCount = 0;                // 0: empty scene
  const vec3* positions = nullptr;   // 3 per triangle, ORIGINAL order (as given to buildBvh)
  const uint* triangleOrder = nullptr;  // reordered position i holds original triangle triangleOrder[i]
  // Optional hit filter (tri is an index into the reordered array); null: every hit counts.
  bool (*passes)(const void* context, uint tri, float b1, float b2, vec3 origin, vec3 dir) = nullptr;
  const void* passesContext = nullptr;
  std::uint64_t stackOverflows = 0;
};
inline thread_local BvhHost* g_bvhHost = nullptr;
SHARED_FN GpuTriangle bvhHostTriangle(const BvhHost& h, uint i) {
  const uint o = h.triangleOrder[i];
  const vec3 v0 = h.positions[3 * o];
  GpuTriangle tri;
  tri.v0 = vec4(v0, 0.0f);
  tri.e1 = vec4(h.positions[3 * o + 1] - v0, 0.0f);
  tri.e2 = vec4(h.positions[3 * o + 2] - v0, 0.0f);
  return tri;
}
SHARED_END
#define BVH_LOCALS const ::nusselt::shared::BvhHost& bvhHost = *::nusselt::shared::g_bvhHost;
#define BVH_EMPTY() (bvhHost.nodeCount == 0u)
#define BVH_NODE(i) (bvhHost.nodes[i])
#define BVH_TRIANGLE(i) ::nusselt::shared::bvhHostTriangle(bvhHost, i)
#define BVH_PASSES(i, b1, b2, origin, dir) \
  (!bvhHost.passes || bvhHost.passes(bvhHost.passesContext, i, b1, b2, origin, dir))
#define BVH_COUNT_STACK_OVERFLOW() (::nusselt::shared::g_bvhHost->stackOverflows++)
#else
#define BVH_LOCALS \
  BvhNodes bvhNodes = g.bvh; \
  Triangles bvhTriangles = g.triangles;
#define BVH_EMPTY() (g.triangleCount == 0u)
#define BVH_NODE(i) loadBvhNode(bvhNodes, i)
#define BVH_TRIANGLE(i) loadTriangle(bvhTriangles, i)
#define BVH_PASSES(i, b1, b2, origin, dir) (!HAS_ALPHA || alphaPasses(i, b1, b2, origin, dir))
#define BVH_COUNT_STACK_OVERFLOW() atomicAdd(g.stats.v[STAT_BVH_STACK_OVERFLOW], 1u)
#endif

SHARED_BEGIN

// Widening of a box's exit distance: covers the rounding of the slab computation so that a
// triangle lying in a box face (flat boxes) is never culled (1 + 2 gamma(3), PBRT 4 6.8.2).
#define BVH_SLAB_EXIT_SCALE 1.0000004f
// Smallest direction component used for the inverse: keeps 1/d finite, so (plane - o) * inv
// never evaluates 0 * inf = NaN. Replacing a zero component by +-1e-30 tilts the ray by a
// negligible angle; its one visible effect is that a ray lying exactly in a box face plane is
// inside the slab at one face (the min face for +0) and outside at the other. The only hits that
// can be lost are thus on triangle edges lying exactly in such a plane (e.g. a straight-down ray
// through the outer edge of an axis-aligned floor): grazing hits, which Moller-Trumbore's edge
// test already decides arbitrarily.
#define BVH_MIN_DIRECTION 1e-30f

// The boxes and links of a stored node (layout.h, BvhNode): bound = origin + h * 2^(E - 127). The
// product is exact (a power of two times a half, kept above the float's normal range by the
// builder), so a fused multiply-add gives the same bits, and the builder's check of its rounding
// (encodeBvhNode) holds for this code in both builds.
SHARED_FN BvhNodeBoxes bvhDecodeNode(BvhNode n) {
  vec3 o = vec3(uintBitsToFloat(n.origin.x), uintBitsToFloat(n.origin.y), uintBitsToFloat(n.origin.z));
  float s = uintBitsToFloat((n.origin.w & 0xffu) << 23);
  vec2 a = unpackHalf2x16(n.child0.x);
  vec2 b = unpackHalf2x16(n.child0.y);
  vec2 c = unpackHalf2x16(n.child0.z);
  BvhNodeBoxes r;
  r.min0 = vec4(o + vec3(a.x, a.y, b.x) * s, 0.0f);
  r.max0 = vec4(o + vec3(b.y, c.x, c.y) * s, 0.0f);
  a = unpackHalf2x16(n.child1.x);
  b = unpackHalf2x16(n.child1.y);
  c = unpackHalf2x16(n.child1.z);
  r.min1 = vec4(o + vec3(a.x, a.y, b.x) * s, 0.0f);
  r.max1 = vec4(o + vec3(b.y, c.x, c.y) * s, 0.0f);
  r.link = uvec4(n.child0.w, n.child1.w, (n.origin.w >> 8) & 0x3fu, (n.origin.w >> 14) & 0x3fu);
  return r;
}

// Per-ray constants of the slab test.
struct BvhRay {
  vec3 origin;
  vec3 inv;        // 1 / direction, components below BVH_MIN_DIRECTION replaced by +-BVH_MIN_DIRECTION
  bvec3 positive;  // inv >= 0: the entry plane is the box min on that axis
};

SHARED_FN BvhRay bvhMakeRay(vec3 origin, vec3 dir) {
  BvhRay r;
  r.origin = origin;
  vec3 d = mix(dir, mix(vec3(-BVH_MIN_DIRECTION), vec3(BVH_MIN_DIRECTION), greaterThanEqual(dir, vec3(0.0f))),
               lessThan(abs(dir), vec3(BVH_MIN_DIRECTION)));
  r.inv = 1.0f / d;
  r.positive = greaterThanEqual(r.inv, vec3(0.0f));
  return r;
}

// Whether a ray can be traced: finite origin and direction. A NaN or infinite component (a broken
// shading frame upstream) makes the slab tests' distances NaN, which max/min may drop (LLVM's
// maxnum returns the other operand), so such a ray would enter every box, the inverted box of an
// empty slot included, and follow its invalid link. It hits nothing instead.
// Branch-free (a chain of short-circuit tests costs lavapipe branches per ray): a float is finite
// when its exponent bits are not all ones.
SHARED_FN bool bvhRayFinite(vec3 origin, vec3 dir) {
  uvec3 e = max(floatBitsToUint(origin) & uvec3(0x7f800000u), floatBitsToUint(dir) & uvec3(0x7f800000u));
  return all(lessThan(e, uvec3(0x7f800000u)));
}

// Slab test. The entry plane is chosen by the sign of the direction rather than as the min of
// both plane distances: an inverted box (the empty slot, min = +inf, max = -inf) then gives
// entry = +inf > exit = -inf and is never entered, where min/max would report (-inf, +inf).
SHARED_FN bool bvhHitBox(BvhRay r, vec4 bmin, vec4 bmax, float tmin, float tmax, OUT(float) tEnter) {
  vec3 nearPlane = mix(vec3(bmax), vec3(bmin), r.positive);
  vec3 farPlane = mix(vec3(bmin), vec3(bmax), r.positive);
  vec3 tn = (nearPlane - r.origin) * r.inv;
  vec3 tf = (farPlane - r.origin) * r.inv;
  tEnter = max(max(tn.x, tn.y), max(tn.z, tmin));
  float tExit = min(min(tf.x, tf.y), min(tf.z, tmax)) * BVH_SLAB_EXIT_SCALE;
  return tEnter <= tExit;
}

// Moller-Trumbore, both faces. b1, b2 are the barycentrics of v1 = v0 + e1 and v2 = v0 + e2.
SHARED_FN bool bvhHitTriangle(vec3 origin, vec3 dir, GpuTriangle tri, float tmin, float tmax, OUT(float) t,
                              OUT(float) b1, OUT(float) b2) {
  vec3 e1 = vec3(tri.e1);
  vec3 e2 = vec3(tri.e2);
  vec3 p = cross(dir, e2);
  float det = dot(e1, p);
  float invDet = 1.0f / det;
  vec3 s = origin - vec3(tri.v0);
  b1 = dot(s, p) * invDet;
  vec3 q = cross(s, e1);
  b2 = dot(dir, q) * invDet;
  t = dot(e2, q) * invDet;
  // Conjunctions only, so that a NaN anywhere (det == 0) rejects the hit.
  return det != 0.0f && b1 >= 0.0f && b2 >= 0.0f && b1 + b2 <= 1.0f && t > tmin && t < tmax;
}

// Triangle i (data T) of a leaf: if it is hit nearer than t and passes, it replaces the hit record.
SHARED_FN void bvhClosestStep(vec3 origin, vec3 dir, GpuTriangle T, uint i, float tmin, INOUT(float) t,
                              INOUT(float) b1, INOUT(float) b2, INOUT(uint) tri, INOUT(bool) found) {
  BVH_LOCALS
  float tt;
  float u;
  float v;
  if (bvhHitTriangle(origin, dir, T, tmin, t, tt, u, v) && BVH_PASSES(i, u, v, origin, dir)) {
    t = tt;
    b1 = u;
    b2 = v;
    tri = i;
    found = true;
  }
}

// Whether triangle i (data T) is hit in (tmin, tmax) and passes.
SHARED_FN bool bvhAnyStep(vec3 origin, vec3 dir, GpuTriangle T, uint i, float tmin, float tmax) {
  BVH_LOCALS
  float tt;
  float u;
  float v;
  return bvhHitTriangle(origin, dir, T, tmin, tmax, tt, u, v) && BVH_PASSES(i, u, v, origin, dir);
}

// The GLSL traversal shares the loads of leaves (below); the tests' trace_tool_lanes module
// (-DNUSSELT_BVH_PER_LANE) does not, to check that both find the same hits bit for bit.
#if !defined(__cplusplus) && !defined(NUSSELT_BVH_PER_LANE)
#define BVH_SHARED_LEAVES 1
#else
#define BVH_SHARED_LEAVES 0
#endif

#if BVH_SHARED_LEAVES
// Shared leaves. A load through a buffer reference costs each lane its own access (on lavapipe a
// scalar load per lane and 64-bit half behind a mask test, layout.h "64-bit loads": 48 for one
// triangle and 8 lanes, where its test is ~40 vector instructions). When every lane of the subgroup tests the same leaf (a small
// scene, coherent rays), lane l loads triangle base + l of the leaf instead and the lanes hand the
// triangles round with subgroupShuffle (one vpermd per component on lavapipe): a batch of
// gl_SubgroupSize triangles for one load per lane. Each lane still tests the triangles of its leaf
// in the same order with the same data, so the hits are bit for bit those of the plain loop.
bool bvhLeafShared(uint first) {
  return subgroupBallotBitCount(subgroupBallot(first == subgroupBroadcastFirst(first))) == gl_SubgroupSize;
}
GpuTriangle bvhShuffleTriangle(GpuTriangle L, uint k) {
  GpuTriangle T;
  T.v0 = vec4(subgroupShuffle(L.v0.xyz, k), 0.0f);
  T.e1 = vec4(subgroupShuffle(L.e1.xyz, k), 0.0f);
  T.e2 = vec4(subgroupShuffle(L.e2.xyz, k), 0.0f);
  return T;
}
#endif

// The triangles [first, first + count) of a leaf: the nearest that passes, with t < the current
// t, replaces the hit record.
SHARED_FN void bvhLeafClosest(vec3 origin, vec3 dir, uint first, uint count, float tmin, INOUT(float) t,
                              INOUT(float) b1, INOUT(float) b2, INOUT(uint) tri, INOUT(bool) found) {
  BVH_LOCALS
#if BVH_SHARED_LEAVES
  if (bvhLeafShared(first)) {
    for (uint base = 0u; base < count; base += gl_SubgroupSize) {
      GpuTriangle L = BVH_TRIANGLE(first + min(base + gl_SubgroupInvocationID, count - 1u));
      uint n = min(gl_SubgroupSize, count - base);
      for (uint k = 0u; k < n; ++k)
        bvhClosestStep(origin, dir, bvhShuffleTriangle(L, k), first + base + k, tmin, t, b1, b2, tri, found);
    }
  } else
#endif
  {
    for (uint i = first; i < first + count; ++i)
      bvhClosestStep(origin, dir, BVH_TRIANGLE(i), i, tmin, t, b1, b2, tri, found);
  }
}

// Whether a triangle of [first, first + count) is hit in (tmin, tmax) and passes.
SHARED_FN bool bvhLeafAny(vec3 origin, vec3 dir, uint first, uint count, float tmin, float tmax) {
  BVH_LOCALS
#if BVH_SHARED_LEAVES
  if (bvhLeafShared(first)) {
    // Every lane stays in the loops (a lane that left would not load its share of the next
    // batch); a lane that has found its hit skips the tests, and the batches stop once all have.
    bool hit = false;
    for (uint base = 0u; base < count && !subgroupAll(hit); base += gl_SubgroupSize) {
      GpuTriangle L = BVH_TRIANGLE(first + min(base + gl_SubgroupInvocationID, count - 1u));
      uint n = min(gl_SubgroupSize, count - base);
      for (uint k = 0u; k < n; ++k) {
        GpuTriangle T = bvhShuffleTriangle(L, k);
        if (!hit) hit = bvhAnyStep(origin, dir, T, first + base + k, tmin, tmax);
      }
    }
    return hit;
  }
#endif
  for (uint i = first; i < first + count; ++i)
    if (bvhAnyStep(origin, dir, BVH_TRIANGLE(i), i, tmin, tmax)) return true;
  return false;
}

// Closest hit with tmin < t < tmax: t, the barycentrics of v1 and v2, and the index of the
// triangle in the reordered triangle array (the index of g.triangles and g.shading). On a miss
// t = tmax and tri = INVALID_INDEX.
SHARED_FN bool traceClosest(vec3 origin, vec3 dir, float tmin, float tmax, OUT(float) t, OUT(float) b1,
                            OUT(float) b2, OUT(uint) tri) {
  t = tmax;
  b1 = 0.0f;
  b2 = 0.0f;
  tri = INVALID_INDEX;
  BVH_LOCALS
  if (BVH_EMPTY() || !bvhRayFinite(origin, dir)) return false;
  BvhRay ray = bvhMakeRay(origin, dir);
  uint stack[BVH_STACK_SIZE];
  uint sp = 0u;
  uint node = 0u;
  bool found = false;
  for (;;) {
    BvhNodeBoxes n = bvhDecodeNode(BVH_NODE(node));
    float enter0;
    float enter1;
    bool hit0 = bvhHitBox(ray, n.min0, n.max0, tmin, t, enter0);
    bool hit1 = bvhHitBox(ray, n.min1, n.max1, tmin, t, enter1);
    if (hit0 && n.link.z > 0u) {
      bvhLeafClosest(origin, dir, n.link.x, n.link.z, tmin, t, b1, b2, tri, found);
      hit0 = false;
    }
    if (hit1 && n.link.w > 0u) {
      bvhLeafClosest(origin, dir, n.link.y, n.link.w, tmin, t, b1, b2, tri, found);
      hit1 = false;
    }
    if (hit0 && hit1) {
      if (sp >= uint(BVH_STACK_SIZE)) {
        BVH_COUNT_STACK_OVERFLOW();
        break;
      }
      bool firstNear = enter0 <= enter1;
      stack[sp++] = firstNear ? n.link.y : n.link.x;
      node = firstNear ? n.link.x : n.link.y;
    } else if (hit0) {
      node = n.link.x;
    } else if (hit1) {
      node = n.link.y;
    } else {
      if (sp == 0u) break;
      node = stack[--sp];
    }
  }
  if (!found) t = tmax;
  return found;
}

// Any hit with tmin < t < tmax (shadow rays): returns at the first one found. Children are
// visited in stored order: with no closest hit to shrink the interval, sorting buys nothing.
SHARED_FN bool traceAny(vec3 origin, vec3 dir, float tmin, float tmax) {
  BVH_LOCALS
  if (BVH_EMPTY() || !bvhRayFinite(origin, dir)) return false;
  BvhRay ray = bvhMakeRay(origin, dir);
  uint stack[BVH_STACK_SIZE];
  uint sp = 0u;
  uint node = 0u;
  for (;;) {
    BvhNodeBoxes n = bvhDecodeNode(BVH_NODE(node));
    float enter0;
    float enter1;
    bool hit0 = bvhHitBox(ray, n.min0, n.max0, tmin, tmax, enter0);
    bool hit1 = bvhHitBox(ray, n.min1, n.max1, tmin, tmax, enter1);
    if (hit0 && n.link.z > 0u) {
      if (bvhLeafAny(origin, dir, n.link.x, n.link.z, tmin, tmax)) return true;
      hit0 = false;
    }
    if (hit1 && n.link.w > 0u) {
      if (bvhLeafAny(origin, dir, n.link.y, n.link.w, tmin, tmax)) return true;
      hit1 = false;
    }
    if (hit0 && hit1) {
      if (sp >= uint(BVH_STACK_SIZE)) {
        BVH_COUNT_STACK_OVERFLOW();
        return false;
      }
      stack[sp++] = n.link.y;
      node = n.link.x;
    } else if (hit0) {
      node = n.link.x;
    } else if (hit1) {
      node = n.link.y;
    } else {
      if (sp == 0u) return false;
      node = stack[--sp];
    }
  }
  return false;
}

SHARED_END

#endif
