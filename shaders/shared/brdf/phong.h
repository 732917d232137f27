// phong: modified (normalised, reciprocal) Phong (Lafortune & Willems 1994), also used for
// "lewis" (Lewis 1994; same function, its own model id):
//   f = kd / pi + ks (n + 2) / (2 pi) max(0, cos alpha)^n
//   kd, ks: colour in [0, 1]; n >= 0. a(0) = kd + ks. docs/brdf-models.md 2.3, 2.4.
#ifndef NUSSELT_BRDF_PHONG_H
#define NUSSELT_BRDF_PHONG_H
#include "phong_specular.h"
SHARED_BEGIN

#define PHONG_KD 0u
#define PHONG_KS 3u
#define PHONG_N 6u

SHARED_FN vec3 phongEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float n = brdfParam(p, PHONG_N);
  float lobe = (n + 2.0f) * (0.5f * NUSSELT_INV_PI) * phongLobe(wi, wo, n);
  return brdfParam3(p, PHONG_KD) * NUSSELT_INV_PI + brdfParam3(p, PHONG_KS) * lobe;
}

// ---- Analytic sampling (sampling_common.h): cosine with probability lum(kd) / (lum(kd) +
// lum(ks)), else the cos^n lobe around R(wo) (Lafortune & Willems 1994); lewis uses it too ----
SHARED_FN float phongAnalyticDiffuseProbability(BrdfParams p) {
  return analyticMixtureProbability(luminance(brdfParam3(p, PHONG_KD)), luminance(brdfParam3(p, PHONG_KS)));
}
SHARED_FN bool phongAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  float ux = u.x;
  if (!analyticPickLobe(phongAnalyticDiffuseProbability(p), ux)) return analyticCosineSample(ux, u.y, d);
  d = analyticAround(brdfReflectZ(wo), analyticLobeOneMinusCos(1.0f - ux, brdfParam(p, PHONG_N)), NUSSELT_TWO_PI * u.y);
  return true;
}
SHARED_FN float phongAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  float pd = phongAnalyticDiffuseProbability(p);
  return analyticMix(pd, wi, pd < 1.0f ? analyticLobePdf(brdfReflectZ(wo), brdfParam(p, PHONG_N), wi) : 0.0f);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// PHONG_DELTA: 0 (evaluated and light-sampled).
// PHONG_ANALYTIC: 1, the analytic strategy uses phongAnalyticSample / phongAnalyticPdf.
#define PHONG_DELTA 0
#define PHONG_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void phongSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "phong";
  m.summary = "normalised reciprocal Phong: kd/pi + ks (n+2)/(2pi) cos^n alpha";
  m.params.push_back(colour("kd", PHONG_KD, 0.4f, 0.0f, 1.0f, "diffuse albedo"));
  m.params.push_back(colour("ks", PHONG_KS, 0.5f, 0.0f, 1.0f, "specular albedo at normal incidence"));
  m.params.push_back(scalar("n", PHONG_N, 50.0f, 0.0f, 100000.0f, false, "exponent"));
  m.typical = {N("kd", 0.4f), N("ks", 0.5f), N("n", 50.0f)};
  m.hard = {N("kd", 0), N("ks", 1), N("n", 10000)};
}
}  // namespace nusselt::models
#endif

#endif
