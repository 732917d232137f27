// trace.glsl: the one pair of scene queries every stage uses (GLSL only; included after
// shared/layout.h by stage_common.glsl):
//   traceClosest(origin, dir, tmin, tmax, out t, out b1, out b2, out tri): the closest hit with
//     tmin < t < tmax; b1, b2 are the barycentrics of v1 = v0 + e1 and v2 = v0 + e2 and tri the
//     index into g.triangles / g.shading. False (t = tmax, tri = INVALID_INDEX) on a miss.
//   traceAny(origin, dir, tmin, tmax): whether anything lies in (tmin, tmax) (shadow rays).
// Both skip hits that alphaPasses (stage_common.glsl) rejects when HAS_ALPHA: MASK and BLEND
// materials (docs/scenes.md, "Alpha").
// Which traversal answers is chosen at compile time: with NUSSELT_RAY_QUERY defined (the *_rq
// modules, CMakeLists.txt), the device's ray queries against the acceleration structures of
// DeviceScene (one bottom level over the scene's triangles in g.triangles order, one top-level
// instance with the identity transform, so primitive index = triangle index); otherwise the GLSL
// BVH of shared/bvh_traverse.h. Both return the same hit record, so the stages that shade a
// hit do not know which one ran. Hits may differ in the last bits of t and b (different
// arithmetic) and, for rays through a shared edge, in which of its triangles is hit.

#ifndef NUSSELT_TRACE_GLSL
#define NUSSELT_TRACE_GLSL

#ifdef NUSSELT_RAY_QUERY

// A ray the ray-query traversal must not see: its result is undefined for non-finite origins or
// directions and negative or NaN intervals (Vulkan spec, rayQueryInitializeEXT), where the BVH
// simply misses. Such rays are reported as misses here too.
bool traceRayInvalid(vec3 origin, vec3 dir, float tmin, float tmax) {
  return any(isnan(origin)) || any(isinf(origin)) || any(isnan(dir)) || any(isinf(dir)) || !(tmin >= 0.0f) ||
         !(tmax >= tmin);
}

accelerationStructureEXT traceScene() { return accelerationStructureEXT(uvec2(g.tlasLow, g.tlasHigh)); }

bool traceClosest(vec3 origin, vec3 dir, float tmin, float tmax, out float t, out float b1, out float b2,
                  out uint tri) {
  t = tmax;
  b1 = 0.0f;
  b2 = 0.0f;
  tri = INVALID_INDEX;
  if (g.triangleCount == 0u || traceRayInvalid(origin, dir, tmin, tmax)) return false;
  rayQueryEXT rq;
  // Opaque geometry: the traversal commits the closest hit itself and proceeds once. With alpha
  // (HAS_ALPHA) every triangle is a candidate, committed when alphaPasses.
  rayQueryInitializeEXT(rq, traceScene(), HAS_ALPHA ? gl_RayFlagsNoOpaqueEXT : gl_RayFlagsOpaqueEXT, 0xffu, origin,
                        tmin, dir, tmax);
  while (rayQueryProceedEXT(rq)) {
    if (HAS_ALPHA && rayQueryGetIntersectionTypeEXT(rq, false) == gl_RayQueryCandidateIntersectionTriangleEXT) {
      vec2 c = rayQueryGetIntersectionBarycentricsEXT(rq, false);
      if (alphaPasses(uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, false)), c.x, c.y, origin, dir))
        rayQueryConfirmIntersectionEXT(rq);
    }
  }
  if (rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionTriangleEXT) return false;
  t = rayQueryGetIntersectionTEXT(rq, true);
  vec2 b = rayQueryGetIntersectionBarycentricsEXT(rq, true);
  b1 = b.x;
  b2 = b.y;
  tri = uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, true));
  return true;
}

bool traceAny(vec3 origin, vec3 dir, float tmin, float tmax) {
  if (g.triangleCount == 0u || traceRayInvalid(origin, dir, tmin, tmax)) return false;
  rayQueryEXT rq;
  rayQueryInitializeEXT(rq, traceScene(),
                        (HAS_ALPHA ? gl_RayFlagsNoOpaqueEXT : gl_RayFlagsOpaqueEXT) | gl_RayFlagsTerminateOnFirstHitEXT,
                        0xffu, origin, tmin, dir, tmax);
  while (rayQueryProceedEXT(rq)) {
    if (HAS_ALPHA && rayQueryGetIntersectionTypeEXT(rq, false) == gl_RayQueryCandidateIntersectionTriangleEXT) {
      vec2 c = rayQueryGetIntersectionBarycentricsEXT(rq, false);
      if (alphaPasses(uint(rayQueryGetIntersectionPrimitiveIndexEXT(rq, false)), c.x, c.y, origin, dir))
        rayQueryConfirmIntersectionEXT(rq);
    }
  }
  return rayQueryGetIntersectionTypeEXT(rq, true) == gl_RayQueryCommittedIntersectionTriangleEXT;
}

#else
#include "shared/bvh_traverse.h"
#endif

#endif
