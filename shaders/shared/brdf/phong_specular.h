// phong_specular: the reciprocal Phong lobe of the random-walk source (Szirmay-Kalos), not
// normalised: f = ks max(0, cos alpha)^n, cos alpha = R(wi).wo.
//   ks: colour >= 0; n >= 0. Energy conserving iff ks <= (n+2)/(2 pi). docs/brdf-models.md 2.2.
#ifndef NUSSELT_BRDF_PHONG_SPECULAR_H
#define NUSSELT_BRDF_PHONG_SPECULAR_H
#include "common.h"
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

SHARED_END
#endif
