// schlick: Schlick 1994 rational BRDF, single material, eq. (30) with the multiple-reflection
// term (docs/brdf-models.md 2.12):
//   t = ch, u = cb, v = ci, v' = co, w = h.x / sqrt(h.x^2 + h.y^2) (w = 1 at h = n)
//   S(u) = c + (1 - c)(1 - u)^5, G(v) = v / (r - r v + v), Z(t) = r / (1 + r t^2 - t^2)^2,
//   A(w) = sqrt(p / (p^2 - p^2 w^2 + w^2))
//   f = S(u) [ G(v) G(v') Z(t) A(w) / (4 pi v v') + multiple (1 - G(v) G(v')) / (4 pi v v') ]
//   c: colour in [0, 1]; r, p in (0, 1]; multiple 0/1.
#ifndef NUSSELT_BRDF_SCHLICK_H
#define NUSSELT_BRDF_SCHLICK_H
#include "common.h"
SHARED_BEGIN

#define SCHLICK_C 0u
#define SCHLICK_R 3u
#define SCHLICK_P 4u
#define SCHLICK_MULTIPLE 5u

SHARED_FN vec3 schlickEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 c = brdfParam3(p, SCHLICK_C);
  float r = brdfParam(p, SCHLICK_R);
  float pp = brdfParam(p, SCHLICK_P);
  float multiple = brdfParam(p, SCHLICK_MULTIPLE);
  vec3 h = brdfHalf(wi, wo);
  float u = brdfHalfCos(wi, wo);
  float v = wi.z;
  float v2 = wo.z;
  // G(v) = v / Dv, Dv = r (1 - v) + v; 1 - G G' = (Dv Dv' - v v') / (Dv Dv') without cancellation.
  float dv = r * (1.0f - v) + v;
  float dv2 = r * (1.0f - v2) + v2;
  float gg = v * v2 / (dv * dv2);
  float oneMinusGG = (r * r * (1.0f - v) * (1.0f - v2) + r * (1.0f - v) * v2 + r * v * (1.0f - v2)) / (dv * dv2);
  // Z(t): 1 + r t^2 - t^2 = r ch^2 + sin^2(theta_h) (exact near h = n).
  float s2 = brdfSin2(h);
  float zd = r * h.z * h.z + s2;
  float Z = r / (zd * zd);
  float w2 = s2 > 1e-20f ? h.x * h.x / s2 : 1.0f;
  float A = sqrt(pp / (pp * pp - pp * pp * w2 + w2));
  float D = (gg * Z * A + multiple * oneMinusGG) / (4.0f * NUSSELT_PI * v * v2);
  vec3 S = c + (vec3(1.0f) - c) * schlickWeight(u);
  return S * D;
}

SHARED_END
#endif
