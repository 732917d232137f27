// combined.h: combined materials f = sum_k w_k f_k (the random-walk source's "sum of elementary
// BRDFs"): the choice of a component at a bounce, and the numbers MIS needs. Shared by the shade
// stage and the CPU tests (docs/models.md, "Combined materials").
//
// The estimator (albedo mode, the source's low-variance one). For the current wo every component
// gets a number a_k = w_k A_k(wo) >= 0 computed from wo alone, before anything is sampled:
// A_k = the tabulated directional albedo (quadAlbedo) for quadtree-sampled components, the
// Fresnel reflectance for a mirror, 1 for a dielectric (lossless), and a CPU-tabulated albedo
// (GpuComponent.albedoLo/Hi) for the other samplers. With S = sum a_k:
//   S <= 1: choose k with P_k = a_k, end the walk with probability 1 - S;
//   S >  1: choose k with P_k = a_k / S (never end here; the weight below stays honest).
// Then sample wi from component k (density pdf_k) and multiply the throughput by
//   w_k f_k(wi, wo) cos / (P_k pdf_k)   (w_k * the delta lobe's weight / P_k for delta lobes).
// Unbiased for ANY a_k that is a function of wo only (it is a known number when k is chosen) and
// positive wherever w_k f_k is not zero: E[weight] = sum_k P_k * integral w_k f_k cos / P_k =
// integral f cos. Choosing a_k ~ the albedo only makes the surviving weights ~1 (exactly 1 for a
// grey component sampled proportionally to f cos on a table): low variance, no extra roulette.
//
// Uniform mode (for comparison): P_k = 1/n, then a separate roulette with probability
// q = min(1, S) (the same albedo estimates); weight w_k f_k cos / (P_k q pdf_k).
//
// Under the throughput roulette (ROULETTE_THROUGHPUT, the default) the choice ends nothing: the
// proportional mode (COMPONENTS_PROPORTIONAL, chosen by combinedChoiceMode) takes P_k = a_k / S
// with a_k = w_k x the LARGEST RGB channel of the component's albedo (componentChoiceMaxAlbedo),
// then the path's throughput roulette decides whether the walk goes on. A luminance choice would
// multiply a saturated component's dominant channel by albedo_c / luminance (3.7 for the Cornell
// box's red wall) whenever it is picked; with the largest channel the weight of a component k,
// S x (its sample weight) / (w_k max_c A_k), stays below S per channel for components whose colour
// does not vary with direction (Lambert: exactly S rho_c / max rho), a bounded factor otherwise.
#ifndef NUSSELT_COMBINED_H
#define NUSSELT_COMBINED_H
#include "bsdf_sampling.h"
SHARED_BEGIN

// The proportional choice of the throughput roulette (never ends the walk; see the top). Not a
// value of Globals.options.y: combinedChoiceMode derives it.
#define COMPONENTS_PROPORTIONAL 2u

// The choice mode of a render: the source's albedo choice (which includes the roulette) under the
// albedo roulette, the proportional one under the throughput roulette; uniform stays uniform.
SHARED_FN uint combinedChoiceMode(uint components, uint roulette) {
  if (components == COMPONENTS_UNIFORM) return COMPONENTS_UNIFORM;
  return roulette == ROULETTE_ALBEDO ? COMPONENTS_ALBEDO : COMPONENTS_PROPORTIONAL;
}

// Component k's value in a vec4 of per-component numbers (k < MAX_COMPONENTS).
SHARED_FN float componentAt(vec4 v, uint k) {
  return k == 0u ? v.x : (k == 1u ? v.y : (k == 2u ? v.z : v.w));
}

// The CPU-tabulated albedo estimate at cos theta_o = c: linear between the nodes i / 7.
SHARED_FN float componentTableAlbedo(vec4 lo, vec4 hi, float c) {
  float x = clamp(c, 0.0f, 1.0f) * float(COMPONENT_ALBEDO_NODES - 1u);
  uint i = min(uint(x), COMPONENT_ALBEDO_NODES - 2u);
  float t = x - float(i);
  float a0 = i < 4u ? componentAt(lo, i) : componentAt(hi, i - 4u);
  float a1 = i + 1u < 4u ? componentAt(lo, i + 1u) : componentAt(hi, i - 3u);
  return mix(a0, a1, t);
}

// a_k = w_k A_k(wo): the (unnormalised) choice weight of one component, from wo only.
// strategy: the shade stage's SAMPLER; model: the component's model (a specialization constant
// at every call site of the shade stage, so only its branch remains).
SHARED_FN float componentChoiceAlbedo(uint strategy, uint model, GpuComponent C, vec3 wo) {
  float w = C.data.x;
  if (!(w > 0.0f) || wo.z <= 0.0f) return 0.0f;
  if (modelIsDelta(model)) return w * deltaChoiceAlbedo(model, C.params, wo, false);
  if (effectiveSampler(strategy, C.info.y) == SAMPLER_QUADTREE)
    return w * quadAlbedo(C.info.y, wo.z, portableAtan2(wo.y, wo.x));
  return w * componentTableAlbedo(C.albedoLo, C.albedoHi, wo.z);
}

// a_k = w_k max_c A_k,c(wo): the choice weight of the proportional mode, from wo only. The CPU
// tabulates the largest channel of every non-delta component's albedo (GpuComponent.albedoLo/Hi)
// for this mode; a mirror takes its largest Fresnel channel, a dielectric 1 (lossless).
SHARED_FN float componentChoiceMaxAlbedo(uint model, GpuComponent C, vec3 wo) {
  float w = C.data.x;
  if (!(w > 0.0f) || wo.z <= 0.0f) return 0.0f;
  if (modelIsDelta(model)) return w * deltaChoiceAlbedo(model, C.params, wo, true);
  return w * componentTableAlbedo(C.albedoLo, C.albedoHi, wo.z);
}

// The choice weight a_k of the render's choice mode (combinedChoiceMode).
SHARED_FN float componentChoiceWeight(uint choiceMode, uint strategy, uint model, GpuComponent C, vec3 wo) {
  if (choiceMode == COMPONENTS_PROPORTIONAL) return componentChoiceMaxAlbedo(model, C, wo);
  return componentChoiceAlbedo(strategy, model, C, wo);
}

// Choice probabilities P_k of the n = count components from their choice weights a (see the top).
// Their sum is min(1, S) in albedo mode (the rest ends the walk), 1 in uniform mode.
SHARED_FN vec4 combinedChoiceProbabilities(uint mode, uint count, vec4 a) {
  if (mode == COMPONENTS_UNIFORM) {
    float p = 1.0f / float(max(count, 1u));
    return vec4(count > 0u ? p : 0.0f, count > 1u ? p : 0.0f, count > 2u ? p : 0.0f, count > 3u ? p : 0.0f);
  }
  float s = a.x + a.y + a.z + a.w;
  if (mode == COMPONENTS_PROPORTIONAL) return s > 0.0f ? a / s : vec4(0.0f);
  // The guard against throughput growth of non-energy-conserving sets: a probability never
  // exceeds 1; the weight divides by the probability actually used.
  return s > 1.0f ? a / s : a;
}

// The separate roulette of uniform mode: continue with q = min(1, S).
SHARED_FN float combinedUniformContinuation(vec4 a) { return min(1.0f, a.x + a.y + a.z + a.w); }

// The choice probabilities given that the walk continues (P / sum P), used for the MIS density
// sum_k c_k pdf_k of a direction (non-delta k): like single-model materials, MIS leaves the
// roulette out of the BSDF density.
SHARED_FN vec4 combinedMisProbabilities(vec4 P) {
  float s = P.x + P.y + P.z + P.w;
  return s > 0.0f ? P / s : vec4(0.0f);
}

// Picks component k with probability P_k (combinedChoiceProbabilities(mode, count, a)) from one
// uniform number u and returns P_k in pk; false (the walk ends) with probability 1 - sum P_k.
// Compares u * max(1, S) (u * S in proportional mode) with the running sum of a, so no rounding of
// a / S can open a gap: when S > 1, or in proportional mode, the walk never ends here (the last
// positive component takes the sliver u * S == S).
SHARED_FN bool combinedPick(uint mode, uint count, vec4 a, float u, OUT(uint) k, OUT(float) pk) {
  k = 0u;
  pk = 0.0f;
  if (count == 0u) return false;
  if (mode == COMPONENTS_UNIFORM) {
    k = min(count - 1u, uint(u * float(count)));
    pk = 1.0f / float(count);
    return true;
  }
  float s = a.x + a.y + a.z + a.w;
  const bool proportional = mode == COMPONENTS_PROPORTIONAL;
  if (proportional && !(s > 0.0f)) return false;
  float scale = proportional ? s : max(1.0f, s);
  float target = u * scale;
  float acc = 0.0f;
  for (uint i = 0u; i < MAX_COMPONENTS; ++i) {
    float ai = componentAt(a, i);
    acc += ai;
    if (ai > 0.0f && target < acc) {
      k = i;
      pk = ai / scale;
      return true;
    }
  }
  if (s > 1.0f || proportional) {  // the rounding sliver: the last positive component
    for (uint i = 0u; i < MAX_COMPONENTS; ++i)
      if (componentAt(a, i) > 0.0f) k = i;
    pk = componentAt(a, k) / scale;
    return true;
  }
  return false;
}

SHARED_END
#endif
