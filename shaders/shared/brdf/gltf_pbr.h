// gltf_pbr: the glTF 2.0 metallic-roughness BRDF (glTF 2.0 specification, appendix B):
//   alpha = roughness^2, D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)          (GGX / T-R)
//   V = 1 / ((|n.l| + sqrt(alpha^2 + (1 - alpha^2)(n.l)^2)) (|n.v| + sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))
//       (height-correlated Smith, V_GGX, with the 1 / (4 ci co) folded in)
//   f0 = mix(0.04, baseColor, metallic), F = f0 + (1 - f0)(1 - |v.h|)^5
//   f = (1 - F) mix(baseColor, 0, metallic) / pi + F D V
// Params: baseColor (colour in [0, 1]), metallic [0, 1], roughness [0, 1] (perceptual).
// Numerical guard (not in the spec): alpha is clamped to >= 1e-3 (roughness ~ 0.032): a GGX lobe
// narrower than that is a near-delta that float directions cannot resolve.
#ifndef NUSSELT_BRDF_GLTF_PBR_H
#define NUSSELT_BRDF_GLTF_PBR_H
#include "common.h"
SHARED_BEGIN

#define GLTF_PBR_BASE_COLOR 0u
#define GLTF_PBR_METALLIC 3u
#define GLTF_PBR_ROUGHNESS 4u

// GGX D from the half vector (1 - (n.h)^2 from the xy part: exact at h = n).
SHARED_FN float ggxD(vec3 h, float alpha) {
  float a2 = alpha * alpha;
  float c2 = h.z * h.z;
  float d = c2 * a2 + brdfSin2(h);  // (n.h)^2 (a2 - 1) + 1 for unit h
  return a2 / (NUSSELT_PI * d * d);
}

// Height-correlated Smith visibility V = G2 / (4 ci co) of glTF appendix B.
SHARED_FN float ggxVisibility(float ci, float co, float alpha) {
  float a2 = alpha * alpha;
  float gi = ci + sqrt(a2 + (1.0f - a2) * ci * ci);
  float go = co + sqrt(a2 + (1.0f - a2) * co * co);
  return 1.0f / (gi * go);
}

SHARED_FN vec3 gltfPbrEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 base = brdfParam3(p, GLTF_PBR_BASE_COLOR);
  float metallic = brdfParam(p, GLTF_PBR_METALLIC);
  float rough = brdfParam(p, GLTF_PBR_ROUGHNESS);
  float alpha = max(rough * rough, 1e-3f);
  vec3 h = brdfHalf(wi, wo);
  float vh = brdfHalfCos(wi, wo);
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  vec3 F = fresnelSchlick3(vh, f0);
  vec3 cdiff = mix(base, vec3(0.0f), metallic);
  float spec = ggxD(h, alpha) * ggxVisibility(wi.z, wo.z, alpha);
  return (vec3(1.0f) - F) * cdiff * NUSSELT_INV_PI + F * spec;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// GLTF_PBR_DELTA: 0 (evaluated and light-sampled).
// GLTF_PBR_ANALYTIC: 0: the analytic strategy samples the cosine.
#define GLTF_PBR_DELTA 0
#define GLTF_PBR_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void gltfPbrSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "gltf_pbr";
  m.summary = "glTF 2.0 metallic-roughness (GGX, height-correlated Smith, Schlick)";
  m.params.push_back(colour("baseColor", GLTF_PBR_BASE_COLOR, 0.8f, 0.0f, 1.0f, "base colour"));
  m.params.push_back(scalar("metallic", GLTF_PBR_METALLIC, 0.0f, 0.0f, 1.0f, false, "metalness"));
  m.params.push_back(scalar("roughness", GLTF_PBR_ROUGHNESS, 0.5f, 0.0f, 1.0f, false,
                            "perceptual roughness (alpha = roughness^2, clamped to >= 1e-3)"));
  m.typical = {N("baseColor", 0.8), N("metallic", 0), N("roughness", 0.5)};
  m.hard = {N("baseColor", 1), N("metallic", 1), N("roughness", 0.05)};
  m.variants = {{"dielectric_rough", {N("baseColor", 1), N("metallic", 0), N("roughness", 1)}}};
}
}  // namespace nusselt::models
#endif

#endif
