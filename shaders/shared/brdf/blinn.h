// blinn: Blinn-Phong half-vector lobe, exactly normalised (docs/brdf-models.md 2.5):
//   f = kd / pi + ks N(n) max(0, cos theta_h)^n,  N(n) = (n+2)(n+4) / (8 pi (2^(-n/2) + n))
//   kd, ks: colour in [0, 1]; n >= 0. a(0) = kd + ks exactly.
#ifndef NUSSELT_BRDF_BLINN_H
#define NUSSELT_BRDF_BLINN_H
#include "common.h"
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

SHARED_END
#endif
