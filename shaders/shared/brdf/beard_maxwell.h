// beard_maxwell: Beard-Maxwell (NEF form, Westlund & Meyer 2002) (docs/brdf-models.md 2.14):
//   thetaN = theta_h, beta = portableAcos(cb)
//   f = Fr(cb; n, k) / Fr(1; n, k) * B exp(-(thetaN / sigma)^2) * ch^2 / (ci co)
//       * (1 + (thetaN_deg / omega_deg) exp(-2 beta_deg / tau_deg)) / (1 + thetaN_deg / omega_deg)
//     + rho_d + 2 rho_v / (ci + co)
// n > 0, k >= 0 (paint surface index), B >= 0 [1/sr], sigma > 0 [rad], tau_deg, omega_deg > 0
// [degrees], rho_d, rho_v: colour (rho_d is a BRDF value [1/sr]; the first-surface term is grey).
// Not bounded at the rim (1/(ci co)); not energy conserving in general.
#ifndef NUSSELT_BRDF_BEARD_MAXWELL_H
#define NUSSELT_BRDF_BEARD_MAXWELL_H
#include "common.h"
SHARED_BEGIN

#define BEARD_MAXWELL_N 0u
#define BEARD_MAXWELL_K 1u
#define BEARD_MAXWELL_B 2u
#define BEARD_MAXWELL_SIGMA 3u
#define BEARD_MAXWELL_TAU_DEG 4u
#define BEARD_MAXWELL_OMEGA_DEG 5u
#define BEARD_MAXWELL_RHO_D 6u
#define BEARD_MAXWELL_RHO_V 9u

SHARED_FN vec3 beardMaxwellEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float n = brdfParam(p, BEARD_MAXWELL_N);
  float k = brdfParam(p, BEARD_MAXWELL_K);
  float sigma = brdfParam(p, BEARD_MAXWELL_SIGMA);
  float tauDeg = brdfParam(p, BEARD_MAXWELL_TAU_DEG);
  float omegaDeg = brdfParam(p, BEARD_MAXWELL_OMEGA_DEG);
  vec3 h = brdfHalf(wi, wo);
  float cb = brdfHalfCos(wi, wo);
  float thetaN = portableAtan2(sqrt(brdfSin2(h)), h.z);
  float beta = brdfTheta(min(cb, 1.0f));
  float toDeg = 180.0f * NUSSELT_INV_PI;
  float f1 = fresnelComplex(1.0f, n, k);
  float rratio = f1 > 0.0f ? fresnelComplex(cb, n, k) / f1 : 0.0f;
  float lobe = brdfParam(p, BEARD_MAXWELL_B) * exp(-sqr(thetaN / sigma));
  float tN = thetaN * toDeg / omegaDeg;
  float so = (1.0f + tN * exp(-2.0f * beta * toDeg / tauDeg)) / (1.0f + tN);
  float surface = rratio * lobe * h.z * h.z / (wi.z * wo.z) * so;
  return vec3(surface) + brdfParam3(p, BEARD_MAXWELL_RHO_D) +
         brdfParam3(p, BEARD_MAXWELL_RHO_V) * (2.0f / (wi.z + wo.z));
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// BEARD_MAXWELL_DELTA: 0 (evaluated and light-sampled).
// BEARD_MAXWELL_ANALYTIC: 0: the analytic strategy samples the cosine.
#define BEARD_MAXWELL_DELTA 0
#define BEARD_MAXWELL_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits beardMaxwellTraits(const BrdfParams&) {
  ModelTraits t;
  t.rimExponent = 1.0f;
  return t;
}
inline void beardMaxwellSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "beard_maxwell";
  m.summary = "Beard-Maxwell (NEF form): paint first surface + volumetric terms";
  m.params.push_back(scalar("n", BEARD_MAXWELL_N, 1.5f, 0.0f, 10.0f, true, "real part of the surface index"));
  m.params.push_back(scalar("k", BEARD_MAXWELL_K, 0.0f, 0.0f, 20.0f, false, "extinction coefficient"));
  m.params.push_back(scalar("B", BEARD_MAXWELL_B, 0.5f, 0.0f, 1000.0f, false, "first-surface lobe amplitude [1/sr]"));
  m.params.push_back(scalar("sigma", BEARD_MAXWELL_SIGMA, 0.1f, 0.001f, 1.5f, false, "facet tilt width [rad]"));
  m.params.push_back(scalar("tau_deg", BEARD_MAXWELL_TAU_DEG, 20.0f, 0.0f, 180.0f, true, "shadowing constant [deg]"));
  m.params.push_back(scalar("omega_deg", BEARD_MAXWELL_OMEGA_DEG, 50.0f, 0.0f, 1000.0f, true, "obscuration constant [deg]"));
  m.params.push_back(colour("rho_d", BEARD_MAXWELL_RHO_D, 0.05f, 0.0f, 1.0f, "volumetric Lambertian BRDF value [1/sr]"));
  m.params.push_back(colour("rho_v", BEARD_MAXWELL_RHO_V, 0.05f, 0.0f, 1.0f, "directional-volumetric coefficient"));
  m.typical = {N("n", 1.5), N("k", 0), N("B", 0.5), N("sigma", 0.1), N("tau_deg", 20), N("omega_deg", 50),
               N("rho_d", 0.05), N("rho_v", 0.05)};
  m.hard = {N("n", 1.5), N("k", 0), N("B", 10), N("sigma", 0.02), N("tau_deg", 5), N("omega_deg", 5),
            N("rho_d", 0), N("rho_v", 0.1)};
  m.traits = &beardMaxwellTraits;
}
}  // namespace nusselt::models
#endif

#endif
