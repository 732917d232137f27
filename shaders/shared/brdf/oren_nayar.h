// oren_nayar: the full Oren-Nayar 1994 model with the interreflection term
// (docs/brdf-models.md 2.11). rho: colour in [0, 1]; sigma in [0, 1.5] rad; interreflection 0/1.
// L1 can become slightly negative for large sigma when both directions approach grazing in
// opposite azimuths (C2 tan(beta) term of the fit exceeds C1); f is clamped at 0 there.
#ifndef NUSSELT_BRDF_OREN_NAYAR_H
#define NUSSELT_BRDF_OREN_NAYAR_H
#include "common.h"
SHARED_BEGIN

#define OREN_NAYAR_RHO 0u
#define OREN_NAYAR_SIGMA 3u
#define OREN_NAYAR_INTERREFLECTION 4u

SHARED_FN vec3 orenNayarEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 rho = brdfParam3(p, OREN_NAYAR_RHO);
  float sigma = brdfParam(p, OREN_NAYAR_SIGMA);
  float inter = brdfParam(p, OREN_NAYAR_INTERREFLECTION);
  float s2 = sigma * sigma;
  float ti = brdfTheta(wi.z);
  float to = brdfTheta(wo.z);
  float alpha = max(ti, to);
  float beta = min(ti, to);
  // tan(beta) from the direction with the larger cosine (exact, no tan near 90 degrees).
  float cbeta = max(wi.z, wo.z);
  float tanBeta = cosFromSin(cbeta) / cbeta;
  float cosPhi = brdfCosPhi(wi, wo);
  float b2 = 2.0f * beta * NUSSELT_INV_PI;
  float C1 = 1.0f - 0.5f * s2 / (s2 + 0.33f);
  float C2 = 0.45f * s2 / (s2 + 0.09f) * (cosPhi >= 0.0f ? sin(alpha) : sin(alpha) - b2 * b2 * b2);
  float C3 = 0.125f * s2 / (s2 + 0.09f) * sqr(4.0f * alpha * beta * NUSSELT_INV_PI * NUSSELT_INV_PI);
  float L1 = C1 + cosPhi * C2 * tanBeta + (1.0f - abs(cosPhi)) * C3 * tan(0.5f * (alpha + beta));
  float L2 = 0.17f * s2 / (s2 + 0.13f) * (1.0f - cosPhi * b2 * b2);
  vec3 f = rho * NUSSELT_INV_PI * L1 + inter * L2 * NUSSELT_INV_PI * rho * rho;
  return max(f, vec3(0.0f));
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// OREN_NAYAR_DELTA: 0 (evaluated and light-sampled).
// OREN_NAYAR_ANALYTIC: 0: the analytic strategy samples the cosine.
#define OREN_NAYAR_DELTA 0
#define OREN_NAYAR_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void orenNayarSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "oren_nayar";
  m.summary = "Oren-Nayar 1994 rough diffuse, full model";
  m.params.push_back(colour("rho", OREN_NAYAR_RHO, 0.8f, 0.0f, 1.0f, "albedo of the facets"));
  m.params.push_back(scalar("sigma", OREN_NAYAR_SIGMA, 0.35f, 0.0f, 1.5f, false, "slope angle std. dev. [rad]"));
  m.params.push_back(choice("interreflection", OREN_NAYAR_INTERREFLECTION, 1, {"off", "on"},
                            "include the L2 interreflection term (0/off or 1/on)"));
  m.typical = {N("rho", 0.8), N("sigma", 0.35), N("interreflection", 1)};
  m.hard = {N("rho", 1), N("sigma", 0.7), N("interreflection", 1)};
}
}  // namespace nusselt::models
#endif

#endif
