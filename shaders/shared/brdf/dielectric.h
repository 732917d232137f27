// dielectric: ideal smooth interface with Fresnel reflection/refraction and total internal
// reflection (docs/brdf-models.md 2.19). eta = n_inside / n_outside (inside = -z side).
// Delta model: dielectricEval is 0. Analytic sampling: dielectricReflectance gives the
// probability of reflection; dielectricRefract the transmitted direction.
#ifndef NUSSELT_BRDF_DIELECTRIC_H
#define NUSSELT_BRDF_DIELECTRIC_H
#include "common.h"
SHARED_BEGIN

#define DIELECTRIC_ETA 0u

SHARED_FN vec3 dielectricEval(BrdfParams p, vec3 wi, vec3 wo) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(wi);
  BRDF_UNUSED(wo);
  return vec3(0.0f);
}

// Relative index seen by a direction w: eta from outside (w.z > 0), 1/eta from inside.
SHARED_FN float dielectricEtaFor(float eta, vec3 w) { return w.z >= 0.0f ? eta : 1.0f / eta; }

// Reflectance R for direction w (either side; 1 under total internal reflection). T = 1 - R.
SHARED_FN float dielectricReflectance(float eta, vec3 w) {
  return fresnelDielectric(abs(w.z), dielectricEtaFor(eta, w));
}

// Refracted direction t of w (pointing away from the surface on the other side). Returns false
// (and t = R(w)) under total internal reflection. Radiance arriving along t and leaving along w
// crosses from the side of t (index n_a) to the side of w (index n_b): scale it by
// (n_b / n_a)^2 = 1 / e^2, e = dielectricEtaFor(eta, w); drop the factor for importance.
SHARED_FN bool dielectricRefract(float eta, vec3 w, OUT(vec3) t) {
  float e = dielectricEtaFor(eta, w);
  float c = abs(w.z);
  float s2t = (1.0f - c * c) / (e * e);
  if (s2t >= 1.0f) {
    t = brdfReflectZ(w);
    return false;
  }
  float ct = sqrt(1.0f - s2t);
  float sgn = w.z >= 0.0f ? 1.0f : -1.0f;
  t = normalize(-w / e + vec3(0.0f, 0.0f, sgn * (c / e - ct)));
  return true;
}

SHARED_END
#endif
