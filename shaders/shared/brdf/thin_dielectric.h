// thin_dielectric: an infinitely thin sheet of a dielectric with the same medium on both sides
// (glTF's thin-walled transmission: KHR_materials_transmission without KHR_materials_volume).
// Light reflects at its two interfaces and between them, and leaves straight through: a sheet of
// vanishing thickness does not bend rays. eta = n_sheet / n_outside. With R1 the Fresnel
// reflectance at the angle of incidence (the inner interface has the same, by reciprocity), the
// sheet reflects R = R1 + (1 - R1)^2 R1 (1 + R1^2 + R1^4 + ...) = 2 R1 / (1 + R1) and transmits
// T = 1 - R = (1 - R1) / (1 + R1), along -wo, times tint (1 = clear; glTF's baseColor tints thin-walled
// transmission); nothing else is absorbed.
// Delta model: thinDielectricEval is 0.
#ifndef NUSSELT_BRDF_THIN_DIELECTRIC_H
#define NUSSELT_BRDF_THIN_DIELECTRIC_H
#include "common.h"
SHARED_BEGIN

#define THIN_DIELECTRIC_ETA 0u
#define THIN_DIELECTRIC_TINT 1u

SHARED_FN vec3 thinDielectricEval(BrdfParams p, vec3 wi, vec3 wo) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(wi);
  BRDF_UNUSED(wo);
  return vec3(0.0f);
}

// The sheet's reflectance 2 R1 / (1 + R1) for a direction w on either side.
SHARED_FN float thinDielectricReflectance(float eta, vec3 w) {
  float r1 = fresnelDielectric(abs(w.z), eta);
  return 2.0f * r1 / (1.0f + r1);
}

// ---- Delta sampling (dispatch.h) ----
// Reflect with probability R, else pass straight through: weight 1, or tint for the passage (no
// radiance scaling: the same medium on both sides). The sheet is symmetric, so `inside` does not matter.
SHARED_FN bool thinDielectricDeltaSample(BrdfParams p, vec3 wo, bool inside, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                                         OUT(float) continuation) {
  BRDF_UNUSED(inside);
  float R = thinDielectricReflectance(brdfParam(p, THIN_DIELECTRIC_ETA), wo);
  bool reflect = u.x < R;
  wi = reflect ? brdfReflectZ(wo) : -wo;
  weight = reflect ? vec3(1.0f) : brdfParam3(p, THIN_DIELECTRIC_TINT);
  continuation = 1.0f;  // lossless: the walk does not end here
  return true;
}

// R + (1 - R) t as the dielectric's (1 for a clear sheet, exactly).
SHARED_FN float thinDielectricDeltaChoiceAlbedo(BrdfParams p, vec3 wo, bool largestChannel) {
  vec3 tint = brdfParam3(p, THIN_DIELECTRIC_TINT);
  float t = largestChannel ? maxComponent(tint) : luminance(tint);
  return 1.0f - (1.0f - t) * (1.0f - thinDielectricReflectance(brdfParam(p, THIN_DIELECTRIC_ETA), wo));
}

// The same medium on both sides: a transmitted sample's radiance is not rescaled.
SHARED_FN float thinDielectricTransmissionEtaScale(BrdfParams p, bool inside) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(inside);
  return 1.0f;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// THIN_DIELECTRIC_DELTA: 1, a delta model, sampled by thinDielectricDeltaSample.
// THIN_DIELECTRIC_ANALYTIC: 0: the analytic strategy samples the cosine.
#define THIN_DIELECTRIC_DELTA 1
#define THIN_DIELECTRIC_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void thinDielectricSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "thin_dielectric";
  m.summary = "thin dielectric sheet: Fresnel reflection between its faces, straight transmission (delta)";
  m.params.push_back(scalar("eta", THIN_DIELECTRIC_ETA, 1.5f, 0.1f, 10.0f, false, "n_sheet / n_outside"));
  m.params.push_back(colour("tint", THIN_DIELECTRIC_TINT, 1.0f, 0.0f, 1.0f, "colour of the transmitted light"));
  m.typical = {N("eta", 1.5)};
  m.hard = {N("eta", 2.42)};
}
}  // namespace nusselt::models
#endif

#endif
