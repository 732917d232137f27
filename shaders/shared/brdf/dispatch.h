// dispatch.h: the switches that map a model id to its shared definition, generated from the
// model list (models.h). In a shade stage the model id is a specialization constant, so each
// switch folds to the one model that stage serves (lavapipe runs every reachable branch body:
// see README "Design").
#ifndef NUSSELT_BRDF_DISPATCH_H
#define NUSSELT_BRDF_DISPATCH_H
#include "../layout.h"
#include "models.h"
SHARED_BEGIN

// Delta models (<NAME>_DELTA 1: mirror, dielectric) are never evaluated or light-sampled: they
// are sampled by deltaSample below.
SHARED_FN bool modelIsDelta(uint model) {
#define NUSSELT_DELTA_CASE_1(NAME, fn) case MODEL_##NAME: return true;
#define NUSSELT_DELTA_CASE_0(NAME, fn)
#define NUSSELT_DELTA_CASE(id, NAME, fn) NUSSELT_CAT(NUSSELT_DELTA_CASE_, NAME##_DELTA)(NAME, fn)
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_DELTA_CASE)
    default: break;
  }
  return false;
}

// Models whose f is not zero below the surface (<NAME>_TRANSMITS 1 in the model's header,
// ModelSpec::transmits; RoughDielectric.CatalogueAndDispatch keeps the two equal):
// rough_dielectric and rough_thin_dielectric. A sample or a light sample of theirs may lie on
// either side; their parameters may differ with the side the path is on (transmissionInsideParams).
SHARED_FN bool modelTransmits(uint model) {
  return (ROUGH_DIELECTRIC_TRANSMITS != 0 && model == MODEL_ROUGH_DIELECTRIC) ||
         (ROUGH_THIN_DIELECTRIC_TRANSMITS != 0 && model == MODEL_ROUGH_THIN_DIELECTRIC);
}

// Models whose evaluation costs an order of magnitude more than the others' (measured in `nusselt
// bench error`'s cosine column, which evaluates f once per sample: htsg ~170 ns, poulin_fournier
// ~175 ns, every other model 7-25 ns on lavapipe): htsg sums a series, poulin_fournier integrates
// its cylinder profile. The quadtree's rejection shares its trials across a subgroup for them
// (quadtree.h, quadLeafSampleShared), where fewer rounds of evaluations pay for the exchange.
SHARED_FN bool modelCostlyEval(uint model) { return model == MODEL_HTSG || model == MODEL_POULIN_FOURNIER; }

// The offset of a model's `tint` parameter (the colour of the light it transmits at each crossing:
// glTF's base colour on KHR_materials_transmission), or INVALID_INDEX for a model without one.
SHARED_FN uint modelTintParam(uint model) {
  if (model == MODEL_DIELECTRIC) return DIELECTRIC_TINT;
  if (model == MODEL_THIN_DIELECTRIC) return THIN_DIELECTRIC_TINT;
  if (model == MODEL_ROUGH_DIELECTRIC) return ROUGH_DIELECTRIC_TINT;
  if (model == MODEL_ROUGH_THIN_DIELECTRIC) return ROUGH_THIN_DIELECTRIC_TINT;
  return INVALID_INDEX;
}

// The parameters of a transmitting model seen from the inside (the -z side of its frame) in the
// frame turned over (inside = +z), so that f(wi, wo; p) = f(flipZ(wi), flipZ(wo); inside(p)); p for
// every other model, and for rough_thin_dielectric, whose sheet has the same medium on both sides.
SHARED_FN BrdfParams transmissionInsideParams(uint model, BrdfParams p) {
  if (model == MODEL_ROUGH_DIELECTRIC) return roughDielectricInside(p);
  return p;
}

// BRDF value f(wi, wo) [1/sr] in the local frame (normal +z); wi towards the light, wo towards
// the viewer. Zero for delta models and for directions below the surface.
SHARED_FN vec3 brdfEval(uint model, BrdfParams p, vec3 wi, vec3 wo) {
#define NUSSELT_EVAL_CASE(id, NAME, fn) case MODEL_##NAME: return fn##Eval(p, wi, wo);
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_EVAL_CASE)
    default: break;
  }
  return vec3(0.0f);
}

// ---- Delta models: each defines (see mirror.h) ----
//   bool <fn>DeltaSample(p, wo, inside, u, OUT wi, OUT weight, OUT continuation): the sampled
//     direction, its weight (f cos / pdf) and the source roulette's continuation probability;
//   float <fn>DeltaChoiceAlbedo(p, wo, largestChannel): the directional albedo a combined
//     material's component choice uses (luminance, or the largest channel);
//   float <fn>TransmissionEtaScale(p, inside): (n_wi / n_wo)^2 for a sample that crossed the
//     surface (the throughput roulette's etaScale), 1 for a model that only reflects.
#define NUSSELT_DELTA_SAMPLE_1(NAME, fn) \
  case MODEL_##NAME: return fn##DeltaSample(p, wo, inside, u, wi, weight, continuation);
#define NUSSELT_DELTA_SAMPLE_0(NAME, fn)
#define NUSSELT_DELTA_SAMPLE(id, NAME, fn) NUSSELT_CAT(NUSSELT_DELTA_SAMPLE_, NAME##_DELTA)(NAME, fn)
SHARED_FN bool deltaSample(uint model, BrdfParams p, vec3 wo, bool inside, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                           OUT(float) continuation) {
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_DELTA_SAMPLE)
    default: break;
  }
  return false;
}

#define NUSSELT_DELTA_ALBEDO_1(NAME, fn) case MODEL_##NAME: return fn##DeltaChoiceAlbedo(p, wo, largestChannel);
#define NUSSELT_DELTA_ALBEDO_0(NAME, fn)
#define NUSSELT_DELTA_ALBEDO(id, NAME, fn) NUSSELT_CAT(NUSSELT_DELTA_ALBEDO_, NAME##_DELTA)(NAME, fn)
SHARED_FN float deltaChoiceAlbedo(uint model, BrdfParams p, vec3 wo, bool largestChannel) {
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_DELTA_ALBEDO)
    default: break;
  }
  return 0.0f;
}

#define NUSSELT_ETA_SCALE_1(NAME, fn) case MODEL_##NAME: return fn##TransmissionEtaScale(p, inside);
#define NUSSELT_ETA_SCALE_0(NAME, fn)
#define NUSSELT_ETA_SCALE(id, NAME, fn) NUSSELT_CAT(NUSSELT_ETA_SCALE_, NAME##_DELTA)(NAME, fn)
// The factor by which a refraction's radiance scaling (n_wo / n_wi)^2 is undone for the throughput
// roulette (pbrt's and Mitsuba's etaScale): (n_wi / n_wo)^2 for a sample of `model` that crossed the
// surface, 1 for everything else (rough_thin_dielectric too: the same medium on both sides). Delta models take their parameters and `inside`; a transmitting
// non-delta model (modelTransmits) its parameters as seen from wo's side (transmissionInsideParams
// applied inside), which already say the side.
SHARED_FN float transmissionEtaScale(uint model, BrdfParams p, bool inside) {
  if (model == MODEL_ROUGH_DIELECTRIC) return roughDielectricTransmissionEtaScale(p);
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_ETA_SCALE)
    default: break;
  }
  return 1.0f;
}

SHARED_END
#endif
