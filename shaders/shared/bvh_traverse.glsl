// bvh_traverse.glsl: ray/scene intersection against the BVH of src/scene/bvh.cpp (GLSL only;
// included after shared/layout.h). The node encoding is documented in src/scene/bvh.h.
// bvhClosestHit in bvh.cpp is the C++ twin of traceClosest: change both together. The alpha test
// of MASK/BLEND materials (HAS_ALPHA, alphaPasses of stage_common.glsl) is the twin's hit filter,
// AlphaTester (src/render/texture_table.h); both apply shared/alpha.h.
//
// Shape of the loop (lavapipe truncates loops after 65,535 iterations per invocation, so keep
// the iteration count low and the loops simple): one iteration per inner node visited. Each
// iteration tests both child boxes of the node, intersects leaf children on the spot (<= 8
// triangles each), then descends into the nearer inner child, deferring the farther one on a
// fixed-size stack. The stack holds at most one node per level and the builder caps the depth
// at BVH_STACK_SIZE - 2, so it cannot overflow; if it ever did, the overflow is counted in
// STAT_BVH_STACK_OVERFLOW and the traversal stops with what it found.

#ifndef NUSSELT_BVH_TRAVERSE_GLSL
#define NUSSELT_BVH_TRAVERSE_GLSL

// Widening of a box's exit distance: covers the rounding of the slab computation so that a
// triangle lying in a box face (flat boxes) is never culled (1 + 2 gamma(3), PBRT 4 6.8.2).
#define BVH_SLAB_EXIT_SCALE 1.0000004f
// Smallest direction component used for the inverse: keeps 1/d finite, so (plane - o) * inv
// never evaluates 0 * inf = NaN (see kMinDirection in bvh.cpp for the one consequence).
#define BVH_MIN_DIRECTION 1e-30f

// Per-ray constants of the slab test.
struct BvhRay {
  vec3 origin;
  vec3 inv;       // 1 / direction, zero components replaced by +-BVH_MIN_DIRECTION
  bvec3 positive; // inv >= 0: the entry plane is the box min on that axis
};

BvhRay bvhMakeRay(vec3 origin, vec3 dir) {
  BvhRay r;
  r.origin = origin;
  vec3 d = mix(dir, mix(vec3(-BVH_MIN_DIRECTION), vec3(BVH_MIN_DIRECTION), greaterThanEqual(dir, vec3(0.0f))),
               lessThan(abs(dir), vec3(BVH_MIN_DIRECTION)));
  r.inv = 1.0f / d;
  r.positive = greaterThanEqual(r.inv, vec3(0.0f));
  return r;
}

// Slab test. The entry plane is chosen by the sign of the direction rather than as the min of
// both plane distances: an inverted box (the empty slot, min = +inf, max = -inf) then gives
// entry = +inf > exit = -inf and is never entered, where min/max would report (-inf, +inf).
bool bvhHitBox(BvhRay r, vec4 bmin, vec4 bmax, float tmin, float tmax, out float tEnter) {
  vec3 nearPlane = mix(bmax.xyz, bmin.xyz, r.positive);
  vec3 farPlane = mix(bmin.xyz, bmax.xyz, r.positive);
  vec3 tn = (nearPlane - r.origin) * r.inv;
  vec3 tf = (farPlane - r.origin) * r.inv;
  tEnter = max(max(tn.x, tn.y), max(tn.z, tmin));
  float tExit = min(min(tf.x, tf.y), min(tf.z, tmax)) * BVH_SLAB_EXIT_SCALE;
  return tEnter <= tExit;
}

// Moller-Trumbore, both faces. b1, b2 are the barycentrics of v1 = v0 + e1 and v2 = v0 + e2.
bool bvhHitTriangle(vec3 origin, vec3 dir, GpuTriangle tri, float tmin, float tmax, out float t, out float b1,
                    out float b2) {
  vec3 e1 = tri.e1.xyz;
  vec3 e2 = tri.e2.xyz;
  vec3 p = cross(dir, e2);
  float det = dot(e1, p);
  float invDet = 1.0f / det;
  vec3 s = origin - tri.v0.xyz;
  b1 = dot(s, p) * invDet;
  vec3 q = cross(s, e1);
  b2 = dot(dir, q) * invDet;
  t = dot(e2, q) * invDet;
  // Conjunctions only, so that a NaN anywhere (det == 0) rejects the hit.
  return det != 0.0f && b1 >= 0.0f && b2 >= 0.0f && b1 + b2 <= 1.0f && t > tmin && t < tmax;
}

// Closest hit with tmin < t < tmax: t, the barycentrics of v1 and v2, and the index of the
// triangle in the reordered triangle array (the index of g.triangles and g.shading).
bool traceClosest(vec3 origin, vec3 dir, float tmin, float tmax, out float t, out float b1, out float b2,
                  out uint tri) {
  t = tmax;
  b1 = 0.0f;
  b2 = 0.0f;
  tri = INVALID_INDEX;
  if (g.triangleCount == 0u) return false;  // empty scene: there is no node 0
  BvhNodes nodes = g.bvh;
  Triangles triangles = g.triangles;
  BvhRay ray = bvhMakeRay(origin, dir);
  uint stack[BVH_STACK_SIZE];
  uint sp = 0u;
  uint node = 0u;
  bool found = false;
  for (;;) {
    BvhNode n = nodes.v[node];
    float enter0;
    float enter1;
    bool hit0 = bvhHitBox(ray, n.min0, n.max0, tmin, t, enter0);
    bool hit1 = bvhHitBox(ray, n.min1, n.max1, tmin, t, enter1);
    if (hit0 && n.link.z > 0u) {
      for (uint i = n.link.x; i < n.link.x + n.link.z; ++i) {
        float tt;
        float u;
        float v;
        if (bvhHitTriangle(origin, dir, triangles.v[i], tmin, t, tt, u, v) && (!HAS_ALPHA || alphaPasses(i, u, v, origin, dir))) {
          t = tt;
          b1 = u;
          b2 = v;
          tri = i;
          found = true;
        }
      }
      hit0 = false;
    }
    if (hit1 && n.link.w > 0u) {
      for (uint i = n.link.y; i < n.link.y + n.link.w; ++i) {
        float tt;
        float u;
        float v;
        if (bvhHitTriangle(origin, dir, triangles.v[i], tmin, t, tt, u, v) && (!HAS_ALPHA || alphaPasses(i, u, v, origin, dir))) {
          t = tt;
          b1 = u;
          b2 = v;
          tri = i;
          found = true;
        }
      }
      hit1 = false;
    }
    if (hit0 && hit1) {
      if (sp >= uint(BVH_STACK_SIZE)) {
        atomicAdd(g.stats.v[STAT_BVH_STACK_OVERFLOW], 1u);
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
bool traceAny(vec3 origin, vec3 dir, float tmin, float tmax) {
  if (g.triangleCount == 0u) return false;
  BvhNodes nodes = g.bvh;
  Triangles triangles = g.triangles;
  BvhRay ray = bvhMakeRay(origin, dir);
  uint stack[BVH_STACK_SIZE];
  uint sp = 0u;
  uint node = 0u;
  for (;;) {
    BvhNode n = nodes.v[node];
    float enter0;
    float enter1;
    bool hit0 = bvhHitBox(ray, n.min0, n.max0, tmin, tmax, enter0);
    bool hit1 = bvhHitBox(ray, n.min1, n.max1, tmin, tmax, enter1);
    if (hit0 && n.link.z > 0u) {
      for (uint i = n.link.x; i < n.link.x + n.link.z; ++i) {
        float tt;
        float u;
        float v;
        if (bvhHitTriangle(origin, dir, triangles.v[i], tmin, tmax, tt, u, v) && (!HAS_ALPHA || alphaPasses(i, u, v, origin, dir)))
          return true;
      }
      hit0 = false;
    }
    if (hit1 && n.link.w > 0u) {
      for (uint i = n.link.y; i < n.link.y + n.link.w; ++i) {
        float tt;
        float u;
        float v;
        if (bvhHitTriangle(origin, dir, triangles.v[i], tmin, tmax, tt, u, v) && (!HAS_ALPHA || alphaPasses(i, u, v, origin, dir)))
          return true;
      }
      hit1 = false;
    }
    if (hit0 && hit1) {
      if (sp >= uint(BVH_STACK_SIZE)) {
        atomicAdd(g.stats.v[STAT_BVH_STACK_OVERFLOW], 1u);
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

#endif
