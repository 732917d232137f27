// ashikhmin_shirley: anisotropic Phong of Ashikhmin & Shirley 2000 (docs/brdf-models.md 2.8):
//   e(h) = (nu h.x^2 + nv h.y^2) / (1 - ch^2)
//   spec = sqrt((nu+1)(nv+1)) / (8 pi) ch^e(h) / (cb max(ci, co)) Fschlick(cb; rs)
//   diff = 28 rd / (23 pi) (1 - rs) (1 - (1 - ci/2)^5) (1 - (1 - co/2)^5)
//   rd, rs: colour in [0, 1]; nu, nv >= 1.
#ifndef NUSSELT_BRDF_ASHIKHMIN_SHIRLEY_H
#define NUSSELT_BRDF_ASHIKHMIN_SHIRLEY_H
#include "sampling_common.h"
SHARED_BEGIN

#define ASHIKHMIN_SHIRLEY_RD 0u
#define ASHIKHMIN_SHIRLEY_RS 3u
#define ASHIKHMIN_SHIRLEY_NU 6u
#define ASHIKHMIN_SHIRLEY_NV 7u

SHARED_FN float ashikhminShirleyPow5(float x) {
  float x2 = x * x;
  return x2 * x2 * x;
}

SHARED_FN vec3 ashikhminShirleyEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 rd = brdfParam3(p, ASHIKHMIN_SHIRLEY_RD);
  vec3 rs = brdfParam3(p, ASHIKHMIN_SHIRLEY_RS);
  float nu = brdfParam(p, ASHIKHMIN_SHIRLEY_NU);
  float nv = brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
  vec3 h = brdfHalf(wi, wo);
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  // ch^e = exp(e log ch), e log ch = (nu hx^2 + nv hy^2) * 0.5 log(1 - s2) / s2 (finite at h = n).
  float s2 = brdfSin2(h);
  float lobe = exp((nu * h.x * h.x + nv * h.y * h.y) * 0.5f * brdfLog1mOverX(s2));
  float spec = sqrt((nu + 1.0f) * (nv + 1.0f)) * (0.125f * NUSSELT_INV_PI) * lobe / (cb * max(wi.z, wo.z));
  float diff = (28.0f / (23.0f * NUSSELT_PI)) * (1.0f - ashikhminShirleyPow5(1.0f - 0.5f * wi.z)) *
               (1.0f - ashikhminShirleyPow5(1.0f - 0.5f * wo.z));
  return spec * fresnelSchlick3(cb, rs) + diff * rd * (vec3(1.0f) - rs);
}

// ---- Analytic sampling (sampling_common.h): mixture with cosine (weight lum(rd (1 - rs))
// against lum(rs)); h with pdf_h = sqrt((nu+1)(nv+1)) / (2 pi) cos theta_h^(nu cos^2 phi + nv
// sin^2 phi) (Ashikhmin & Shirley 2000, eq. 9 and its sampling formulas) ----
SHARED_FN float ashikhminShirleyAnalyticDiffuseProbability(BrdfParams p) {
  vec3 rs = brdfParam3(p, ASHIKHMIN_SHIRLEY_RS);
  return analyticMixtureProbability(luminance(brdfParam3(p, ASHIKHMIN_SHIRLEY_RD) * (vec3(1.0f) - rs)), luminance(rs));
}
// pdf_h(h) / (4 wo.h) (exponent as ashikhminShirleyEval).
SHARED_FN float ashikhminShirleyAnalyticHalfPdf(float nu, float nv, vec3 wi, vec3 wo) {
  vec3 h = brdfHalf(wi, wo);
  if (h.z <= 0.0f) return 0.0f;
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  float s2 = brdfSin2(h);
  float lobe = exp((nu * h.x * h.x + nv * h.y * h.y) * 0.5f * brdfLog1mOverX(s2));
  return sqrt((nu + 1.0f) * (nv + 1.0f)) * (0.5f * NUSSELT_INV_PI) * lobe / (4.0f * cb);
}
SHARED_FN bool ashikhminShirleyAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  float ux = u.x;
  if (!analyticPickLobe(ashikhminShirleyAnalyticDiffuseProbability(p), ux)) return analyticCosineSample(ux, u.y, d);
  float phi = NUSSELT_TWO_PI * u.y;
  float nu = brdfParam(p, ASHIKHMIN_SHIRLEY_NU);
  float nv = brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
  // tan phi_h = sqrt((nu+1)/(nv+1)) tan(2 pi u.y), in the quadrant of 2 pi u.y.
  vec2 cs = normalize(vec2(sqrt(nv + 1.0f) * cos(phi), sqrt(nu + 1.0f) * sin(phi)));
  float e = nu * cs.x * cs.x + nv * cs.y * cs.y;
  float omc = analyticLobeOneMinusCos(1.0f - ux, e);
  float s = sqrt(max(omc * (2.0f - omc), 0.0f));
  return analyticReflectHalf(wo, normalize(vec3(s * cs.x, s * cs.y, 1.0f - omc)), d);
}
SHARED_FN float ashikhminShirleyAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  float pd = ashikhminShirleyAnalyticDiffuseProbability(p);
  float spec = pd < 1.0f ? ashikhminShirleyAnalyticHalfPdf(brdfParam(p, ASHIKHMIN_SHIRLEY_NU),
                                                           brdfParam(p, ASHIKHMIN_SHIRLEY_NV), wi, wo)
                         : 0.0f;
  return analyticMix(pd, wi, spec);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// ASHIKHMIN_SHIRLEY_DELTA: 0 (evaluated and light-sampled).
// ASHIKHMIN_SHIRLEY_ANALYTIC: 1, the analytic strategy uses ashikhminShirleyAnalyticSample / ashikhminShirleyAnalyticPdf.
#define ASHIKHMIN_SHIRLEY_DELTA 0
#define ASHIKHMIN_SHIRLEY_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits ashikhminShirleyTraits(const BrdfParams& p) {
  ModelTraits t;
  t.anisotropic = shared::brdfParam(p, ASHIKHMIN_SHIRLEY_NU) != shared::brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
  return t;
}
inline void ashikhminShirleySpec(ModelSpec& m) {
  using namespace spec;
  m.name = "ashikhmin_shirley";
  m.summary = "Ashikhmin-Shirley 2000 anisotropic Phong";
  m.params.push_back(colour("rd", ASHIKHMIN_SHIRLEY_RD, 0.5f, 0.0f, 1.0f, "diffuse reflectance"));
  m.params.push_back(colour("rs", ASHIKHMIN_SHIRLEY_RS, 0.05f, 0.0f, 1.0f, "specular reflectance at normal incidence"));
  m.params.push_back(scalar("nu", ASHIKHMIN_SHIRLEY_NU, 100.0f, 1.0f, 100000.0f, false, "exponent along x"));
  m.params.push_back(scalar("nv", ASHIKHMIN_SHIRLEY_NV, 100.0f, 1.0f, 100000.0f, false, "exponent along y"));
  m.typical = {N("rd", 0.5), N("rs", 0.05), N("nu", 100), N("nv", 100)};
  m.hard = {N("rd", 0), N("rs", 0.9), N("nu", 10), N("nv", 10000)};
  m.traits = &ashikhminShirleyTraits;
}
}  // namespace nusselt::models
#endif

#endif
