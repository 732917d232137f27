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

SHARED_END
#endif
