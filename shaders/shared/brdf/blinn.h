// blinn: Blinn-Phong half-vector lobe, exactly normalised (docs/brdf-models.md 2.5):
//   f = kd / pi + ks N(n) max(0, cos theta_h)^n,  N(n) = (n+2)(n+4) / (8 pi (2^(-n/2) + n))
//   kd, ks: colour in [0, 1]; n >= 0. a(0) = kd + ks exactly.
#ifndef NUSSELT_BRDF_BLINN_H
#define NUSSELT_BRDF_BLINN_H
#include "sampling_common.h"
SHARED_BEGIN

#define BLINN_KD 0u
#define BLINN_KS 3u
#define BLINN_N 6u

SHARED_FN float blinnNormalisation(float n) {
  return (n + 2.0f) * (n + 4.0f) / (8.0f * NUSSELT_PI * (exp2(-0.5f * n) + n));
}

SHARED_FN vec3 blinnEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float n = brdfParam(p, BLINN_N);
  vec3 h = brdfHalf(wi, wo);
  float lobe = blinnNormalisation(n) * brdfPowOneMinus(brdfOneMinusCos(h), n);
  return brdfParam3(p, BLINN_KD) * NUSSELT_INV_PI + brdfParam3(p, BLINN_KS) * lobe;
}

// ---- Analytic sampling (sampling_common.h): mixture with cosine; half vector h with pdf_h =
// (n+1)/(2 pi) cos^n theta_h, wi = reflect(wo, h), pdf = pdf_h / (4 wo.h) ----
SHARED_FN float blinnAnalyticDiffuseProbability(BrdfParams p) {
  return analyticMixtureProbability(luminance(brdfParam3(p, BLINN_KD)), luminance(brdfParam3(p, BLINN_KS)));
}
// pdf_h(h) / (4 wo.h).
SHARED_FN float blinnAnalyticHalfPdf(float n, vec3 wi, vec3 wo) {
  vec3 h = brdfHalf(wi, wo);
  if (h.z <= 0.0f) return 0.0f;
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  return (n + 1.0f) * (0.5f * NUSSELT_INV_PI) * brdfPowOneMinus(brdfOneMinusCos(h), n) / (4.0f * cb);
}
SHARED_FN bool blinnAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  float ux = u.x;
  if (!analyticPickLobe(blinnAnalyticDiffuseProbability(p), ux)) return analyticCosineSample(ux, u.y, d);
  float phi = NUSSELT_TWO_PI * u.y;
  float omc = analyticLobeOneMinusCos(1.0f - ux, brdfParam(p, BLINN_N));
  float s = sqrt(max(omc * (2.0f - omc), 0.0f));
  return analyticReflectHalf(wo, normalize(vec3(s * cos(phi), s * sin(phi), 1.0f - omc)), d);
}
SHARED_FN float blinnAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  float pd = blinnAnalyticDiffuseProbability(p);
  return analyticMix(pd, wi, pd < 1.0f ? blinnAnalyticHalfPdf(brdfParam(p, BLINN_N), wi, wo) : 0.0f);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// BLINN_DELTA: 0 (evaluated and light-sampled).
// BLINN_ANALYTIC: 1, the analytic strategy uses blinnAnalyticSample / blinnAnalyticPdf.
#define BLINN_DELTA 0
#define BLINN_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void blinnSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "blinn";
  m.summary = "Blinn-Phong half-vector lobe, exactly normalised";
  m.params.push_back(colour("kd", BLINN_KD, 0.4f, 0.0f, 1.0f, "diffuse albedo"));
  m.params.push_back(colour("ks", BLINN_KS, 0.5f, 0.0f, 1.0f, "specular albedo at normal incidence"));
  m.params.push_back(scalar("n", BLINN_N, 100.0f, 0.0f, 100000.0f, false, "exponent of cos theta_h"));
  m.typical = {N("kd", 0.4), N("ks", 0.5), N("n", 100)};
  m.hard = {N("kd", 0), N("ks", 1), N("n", 20000)};
}
}  // namespace nusselt::models
#endif

#endif
