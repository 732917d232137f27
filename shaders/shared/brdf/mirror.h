// mirror: ideal specular reflection with the exact complex-index Fresnel term
// (docs/brdf-models.md 2.18). Delta model: mirrorEval is 0 (never evaluated or light-sampled);
// analytic sampling uses wo = R(wi) with weight mirrorReflectance(p, cos theta_i).
//   eta, k: colour (complex relative index per channel).
#ifndef NUSSELT_BRDF_MIRROR_H
#define NUSSELT_BRDF_MIRROR_H
#include "common.h"
SHARED_BEGIN

#define MIRROR_ETA 0u
#define MIRROR_K 3u

SHARED_FN vec3 mirrorEval(BrdfParams p, vec3 wi, vec3 wo) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(wi);
  BRDF_UNUSED(wo);
  return vec3(0.0f);
}

// Fraction of energy reflected at incidence cosine c (per channel).
SHARED_FN vec3 mirrorReflectance(BrdfParams p, float c) {
  return fresnelComplex3(abs(c), brdfParam3(p, MIRROR_ETA), brdfParam3(p, MIRROR_K));
}

SHARED_END
#endif
