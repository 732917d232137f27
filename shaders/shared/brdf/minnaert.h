// minnaert: Minnaert 1941, normalised so that a(0) = rho (docs/brdf-models.md 2.10):
//   f = rho (k + 1) / (2 pi) (ci co)^(k - 1);  a(theta_i) = rho cos^(k-1) theta_i.
//   rho: colour in [0, 1]; k in [0.5, 2] (k < 1: unbounded at the rim, integrable).
#ifndef NUSSELT_BRDF_MINNAERT_H
#define NUSSELT_BRDF_MINNAERT_H
#include "common.h"
SHARED_BEGIN

#define MINNAERT_RHO 0u
#define MINNAERT_K 3u

SHARED_FN vec3 minnaertEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float k = brdfParam(p, MINNAERT_K);
  float s = (k + 1.0f) * (0.5f * NUSSELT_INV_PI) * exp((k - 1.0f) * (portableLog(wi.z) + portableLog(wo.z)));
  return brdfParam3(p, MINNAERT_RHO) * s;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// MINNAERT_DELTA: 0 (evaluated and light-sampled).
// MINNAERT_ANALYTIC: 0: the analytic strategy samples the cosine.
#define MINNAERT_DELTA 0
#define MINNAERT_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits minnaertTraits(const BrdfParams& p) {
  ModelTraits t;
  t.rimExponent = std::max(0.0f, 1.0f - shared::brdfParam(p, MINNAERT_K));
  return t;
}
inline void minnaertSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "minnaert";
  m.summary = "Minnaert 1941: rho (k+1)/(2pi) (ci co)^(k-1)";
  m.params.push_back(colour("rho", MINNAERT_RHO, 0.8f, 0.0f, 1.0f, "albedo at normal incidence"));
  m.params.push_back(scalar("k", MINNAERT_K, 0.8f, 0.5f, 2.0f, false, "limb darkening exponent (1: Lambert)"));
  m.typical = {N("rho", 0.8), N("k", 0.8)};
  m.hard = {N("rho", 1), N("k", 0.5)};
  m.traits = &minnaertTraits;
}
}  // namespace nusselt::models
#endif

#endif
