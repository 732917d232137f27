// ward: Ward 1992 anisotropic Gaussian lobe with three normalisations (docs/brdf-models.md 2.7):
//   E = exp(-((H.x/ax)^2 + (H.y/ay)^2) / H.z^2)
//   ward92: E / (4 pi ax ay sqrt(ci co));  duer: E / (4 pi ax ay ci co);
//   gmd: E (H.H) / (pi ax ay H.z^4)   (H = wi + wo unnormalised)
//   f = kd / pi + ks spec.  kd, ks: colour in [0, 1]; ax, ay in (0, 1]; normalization 0/1/2.
#ifndef NUSSELT_BRDF_WARD_H
#define NUSSELT_BRDF_WARD_H
#include "common.h"
SHARED_BEGIN

#define WARD_KD 0u
#define WARD_KS 3u
#define WARD_AX 6u
#define WARD_AY 7u
#define WARD_NORMALIZATION 8u
#define WARD_NORM_WARD92 0u
#define WARD_NORM_DUER 1u
#define WARD_NORM_GMD 2u

SHARED_FN vec3 wardEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float ax = brdfParam(p, WARD_AX);
  float ay = brdfParam(p, WARD_AY);
  uint norm = uint(brdfParam(p, WARD_NORMALIZATION) + 0.5f);
  vec3 H = wi + wo;
  float hx = H.x / ax;
  float hy = H.y / ay;
  float e = exp(-(hx * hx + hy * hy) / (H.z * H.z));
  float spec;
  if (norm == WARD_NORM_DUER) {
    spec = e / (4.0f * NUSSELT_PI * ax * ay * wi.z * wo.z);
  } else if (norm == WARD_NORM_GMD) {
    float hz2 = H.z * H.z;
    spec = e * dot(H, H) / (NUSSELT_PI * ax * ay * hz2 * hz2);
  } else {
    spec = e / (4.0f * NUSSELT_PI * ax * ay * sqrt(wi.z * wo.z));
  }
  return brdfParam3(p, WARD_KD) * NUSSELT_INV_PI + brdfParam3(p, WARD_KS) * spec;
}

SHARED_END
#endif
