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

// ---- Traits read by the model list (models.h) ----
// SCHLICK_DELTA: 0 (evaluated and light-sampled).
// SCHLICK_ANALYTIC: 0: the analytic strategy samples the cosine.
#define SCHLICK_DELTA 0
#define SCHLICK_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits schlickTraits(const BrdfParams& p) {
  ModelTraits t;
  t.rimExponent = shared::brdfParam(p, SCHLICK_MULTIPLE) > 0.5f ? 1.0f : 0.0f;
  t.anisotropic = shared::brdfParam(p, SCHLICK_P) < 1.0f;
  return t;
}
inline void schlickSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "schlick";
  m.summary = "Schlick 1994 rational BRDF (single material, eq. 30)";
  m.params.push_back(colour("c", SCHLICK_C, 0.5f, 0.0f, 1.0f, "reflectance at normal incidence"));
  m.params.push_back(scalar("r", SCHLICK_R, 0.2f, 0.0001f, 1.0f, false, "roughness (0 mirror, 1 diffuse)"));
  m.params.push_back(scalar("p", SCHLICK_P, 1.0f, 0.001f, 1.0f, false, "isotropy (1 isotropic)"));
  m.params.push_back(choice("multiple", SCHLICK_MULTIPLE, 1, {"off", "on"},
                            "include the multiple-reflection term (0/off or 1/on)"));
  m.typical = {N("c", 0.5), N("r", 0.2), N("p", 1), N("multiple", 1)};
  m.hard = {N("c", 0.9), N("r", 0.002), N("p", 0.1), N("multiple", 1)};
  m.variants = {{"typical_single", {N("c", 0.5), N("r", 0.2), N("p", 1), N("multiple", 0)}}};
  m.traits = &schlickTraits;
}
}  // namespace nusselt::models
#endif

#endif
