// dielectric: ideal smooth interface with Fresnel reflection/refraction and total internal
// reflection (docs/brdf-models.md 2.19). eta = n_inside / n_outside (inside = -z side). tint: the
// colour of the light the interface transmits (1 = clear), at every crossing, as glTF's baseColor
// tints KHR_materials_transmission ("a coloured foil" on the volume's boundary); reflection is
// untinted.
// Delta model: dielectricEval is 0. Analytic sampling: dielectricReflectance gives the
// probability of reflection; dielectricRefract the transmitted direction.
#ifndef NUSSELT_BRDF_DIELECTRIC_H
#define NUSSELT_BRDF_DIELECTRIC_H
#include "common.h"
SHARED_BEGIN

#define DIELECTRIC_ETA 0u
#define DIELECTRIC_TINT 1u

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

// ---- Delta sampling (dispatch.h) ----
// Reflect with probability R (Fresnel), refract otherwise: weight 1 for a reflection, tint times the
// radiance scaling (n_wo / n_wi)^2 across the interface for refraction (catalogue 2.19). inside:
// the path arrived from the inside, where the relative index is 1/eta.
SHARED_FN bool dielectricDeltaSample(BrdfParams p, vec3 wo, bool inside, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                                     OUT(float) continuation) {
  float eta = brdfParam(p, DIELECTRIC_ETA);
  float etaRel = inside ? 1.0f / eta : eta;  // n(wi side) / n(wo side) for transmission
  float R = fresnelDielectric(wo.z, etaRel);
  vec3 t;
  if (u.x < R || !dielectricRefract(etaRel, wo, t)) {
    wi = brdfReflectZ(wo);
    weight = vec3(1.0f);
  } else {
    wi = t;
    weight = brdfParam3(p, DIELECTRIC_TINT) * (1.0f / (etaRel * etaRel));
  }
  // The walk does not end at a lossless interface: the radiance scaling is not an albedo.
  continuation = 1.0f;
  return true;
}

// R + (1 - R) t, t the tint's luminance or largest channel: 1 for a clear (lossless) interface,
// written as 1 - (1 - t)(1 - R) so that t = 1 gives exactly 1.
SHARED_FN float dielectricDeltaChoiceAlbedo(BrdfParams p, vec3 wo, bool largestChannel) {
  vec3 tint = brdfParam3(p, DIELECTRIC_TINT);
  float t = largestChannel ? maxComponent(tint) : luminance(tint);
  return 1.0f - (1.0f - t) * (1.0f - fresnelDielectric(wo.z, brdfParam(p, DIELECTRIC_ETA)));
}

// (n_wi / n_wo)^2 of a refracted sample.
SHARED_FN float dielectricTransmissionEtaScale(BrdfParams p, bool inside) {
  float eta = brdfParam(p, DIELECTRIC_ETA);
  float etaRel = inside ? 1.0f / eta : eta;
  return etaRel * etaRel;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// DIELECTRIC_DELTA: 1, a delta model: never evaluated or light-sampled; sampled by dielectricDeltaSample.
// DIELECTRIC_ANALYTIC: 0: the analytic strategy samples the cosine.
#define DIELECTRIC_DELTA 1
#define DIELECTRIC_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void dielectricSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "dielectric";
  m.summary = "ideal refraction with Fresnel and total internal reflection (delta)";
  m.params.push_back(scalar("eta", DIELECTRIC_ETA, 1.5f, 0.1f, 10.0f, false, "n_inside / n_outside"));
  m.params.push_back(colour("tint", DIELECTRIC_TINT, 1.0f, 0.0f, 1.0f, "colour of the transmitted light, per crossing"));
  m.typical = {N("eta", 1.5)};
  m.hard = {N("eta", 2.42)};
}
}  // namespace nusselt::models
#endif

#endif
