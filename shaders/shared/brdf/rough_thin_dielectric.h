// rough_thin_dielectric: a thin rough sheet of a dielectric with the same medium on both sides
// (glTF's thin-walled rough transmission: KHR_materials_transmission with roughness and without
// KHR_materials_volume). The rough counterpart of thin_dielectric: a sheet of vanishing thickness
// has no inside and bends no ray, so light that passes through leaves along the straight-through
// direction, blurred by the roughness.
//
// Frame: either side of the sheet is +z (both sides behave the same). wi points towards the light,
// wo towards the viewer. GGX D, separable Smith G = G1(wi', h) G1(wo, h) (rough_dielectric.h), and
// the sheet's reflectance at the microfacet's angle
//   R(c) = 2 F(c) / (1 + F(c)),  F = the exact dielectric Fresnel reflectance at index eta,
// thin_dielectric's sum over the reflections between the two faces (each face reflects F; the
// sheet absorbs nothing), so that the model tends to thin_dielectric as alpha -> 0.
//   reflection (wi.z wo.z > 0): wi' = wi, h = normalize(wi + wo) (flipped to h.z > 0),
//     f = R(|wo.h|) D(h) G1(wi, h) G1(wo, h) / (4 |wi.z| |wo.z|)
//   transmission (wi.z wo.z < 0): the same lobe mirrored through the plane of the surface,
//     wi' = (wi.x, wi.y, -wi.z), h = normalize(wi' + wo) (flipped to h.z > 0),
//     f = tint (1 - R(|wo.h|)) D(h) G1(wi', h) G1(wo, h) / (4 |wi.z| |wo.z|)
//   (the peak of transmission is at wi = -wo: straight through).
// Energy: mirroring wi -> wi' maps the lower hemisphere onto the upper one with |wi.z| and the
// solid angle unchanged, so for tint = 1 the directional albedo (reflection + transmission) is the
// integral of D G / (4 |wo.z|) over the upper hemisphere: the GGX reflection albedo with F = 1,
// which is <= 1 (the single-scattering loss of the Smith term), whatever eta; reflection and
// transmission only divide it in R : 1 - R at each microfacet. tint < 1 absorbs.
// Symmetric (f(wi, wo) = f(wo, wi): swapping mirrors h, which D and G do not see) and
// f(flipZ wi, flipZ wo) = f(wi, wo): the parameters seen from the other side are the same
// (transmissionInsideParams: p), and a transmitted sample's radiance is not rescaled (the same
// medium on both sides: transmissionEtaScale 1).
// Params: alpha (GGX roughness: alpha = roughness^2 in glTF terms), eta (n_sheet / n_outside),
// tint (the colour of the transmitted light: glTF's baseColor on thin-walled transmission).
#ifndef NUSSELT_BRDF_ROUGH_THIN_DIELECTRIC_H
#define NUSSELT_BRDF_ROUGH_THIN_DIELECTRIC_H
#include "common.h"
#include "rough_dielectric.h"  // ggxSmithG1 (and gltf_pbr.h's ggxD)
SHARED_BEGIN

#define ROUGH_THIN_DIELECTRIC_ALPHA 0u
#define ROUGH_THIN_DIELECTRIC_ETA 1u
#define ROUGH_THIN_DIELECTRIC_TINT 2u

// The sheet's reflectance at cosine c to the microfacet normal: 2 F / (1 + F).
SHARED_FN float roughThinSheetReflectance(float eta, float c) {
  float r1 = fresnelDielectric(c, eta);
  return 2.0f * r1 / (1.0f + r1);
}

// The scalar lobes (grey, without tint): reflection for wi.z wo.z > 0, transmission for < 0, zero
// for a direction in the plane of the surface. See the header comment.
SHARED_FN float roughThinDielectricF(float alpha, float eta, vec3 wi, vec3 wo) {
  if (wi.z == 0.0f || wo.z == 0.0f) return 0.0f;
  bool transmitted = wi.z * wo.z < 0.0f;
  vec3 wm = transmitted ? vec3(wi.x, wi.y, -wi.z) : wi;  // wi', on wo's side
  vec3 h = normalize(wm + wo);
  if (h.z < 0.0f) h = -h;
  float G = ggxSmithG1(wm, h, alpha) * ggxSmithG1(wo, h, alpha);
  if (G <= 0.0f) return 0.0f;
  float R = roughThinSheetReflectance(eta, brdfHalfCos(wm, wo));
  return (transmitted ? 1.0f - R : R) * ggxD(h, alpha) * G / (4.0f * abs(wi.z * wo.z));
}

SHARED_FN vec3 roughThinDielectricEval(BrdfParams p, vec3 wi, vec3 wo) {
  vec3 f = vec3(roughThinDielectricF(brdfParam(p, ROUGH_THIN_DIELECTRIC_ALPHA), brdfParam(p, ROUGH_THIN_DIELECTRIC_ETA),
                                     wi, wo));
  return wi.z * wo.z < 0.0f ? f * brdfParam3(p, ROUGH_THIN_DIELECTRIC_TINT) : f;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// ROUGH_THIN_DIELECTRIC_DELTA: 0 (evaluated and light-sampled).
// ROUGH_THIN_DIELECTRIC_ANALYTIC: 0: the analytic strategy samples the cosine.
// ROUGH_THIN_DIELECTRIC_TRANSMITS: 1: f is not zero below the surface; sampled by the quadtree
//   over both discs, as rough_dielectric (its header says how the renderer treats such models).
#define ROUGH_THIN_DIELECTRIC_DELTA 0
#define ROUGH_THIN_DIELECTRIC_ANALYTIC 0
#define ROUGH_THIN_DIELECTRIC_TRANSMITS 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void roughThinDielectricSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "rough_thin_dielectric";
  m.summary = "thin rough dielectric sheet: GGX reflection, the same lobe mirrored through the surface as straight "
              "transmission (glTF thin-walled)";
  m.transmits = ROUGH_THIN_DIELECTRIC_TRANSMITS != 0;
  m.params.push_back(scalar("alpha", ROUGH_THIN_DIELECTRIC_ALPHA, 0.2f, 0.001f, 1.0f, false,
                            "GGX roughness (alpha, not perceptual roughness)"));
  m.params.push_back(scalar("eta", ROUGH_THIN_DIELECTRIC_ETA, 1.5f, 1.01f, 4.0f, false, "n_sheet / n_outside"));
  m.params.push_back(colour("tint", ROUGH_THIN_DIELECTRIC_TINT, 1.0f, 0.0f, 1.0f, "colour of the transmitted light"));
  m.typical = {N("alpha", 0.2), N("eta", 1.5)};
  m.hard = {N("alpha", 0.02), N("eta", 2.42)};
  // The lower disc's peak, the straight-through direction -v, is the builder's mirror point
  // (-v.x, -v.y) already: no features of its own.
}
}  // namespace nusselt::models
#endif

#endif
