// torrance_sparrow: Torrance-Sparrow / Cook-Torrance with the Beckmann distribution, V-cavity
// masking-shadowing and the exact Fresnel term, normalised as Walter et al. 2007
// (docs/brdf-models.md 2.6):
//   f = kd / pi + ks Fr(cb; eta, k) Dbeck(h; m) G / (4 ci co),  G = min(1, 2 ch co / cb, 2 ch ci / cb)
//   kd, ks: colour in [0, 1]; m in (0, 1]; eta > 0; k >= 0.
#ifndef NUSSELT_BRDF_TORRANCE_SPARROW_H
#define NUSSELT_BRDF_TORRANCE_SPARROW_H
#include "common.h"
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

SHARED_END
#endif
