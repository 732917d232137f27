// torrance_sparrow: Torrance-Sparrow / Cook-Torrance with the Beckmann distribution, V-cavity
// masking-shadowing and the exact Fresnel term, normalised as Walter et al. 2007
// (docs/brdf-models.md 2.6):
//   f = kd / pi + ks Fr(cb; eta, k) Dbeck(h; m) G / (4 ci co),  G = min(1, 2 ch co / cb, 2 ch ci / cb)
//   kd, ks: colour in [0, 1]; m in (0, 1]; eta > 0; k >= 0.
#ifndef NUSSELT_BRDF_TORRANCE_SPARROW_H
#define NUSSELT_BRDF_TORRANCE_SPARROW_H
#include "sampling_common.h"
SHARED_BEGIN

#define TORRANCE_SPARROW_KD 0u
#define TORRANCE_SPARROW_KS 3u
#define TORRANCE_SPARROW_M 6u
#define TORRANCE_SPARROW_ETA 7u
#define TORRANCE_SPARROW_K 8u

// V-cavity G / (4 ci co), written so that nothing is divided by a vanishing cosine:
// min(1, 2 ch co/cb, 2 ch ci/cb) / (4 ci co) = min(1/(ci co), 2 ch/(cb ci), 2 ch/(cb co)) / 4.
SHARED_FN float vcavityGOver4CiCo(float ci, float co, float ch, float cb) {
  float g = min(1.0f / (ci * co), 2.0f * ch / (cb * max(ci, co)));
  return 0.25f * g;
}

SHARED_FN vec3 torranceSparrowEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 h = brdfHalf(wi, wo);
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  float F = fresnelComplex(cb, brdfParam(p, TORRANCE_SPARROW_ETA), brdfParam(p, TORRANCE_SPARROW_K));
  float spec = F * beckmannD(h, brdfParam(p, TORRANCE_SPARROW_M)) * vcavityGOver4CiCo(wi.z, wo.z, h.z, cb);
  return brdfParam3(p, TORRANCE_SPARROW_KD) * NUSSELT_INV_PI + brdfParam3(p, TORRANCE_SPARROW_KS) * spec;
}

// ---- Analytic sampling (sampling_common.h): mixture with cosine; h from the Beckmann
// distribution (= D(h) cos theta_h), as ward's with ax = ay = m ----
SHARED_FN float torranceSparrowAnalyticDiffuseProbability(BrdfParams p) {
  return analyticMixtureProbability(luminance(brdfParam3(p, TORRANCE_SPARROW_KD)),
                                    luminance(brdfParam3(p, TORRANCE_SPARROW_KS)));
}
SHARED_FN bool torranceSparrowAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  float ux = u.x;
  if (!analyticPickLobe(torranceSparrowAnalyticDiffuseProbability(p), ux)) return analyticCosineSample(ux, u.y, d);
  float m = brdfParam(p, TORRANCE_SPARROW_M);
  return analyticBeckmannSample(m, m, wo, ux, NUSSELT_TWO_PI * u.y, d);
}
SHARED_FN float torranceSparrowAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  float pd = torranceSparrowAnalyticDiffuseProbability(p);
  float m = brdfParam(p, TORRANCE_SPARROW_M);
  return analyticMix(pd, wi, pd < 1.0f ? analyticBeckmannPdf(m, m, wi, wo) : 0.0f);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// TORRANCE_SPARROW_DELTA: 0 (evaluated and light-sampled).
// TORRANCE_SPARROW_ANALYTIC: 1, the analytic strategy uses torranceSparrowAnalyticSample / torranceSparrowAnalyticPdf.
#define TORRANCE_SPARROW_DELTA 0
#define TORRANCE_SPARROW_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void torranceSparrowSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "torrance_sparrow";
  m.summary = "Torrance-Sparrow / Cook-Torrance: Beckmann D, V-cavity G, exact Fresnel";
  m.params.push_back(colour("kd", TORRANCE_SPARROW_KD, 0.3f, 0.0f, 1.0f, "diffuse albedo"));
  m.params.push_back(colour("ks", TORRANCE_SPARROW_KS, 0.7f, 0.0f, 1.0f, "specular weight"));
  m.params.push_back(scalar("m", TORRANCE_SPARROW_M, 0.2f, 0.001f, 1.0f, false, "Beckmann rms slope"));
  m.params.push_back(scalar("eta", TORRANCE_SPARROW_ETA, 1.5f, 0.0f, 20.0f, true, "real part of the relative index"));
  m.params.push_back(scalar("k", TORRANCE_SPARROW_K, 0.0f, 0.0f, 20.0f, false, "extinction coefficient"));
  m.typical = {N("kd", 0.3), N("ks", 0.7), N("m", 0.2), N("eta", 1.5), N("k", 0)};
  m.hard = {N("kd", 0), N("ks", 1), N("m", 0.01), N("eta", 1.5), N("k", 0)};
  m.variants = {{"metal", {N("kd", 0), N("ks", 1), N("m", 0.3), N("eta", 0.2), N("k", 3)}}};
}
}  // namespace nusselt::models
#endif

#endif
