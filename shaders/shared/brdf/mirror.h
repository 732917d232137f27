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

// ---- Delta sampling (dispatch.h) ----
// wi = R(wo) with weight F(cos theta_o); the source roulette continues with luminance(F).
SHARED_FN bool mirrorDeltaSample(BrdfParams p, vec3 wo, bool inside, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                                 OUT(float) continuation) {
  BRDF_UNUSED(inside);
  BRDF_UNUSED(u);
  wi = brdfReflectZ(wo);
  weight = mirrorReflectance(p, wo.z);
  continuation = min(1.0f, luminance(weight));
  return true;
}

SHARED_FN float mirrorDeltaChoiceAlbedo(BrdfParams p, vec3 wo, bool largestChannel) {
  vec3 F = mirrorReflectance(p, wo.z);
  return largestChannel ? maxComponent(F) : luminance(F);
}

// A mirror only reflects.
SHARED_FN float mirrorTransmissionEtaScale(BrdfParams p, bool inside) {
  BRDF_UNUSED(p);
  BRDF_UNUSED(inside);
  return 1.0f;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// MIRROR_DELTA: 1, a delta model: never evaluated or light-sampled; sampled by mirrorDeltaSample.
// MIRROR_ANALYTIC: 0: the analytic strategy samples the cosine.
#define MIRROR_DELTA 1
#define MIRROR_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void mirrorSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "mirror";
  m.summary = "ideal mirror with complex-index Fresnel (delta)";
  ParamSpec eta = colour("eta", MIRROR_ETA, 0.96f, 0.0f, 20.0f, "real part of the relative index");
  eta.minExclusive = true;
  m.params.push_back(eta);
  m.params.push_back(colour("k", MIRROR_K, 6.69f, 0.0f, 20.0f, "extinction coefficient"));
  m.typical = {N("eta", 0.96), N("k", 6.69)};
  m.hard = {N("eta", 0.2), N("k", 3.0)};
}
}  // namespace nusselt::models
#endif

#endif
