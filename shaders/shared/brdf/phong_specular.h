// phong_specular: the reciprocal Phong lobe of the random-walk source (Szirmay-Kalos), not
// normalised: f = ks max(0, cos alpha)^n, cos alpha = R(wi).wo.
//   ks: colour >= 0; n >= 0. Energy conserving iff ks <= (n+2)/(2 pi). docs/brdf-models.md 2.2.
#ifndef NUSSELT_BRDF_PHONG_SPECULAR_H
#define NUSSELT_BRDF_PHONG_SPECULAR_H
#include "sampling_common.h"
SHARED_BEGIN

#define PHONG_SPECULAR_KS 0u
#define PHONG_SPECULAR_N 3u

// max(0, R(wi).wo)^n, computed from 1 - cos alpha = |R(wi) - wo|^2 / 2 (exact for huge n).
SHARED_FN float phongLobe(vec3 wi, vec3 wo, float n) {
  return brdfPowOneMinus(brdfOneMinusDot(brdfReflectZ(wi), wo), n);
}

SHARED_FN vec3 phongSpecularEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  return brdfParam3(p, PHONG_SPECULAR_KS) * phongLobe(wi, wo, brdfParam(p, PHONG_SPECULAR_N));
}

// ---- Analytic sampling (sampling_common.h): the cos^n lobe around the mirror direction R(wo),
// pdf (n+1)/(2 pi) cos^n alpha (a mixture whose cosine weight is 0) ----
SHARED_FN float phongSpecularAnalyticDiffuseProbability() { return analyticMixtureProbability(0.0f, 1.0f); }
SHARED_FN bool phongSpecularAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  float ux = u.x;
  if (!analyticPickLobe(phongSpecularAnalyticDiffuseProbability(), ux)) return analyticCosineSample(ux, u.y, d);
  float n = brdfParam(p, PHONG_SPECULAR_N);
  d = analyticAround(brdfReflectZ(wo), analyticLobeOneMinusCos(1.0f - ux, n), NUSSELT_TWO_PI * u.y);
  return true;
}
SHARED_FN float phongSpecularAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  float pd = phongSpecularAnalyticDiffuseProbability();
  return analyticMix(pd, wi, pd < 1.0f ? analyticLobePdf(brdfReflectZ(wo), brdfParam(p, PHONG_SPECULAR_N), wi) : 0.0f);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// PHONG_SPECULAR_DELTA: 0 (evaluated and light-sampled).
// PHONG_SPECULAR_ANALYTIC: 1, the analytic strategy uses phongSpecularAnalyticSample / phongSpecularAnalyticPdf.
#define PHONG_SPECULAR_DELTA 0
#define PHONG_SPECULAR_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void phongSpecularSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "phong_specular";
  m.summary = "reciprocal Phong lobe (random-walk source): f = ks max(0, cos alpha)^n";
  m.params.push_back(colour("ks", PHONG_SPECULAR_KS, 1.5f, 0.0f, 100000.0f, "lobe peak value [1/sr]"));
  m.params.push_back(scalar("n", PHONG_SPECULAR_N, 20.0f, 0.0f, 100000.0f, false, "exponent"));
  m.typical = {N("ks", 1.5), N("n", 20)};
  m.hard = {N("ks", 1500), N("n", 10000)};
}
}  // namespace nusselt::models
#endif

#endif
