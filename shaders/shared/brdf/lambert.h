// lambert: ideal diffuse reflection (Lambert 1760; the random-walk source's diffuse BRDF).
//   f = rho / pi            rho: colour in [0, 1]
// Measure: BRDF value [1/sr], zero unless wi.z > 0 and wo.z > 0.
#ifndef NUSSELT_BRDF_LAMBERT_H
#define NUSSELT_BRDF_LAMBERT_H
#include "sampling_common.h"
SHARED_BEGIN

#define LAMBERT_RHO 0u

SHARED_FN vec3 lambertEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  return brdfParam3(p, LAMBERT_RHO) * NUSSELT_INV_PI;
}

// ---- Analytic sampling (sampling_common.h): cosine, pdf cos / pi ----
SHARED_FN bool lambertAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(wo);
  return analyticCosineSample(u.x, u.y, d);
}
SHARED_FN float lambertAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(wo);
  return wi.z * NUSSELT_INV_PI;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// LAMBERT_DELTA: 0 (evaluated and light-sampled).
// LAMBERT_ANALYTIC: 1, the analytic strategy uses lambertAnalyticSample / lambertAnalyticPdf.
#define LAMBERT_DELTA 0
#define LAMBERT_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void lambertSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "lambert";
  m.summary = "ideal diffuse: f = rho / pi";
  m.params.push_back(colour("rho", LAMBERT_RHO, 0.8f, 0.0f, 1.0f, "reflectance (albedo)"));
  m.typical = {N("rho", 0.8)};
  m.hard = {N("rho", 1.0)};
}
}  // namespace nusselt::models
#endif

#endif
