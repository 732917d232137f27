// rough_dielectric: a rough interface between two dielectrics, reflecting AND transmitting
// (Walter, Marschner, Li, Torrance 2007, "Microfacet models for refraction through rough
// surfaces"): GGX D, separable Smith G = G1(wi, h) G1(wo, h), exact dielectric Fresnel.
//
// Frame and sides: the local +z is the side the normal points to, the OUTSIDE (index n_out); -z
// is the inside (n_in); eta = n_in / n_out. Either direction may lie on either side. The formula
// only involves index ratios, so n_out = 1, n_in = eta below. wi points towards the light, wo
// towards the viewer (the known direction v). Write n_i, n_o for the index on the side of wi, wo.
//
//   reflection (wi.z wo.z > 0): h = normalize(wi + wo) (flipped to h.z > 0),
//     f = F(|wo.h|, n_other / n_o) D(h) G / (4 |wi.z| |wo.z|)       (TIR: F = 1 from the denser side)
//   transmission (wi.z wo.z < 0): generalized half vector h ~ -(n_i wi + n_o wo) (h.z > 0),
//     f = |wi.h| |wo.h| / (|wi.z| |wo.z|) n_o^2 (1 - F) D(h) G / (n_i wi.h + n_o wo.h)^2
//     (F = F(|wi.h|, n_o / n_i) = F(|wo.h|, n_i / n_o), computed from the side of the lower index)
//     (zero unless wi and wo lie on opposite sides of the microfacet: (wi.h)(wo.h) < 0);
//     (n_i wi.h + n_o wo.h)^2 = |n_i wi + n_o wo|^2 is computed as the latter (no cancellation).
//
// Radiance vs importance, stated on purpose: f is the RADIANCE BSDF (radiance arriving along wi,
// leaving along wo). Its transmission carries the factor (n_o / n_i)^2: radiance entering a denser
// medium is concentrated in a narrower cone (the smooth dielectric's 1 / e^2 weight, dielectric.h).
// It is not symmetric; the generalized reciprocity f(wi, wo) / n_o^2 = f(wo, wi) / n_i^2 holds
// (tested), and reflection is symmetric. Importance transport (from the camera's side, adjoint)
// uses f(wo, wi) instead, i.e. f without the (n_o / n_i)^2 factor. Energy: for fixed wo,
//   integral of f(wi, wo) |wi.z| over the upper and lower hemispheres of wi
//     = R + (n_o / n_i)^2 T,  R + T <= 1,
// with R + T -> 1 (the smooth Fresnel split) as alpha -> 0; at larger alpha the single-scattering
// loss of the G term makes R + T < 1.
//
// Symmetry of the sides: f(wi, wo; eta) = f(flipZ(wi), flipZ(wo); 1 / eta) exactly (only the index
// ratios enter), so a path inside the material is the outside case with 1 / eta (tested).
// Params: alpha (GGX roughness, not perceptual: alpha = roughness^2 in glTF terms), eta, tint (the
// colour of the transmitted light at every crossing, 1 = clear: glTF's baseColor on
// KHR_materials_transmission; the transmission term above times tint, reflection untinted).
#ifndef NUSSELT_BRDF_ROUGH_DIELECTRIC_H
#define NUSSELT_BRDF_ROUGH_DIELECTRIC_H
#include "common.h"
#include "gltf_pbr.h"  // ggxD
SHARED_BEGIN

#define ROUGH_DIELECTRIC_ALPHA 0u
#define ROUGH_DIELECTRIC_ETA 1u
#define ROUGH_DIELECTRIC_TINT 2u

// Smith G1 of GGX for direction w (either side) and microfacet normal m (m.z > 0): zero when w
// sees the back of m ((w.m)(w.z) <= 0). 2 / (1 + sqrt(1 + alpha^2 tan^2)) written with cos and
// sin^2 so that it is exact at the pole and 0 at the horizon.
SHARED_FN float ggxSmithG1(vec3 w, vec3 m, float alpha) {
  if (dot(w, m) * w.z <= 0.0f) return 0.0f;
  float c = abs(w.z);
  return 2.0f * c / (c + sqrt(c * c + alpha * alpha * brdfSin2(w)));
}

// The scalar BSDF (grey): see the header comment. Zero for a direction in the plane of the surface.
SHARED_FN float roughDielectricF(float alpha, float eta, vec3 wi, vec3 wo) {
  if (wi.z == 0.0f || wo.z == 0.0f) return 0.0f;
  float ni = wi.z > 0.0f ? 1.0f : eta;
  float no = wo.z > 0.0f ? 1.0f : eta;
  float cio = abs(wi.z * wo.z);
  // ---- Reflection ----
  if (wi.z * wo.z > 0.0f) {
    vec3 h = normalize(wi + wo);
    if (h.z < 0.0f) h = -h;
    float G = ggxSmithG1(wi, h, alpha) * ggxSmithG1(wo, h, alpha);
    if (G <= 0.0f) return 0.0f;
    float F = fresnelDielectric(brdfHalfCos(wi, wo), wo.z > 0.0f ? eta : 1.0f / eta);
    return F * ggxD(h, alpha) * G / (4.0f * cio);
  }
  // ---- Transmission ----
  vec3 s = ni * wi + no * wo;
  float s2 = dot(s, s);  // = (n_i wi.h + n_o wo.h)^2
  if (!(s2 > 0.0f)) return 0.0f;
  vec3 h = s * (-1.0f / sqrt(s2));
  if (h.z < 0.0f) h = -h;
  float ih = dot(wi, h);
  float oh = dot(wo, h);
  if (ih * oh >= 0.0f) return 0.0f;
  float G = ggxSmithG1(wi, h, alpha) * ggxSmithG1(wo, h, alpha);
  if (G <= 0.0f) return 0.0f;
  // F of the refraction pair, evaluated from the side of the lower index (relative index >= 1):
  // the same value as from the other side, but without the critical angle's square-root
  // singularity there, which turns the float error of the cosine into percents of 1 - F near
  // grazing (and would break the reciprocity of f by as much).
  float F = ni <= no ? fresnelDielectric(abs(ih), no / ni) : fresnelDielectric(abs(oh), ni / no);
  return abs(ih * oh) / cio * no * no * (1.0f - F) * ggxD(h, alpha) * G / s2;
}

SHARED_FN vec3 roughDielectricEval(BrdfParams p, vec3 wi, vec3 wo) {
  float alpha = brdfParam(p, ROUGH_DIELECTRIC_ALPHA);
  float eta = brdfParam(p, ROUGH_DIELECTRIC_ETA);
  vec3 f = vec3(roughDielectricF(alpha, eta, wi, wo));
  return wi.z * wo.z < 0.0f ? f * brdfParam3(p, ROUGH_DIELECTRIC_TINT) : f;
}

// The parameters seen from the inside, in the frame turned over so that the inside is +z (the
// path tracer's local frame on the side the path arrived from): eta -> 1 / eta, by the symmetry of
// the sides above. The renderer builds the sampler's tables for these too (material_table.cpp).
SHARED_FN BrdfParams roughDielectricInside(BrdfParams p) {
  BrdfParams q = p;
  q.v[ROUGH_DIELECTRIC_ETA / 4u][ROUGH_DIELECTRIC_ETA % 4u] = 1.0f / brdfParam(p, ROUGH_DIELECTRIC_ETA);
  return q;
}

// (n_wi / n_wo)^2 of a sample across the surface, p as seen from wo's side (roughDielectricInside
// from the inside): eta^2. The throughput roulette's etaScale (bsdf_sampling.h), which undoes the
// (n_o / n_i)^2 that f carries; not a factor of the path's weight.
SHARED_FN float roughDielectricTransmissionEtaScale(BrdfParams p) {
  float eta = brdfParam(p, ROUGH_DIELECTRIC_ETA);
  return eta * eta;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// ROUGH_DIELECTRIC_DELTA: 0 (evaluated and light-sampled).
// ROUGH_DIELECTRIC_ANALYTIC: 0: the analytic strategy samples the cosine.
// ROUGH_DIELECTRIC_TRANSMITS: 1: f is not zero below the surface (wi.z < 0 for wo.z > 0). The
//   quadtree sampler covers both discs (QT_SET_TRANSMITS); the path tracer samples and takes light
//   samples on both sides (modelTransmits in dispatch.h; shade_body.glsl). The other strategies
//   sample the upper hemisphere only: renders refuse them for this model (material_table.cpp).
#define ROUGH_DIELECTRIC_DELTA 0
#define ROUGH_DIELECTRIC_ANALYTIC 0
#define ROUGH_DIELECTRIC_TRANSMITS 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void roughDielectricSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "rough_dielectric";
  m.summary = "rough dielectric interface, reflection + refraction (Walter et al. 2007: GGX, Smith G, Fresnel)";
  m.transmits = ROUGH_DIELECTRIC_TRANSMITS != 0;
  m.params.push_back(scalar("alpha", ROUGH_DIELECTRIC_ALPHA, 0.2f, 0.001f, 1.0f, false,
                            "GGX roughness (alpha, not perceptual roughness)"));
  m.params.push_back(scalar("eta", ROUGH_DIELECTRIC_ETA, 1.5f, 1.01f, 4.0f, false,
                            "n_inside / n_outside (inside = -z side)"));
  m.params.push_back(colour("tint", ROUGH_DIELECTRIC_TINT, 1.0f, 0.0f, 1.0f, "colour of the transmitted light, per crossing"));
  m.typical = {N("alpha", 0.2), N("eta", 1.5)};
  m.hard = {N("alpha", 0.02), N("eta", 2.42)};
  // The tree builder's lower disc: the refraction direction of v (v above the surface, the
  // sampler's known direction), t.xy = -v.xy / eta, where the transmission lobe peaks.
  m.features = [](const BrdfParams& p, const shared::vec3& v, ModelFeatures& out) {
    double eta = shared::brdfParam(p, ROUGH_DIELECTRIC_ETA);
    out.lowerPeaks.push_back({-v.x / eta, -v.y / eta});
  };
}
}  // namespace nusselt::models
#endif

#endif
