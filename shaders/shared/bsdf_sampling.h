// bsdf_sampling.h: how the integrator draws a new direction at a surface, for any model.
//
// Measures: directions in the local frame (normal +z on the side the path arrived from), wo
// towards the viewer (wo.z > 0), wi towards the light; pdf is per unit solid angle, 0 for a
// delta (specular) sample; weight = f(wi, wo) cos(theta_i) / pdf (rgb), or the delta lobe's
// reflectance/transmittance for delta samples; continuation = probability of continuing the
// random walk after this sample (Russian roulette).
// Failure: returns false (no direction, zero pdf) and the path ends.
//
// Strategies for non-delta models (SAMPLER_*, a specialization constant of the shade stage):
//   quadtree  the generic sampler of Montes et al. (quadtree.h): density proportional to
//             f cos, for any model; continuation = the tabulated directional albedo
//   cosine    cosine-weighted hemisphere (the random-walk source's diffuse sampling)
//   uniform   uniform hemisphere
//   analytic  the model's own importance sampling where one exists, cosine elsewhere
//             (analytic_sampling.h); continuation = min(1, luminance of the weight)
//   tabulated piecewise-constant tables per incident angle with inverse-CDF sampling
//             (tabulated.h); continuation = the table's directional albedo
// All return the true density of their samples, so all are unbiased. Delta models (mirror,
// dielectric) are always sampled analytically.
//
// The set argument `quadSet` is the table set of the active strategy: the QuadSet for quadtree,
// the TabSet for tabulated (the renderer stores the one of the strategy it renders with in
// GpuMaterial.info.z); INVALID_INDEX (no tables) falls back to cosine.
//
// The tabulated strategy's buffers are Globals.tabSets/tabTables/tabData (layout.h, which defines
// NUSSELT_TABULATED_BUFFERS); the renderer builds them (src/render/renderer.cpp) and stores each
// material's TabSet where the QuadSet would go (GpuMaterial.info.z, GpuComponent.info.y). A GLSL
// file that includes this header without layout.h compiles tabulated as cosine.
#ifndef NUSSELT_BSDF_SAMPLING_H
#define NUSSELT_BSDF_SAMPLING_H
#include "brdf/dispatch.h"
#include "analytic_sampling.h"
#include "quadtree.h"
#include "warp.h"
#if defined(__cplusplus) || defined(NUSSELT_TABULATED_BUFFERS)
#include "tabulated.h"
#define NUSSELT_HAS_TABULATED 1
#endif
SHARED_BEGIN

#define SAMPLER_QUADTREE 0u
#define SAMPLER_COSINE 1u
#define SAMPLER_UNIFORM 2u
#define SAMPLER_ANALYTIC 3u
#define SAMPLER_TABULATED 4u

// The shade stage is compiled once per strategy (NUSSELT_SHADE_SAMPLER = its id, CMakeLists.txt):
// only that strategy's code and the cosine fallback are in the module. C++ and the other stages
// have all of them.
#ifdef NUSSELT_SHADE_SAMPLER
#define NUSSELT_WITH_QUADTREE (NUSSELT_SHADE_SAMPLER == 0)
#define NUSSELT_WITH_UNIFORM (NUSSELT_SHADE_SAMPLER == 2)
#define NUSSELT_WITH_ANALYTIC (NUSSELT_SHADE_SAMPLER == 3)
#define NUSSELT_WITH_TABULATED (NUSSELT_SHADE_SAMPLER == 4)
#else
#define NUSSELT_WITH_QUADTREE 1
#define NUSSELT_WITH_UNIFORM 1
#define NUSSELT_WITH_ANALYTIC 1
#define NUSSELT_WITH_TABULATED 1
#endif

// The quadtree and tabulated samplers need the material's table set; without one they fall back
// to cosine (so does tabulated in GLSL without its buffers: see above).
SHARED_FN uint effectiveSampler(uint strategy, uint quadSet) {
#ifndef NUSSELT_HAS_TABULATED
  if (strategy == SAMPLER_TABULATED) return SAMPLER_COSINE;
#endif
  return ((strategy == SAMPLER_QUADTREE || strategy == SAMPLER_TABULATED) && quadSet == INVALID_INDEX) ? SAMPLER_COSINE
                                                                                                      : strategy;
}

// wi below the surface: 0, except for a transmitting model (modelTransmits) under the quadtree,
// whose transmitting sets sample both discs (the other strategies sample the upper one only).
SHARED_FN float bsdfPdf(uint strategy, uint model, uint quadSet, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || (wi.z <= 0.0f && !(modelTransmits(model) && wi.z < 0.0f)) || modelIsDelta(model)) return 0.0f;
  uint s = effectiveSampler(strategy, quadSet);
  if (modelTransmits(model) && wi.z < 0.0f && s != SAMPLER_QUADTREE) return 0.0f;
#if NUSSELT_WITH_QUADTREE
  if (s == SAMPLER_QUADTREE) return quadPdf(quadSet, model, p, wo, wi);
#endif
#if NUSSELT_WITH_UNIFORM
  if (s == SAMPLER_UNIFORM) return 0.5f * NUSSELT_INV_PI;
#endif
#if NUSSELT_WITH_ANALYTIC
  if (s == SAMPLER_ANALYTIC) return analyticPdf(model, p, wo, wi);
#endif
#if defined(NUSSELT_HAS_TABULATED) && NUSSELT_WITH_TABULATED
  if (s == SAMPLER_TABULATED) return tabPdf(quadSet, wo, wi);
#endif
  return cosineHemispherePdf(wi);
}

// Draws wi for the known direction wo (wo.z > 0; a model that is not delta) with strategy s (a
// SAMPLER_* id, after effectiveSampler) and two uniform numbers u in [0, 1), and returns the
// density pdf and f = f(wi, wo) (the quadtree returns the value its rejection test evaluated).
// A function of u alone (the quadtree's further numbers come from the stream of u: rng.h,
// rngStreamKey). False for a failed sample. The one strategy switch: the shade stage (through bsdfSample), the
// sample tool (shaders/tools/sample_tool.comp) and `nusselt sample --cpu` all draw through it.
SHARED_FN bool strategySample(uint s, uint model, uint set, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(float) pdf,
                              OUT(vec3) f) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  f = vec3(0.0f);
#if NUSSELT_WITH_QUADTREE
  if (s == SAMPLER_QUADTREE) return quadSample(set, model, p, wo, u, wi, pdf, f) && pdf > 0.0f;
#endif
  if (false) {
#if NUSSELT_WITH_ANALYTIC
  } else if (s == SAMPLER_ANALYTIC) {
    if (!analyticSample(model, p, wo, u, wi, pdf)) return false;
#endif
#if defined(NUSSELT_HAS_TABULATED) && NUSSELT_WITH_TABULATED
  } else if (s == SAMPLER_TABULATED) {
    if (!tabSample(set, wo, u, wi, pdf)) return false;
#endif
#if NUSSELT_WITH_UNIFORM
  } else if (s == SAMPLER_UNIFORM) {
    float z = u.x;
    float r = cosFromSin(z);
    float phi = NUSSELT_TWO_PI * u.y;
    wi = vec3(r * cos(phi), r * sin(phi), z);
    pdf = 0.5f * NUSSELT_INV_PI;
#endif
  } else {
    wi = squareToCosineHemisphere(u);
    pdf = cosineHemispherePdf(wi);
  }
  if (!(pdf > 0.0f) || wi.z <= 0.0f) return false;
  f = brdfEval(model, p, wi, wo);
  return true;
}

// inside: the path arrived from the inside (the back side of the surface's front face), which
// matters for refraction only: the dielectric's relative index is then 1/eta.
// The sample is a function of u alone (Metropolis, issue 19).
SHARED_FN bool bsdfSample(uint strategy, uint model, uint quadSet, BrdfParams p, vec3 wo, bool inside, vec2 u,
                          OUT(vec3) wi, OUT(vec3) weight, OUT(float) pdf, OUT(float) continuation) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  weight = vec3(0.0f);
  pdf = 0.0f;
  continuation = 0.0f;
  if (wo.z <= 0.0f) return false;
  if (modelIsDelta(model)) return deltaSample(model, p, wo, inside, u, wi, weight, continuation);
  uint s = effectiveSampler(strategy, quadSet);
  vec3 f;
  if (!strategySample(s, model, quadSet, p, wo, u, wi, pdf, f)) return false;
  // A transmitting model's quadtree sample may lie below the surface (QT_SET_TRANSMITS): weight
  // f |cos| / pdf, f the radiance BSDF with its (n_o / n_i)^2 (nothing else scales it). Other
  // models' samples lie above the surface.
  if (wi.z < 0.0f && !modelTransmits(model)) return false;
  weight = f * ((modelTransmits(model) ? abs(wi.z) : wi.z) / pdf);
#if NUSSELT_WITH_QUADTREE
  // The random-walk source's roulette: continue with the tabulated directional albedo. With
  // sampling proportional to f cos the weight's luminance is that albedo, so surviving paths of
  // a grey BRDF carry weight 1.
  if (s == SAMPLER_QUADTREE) {
    continuation = min(1.0f, quadAlbedo(quadSet, wo.z, portableAtan2(wo.y, wo.x)));
    return true;
  }
#endif
  float cont = -1.0f;  // < 0: min(1, luminance(weight))
#if defined(NUSSELT_HAS_TABULATED) && NUSSELT_WITH_TABULATED
  if (s == SAMPLER_TABULATED) {
    float a = tabAlbedo(quadSet, wo);
    if (a > 0.0f) cont = min(1.0f, a);
  }
#endif
  // Without a tabulated albedo, the sample weight's luminance (its estimate) is the continuation.
  continuation = cont >= 0.0f ? cont : min(1.0f, luminance(weight));
  return true;
}

// ---- Binned sampling: gltf_pbr whose textures vary its parameters (issue 18) ----------------------
// No one tree fits a material whose baseColor, metallic and roughness change per texel, and a tree
// per texel is out of reach. The material is sampled instead from a mixture built at the hit:
//   pdf(wi) = c_d cos / pi + (1 - c_d) [(1 - t) q_j(wi) + t q_{j+1}(wi)]
// q_j = the quadtree density (quadPdf) of the pure specular lobe at roughness r_j (gltf_pbr with
// baseColor 1, metallic 1: F = 1, no diffuse part), one set per bin shared by every such material
// of the scene (RoughnessBins, quadtree_layout.h); r_j <= r <= r_{j+1} the texel's roughness,
// t = (r - r_j) / (r_{j+1} - r_j) (binLocate). c_d (binnedDiffuseChoice) weighs the texel's diffuse
// albedo against its specular one at wo (from the bins' tabulated albedo and Fresnel moments); it is a function of wo and the texel only and at least
// BIN_COSINE_FLOOR, so the cosine part covers the whole hemisphere whatever the trees do.
// The sample is weighted with the texel's own f: weight = f cos / pdf, pdf the EXACT mixture density
// above (binnedPdf), which MIS uses too: unbiased for any bins and any c_d. The component and the
// bin are chosen by remapping u.x (u.x < c_d: cosine with u.x / c_d, and so on), so the sample
// stays a function of u alone (the trees' further numbers come from the stream of the remapped u).
// Bins: r_j = (j / (K - 1))^spacing; spacing 1 is uniform in roughness, 2 puts more bins at low
// roughness where the lobe changes fastest (docs/scenes.md, "Sampling textured materials").
#define BIN_COSINE_FLOOR 0.05f

// The roughness of bin j of K bins.
SHARED_FN float binRoughness(RoughnessBins B, uint j) {
  if (j == 0u) return 0.0f;
  if (j + 1u >= B.count) return 1.0f;
  return pow(float(j) / float(B.count - 1u), B.spacing);
}

// The bins j, j + 1 around roughness r (clamped to [0, 1]) and the weight t of bin j + 1.
SHARED_FN void binLocate(RoughnessBins B, float r, OUT(uint) j, OUT(float) t) {
  float rc = clamp(r, 0.0f, 1.0f);
  float x = pow(rc, 1.0f / B.spacing) * float(B.count - 1u);
  j = min(uint(x), B.count - 2u);
  // The power's rounding may put r just outside [r_j, r_{j+1}]: step to the right pair.
  if (j > 0u && rc < binRoughness(B, j)) j -= 1u;
  if (j + 2u < B.count && rc > binRoughness(B, j + 1u)) j += 1u;
  float r0 = binRoughness(B, j);
  float r1 = binRoughness(B, j + 1u);
  t = clamp((rc - r0) / (r1 - r0), 0.0f, 1.0f);
}

// The parameters the bins' trees were built for (and are evaluated with): the pure specular lobe.
SHARED_FN BrdfParams binParams(float r) {
  BrdfParams q;
  for (uint i = 0u; i < uint(BRDF_PARAM_VEC4S); ++i) q.v[i] = vec4(0.0f);
  q.v[0] = vec4(1.0f, 1.0f, 1.0f, 1.0f);  // baseColor (1, 1, 1), metallic 1
  q.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = r;
  return q;
}

// The Fresnel moments of bin `set` at the known direction (cosTheta, phi), interpolated between
// tables like quadAlbedo: x = A5, the albedo of the bin's lobe weighted by (1 - v.h)^5 (with F = 1
// the table's mass is A1; Schlick's F = f0 + (1 - f0)(1 - v.h)^5 is linear in f0, so the lobe's
// albedo with F is f0 A1 + (1 - f0) A5); y = B5 = (1 / pi) * integral of (1 - v.h)^5 cos theta_i
// over the hemisphere (the diffuse part (1 - F) cdiff / pi has albedo (1 - f0)(1 - B5) cdiff).
// Stored as two unorm16 in QuadTable.info.w of the bins' tables (setRoughnessBinMoments,
// src/quadtree/roughness_bins.cpp); 0 where not set (then c_d is the normal-incidence estimate).
SHARED_FN vec2 binFresnelMoments(uint set, float cosTheta, float phi) {
  QuadSet S = QT_SET(set);
  float c = clamp(cosTheta, 0.0f, 1.0f);
  vec3 v = vec3(cosFromSin(c) * cos(phi), cosFromSin(c) * sin(phi), c);
  vec4 fr = quadFrame((S.info.w & QT_SET_ANISOTROPIC) != 0u, v);
  uvec4 idx;
  vec2 ts;
  quadGrid(S, quadToCanonical(fr, v), idx, ts);
  uint np = S.info.z;
  uint m0 = QT_TABLE(S.info.x + idx.x * np + idx.z).info.w;
  uint m1 = QT_TABLE(S.info.x + idx.y * np + idx.z).info.w;
  vec2 a = vec2(float(m0 & 0xffffu), float(m0 >> 16u)) * (1.0f / 65535.0f);
  vec2 b = vec2(float(m1 & 0xffffu), float(m1 >> 16u)) * (1.0f / 65535.0f);
  return mix(a, b, ts.x);
}

// The probability c_d of the cosine part for the texel p and wo: the texel's diffuse albedo at wo,
// lum((1 - f0) cdiff) (1 - B5), against its specular one, lum(f0) A1 + (1 - lum(f0)) A5, with the
// bins' tabulated albedo A1 (quadAlbedo) and Fresnel moments (binFresnelMoments) at wo mixed like
// the trees (exact at the texel's roughness on a bin and a table direction), floored at
// BIN_COSINE_FLOOR. (Schlick's F at cos theta_o instead, as before, tends to 1 at grazing incidence
// and gave the lobe most samples there, whatever the diffuse part's share.)
SHARED_FN float binnedDiffuseChoice(RoughnessBins B, BrdfParams p, vec3 wo, uint j, float t) {
  vec3 base = brdfParam3(p, GLTF_PBR_BASE_COLOR);
  float metallic = clamp(brdfParam(p, GLTF_PBR_METALLIC), 0.0f, 1.0f);
  vec3 f0 = mix(vec3(0.04f), base, metallic);
  float phi = portableAtan2(wo.y, wo.x);
  float a = 0.0f;
  vec2 m = vec2(0.0f);
  if (t < 1.0f) {
    a += (1.0f - t) * quadAlbedo(B.first + j, wo.z, phi);
    m += (1.0f - t) * binFresnelMoments(B.first + j, wo.z, phi);
  }
  if (t > 0.0f) {
    a += t * quadAlbedo(B.first + j + 1u, wo.z, phi);
    m += t * binFresnelMoments(B.first + j + 1u, wo.z, phi);
  }
  float lf0 = luminance(f0);
  float d = luminance((vec3(1.0f) - f0) * base) * (1.0f - metallic) * (1.0f - m.y);
  float s = lf0 * a + (1.0f - lf0) * m.x;
  float cd = d + s > 0.0f ? d / (d + s) : 1.0f;
  return clamp(cd, BIN_COSINE_FLOOR, 1.0f);
}

// The mixture's density at wi (solid angle), given its choice c_d and bins (j, t).
SHARED_FN float binnedMixturePdf(RoughnessBins B, float cd, uint j, float t, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  float pdf = cd * cosineHemispherePdf(wi);
  if (t < 1.0f) pdf += (1.0f - cd) * (1.0f - t) * quadPdf(B.first + j, MODEL_GLTF_PBR, binParams(binRoughness(B, j)), wo, wi);
  if (t > 0.0f)
    pdf += (1.0f - cd) * t * quadPdf(B.first + j + 1u, MODEL_GLTF_PBR, binParams(binRoughness(B, j + 1u)), wo, wi);
  return pdf;
}

// The density with which binnedSample draws wi for the texel parameters p (gltf_pbr): for MIS.
SHARED_FN float binnedPdf(RoughnessBins B, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  uint j;
  float t;
  binLocate(B, brdfParam(p, GLTF_PBR_ROUGHNESS), j, t);
  return binnedMixturePdf(B, binnedDiffuseChoice(B, p, wo, j, t), j, t, wo, wi);
}

// Draws wi for the texel parameters p (gltf_pbr) and wo.z > 0 with density pdf = binnedPdf, and
// returns f = gltfPbrEval(p, wi, wo). False for a failed sample (a tree's rejection cap, below the
// surface).
SHARED_FN bool binnedSample(RoughnessBins B, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(float) pdf, OUT(vec3) f) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  f = vec3(0.0f);
  if (wo.z <= 0.0f) return false;
  uint j;
  float t;
  binLocate(B, brdfParam(p, GLTF_PBR_ROUGHNESS), j, t);
  float cd = binnedDiffuseChoice(B, p, wo, j, t);
  const float below1 = 0.99999994f;  // the largest float below 1
  if (u.x < cd) {
    wi = squareToCosineHemisphere(vec2(min(u.x / cd, below1), u.y));
  } else {
    float x = min((u.x - cd) / (1.0f - cd), below1);
    uint k = j;
    if (t >= 1.0f || (t > 0.0f && x >= 1.0f - t)) {
      k = j + 1u;
      x = t >= 1.0f ? x : (x - (1.0f - t)) / t;
    } else if (t > 0.0f) {
      x = x / (1.0f - t);
    }
    float qpdf;
    vec3 qf;
    if (!quadSample(B.first + k, MODEL_GLTF_PBR, binParams(binRoughness(B, k)), wo, vec2(min(x, below1), u.y), wi,
                    qpdf, qf))
      return false;
  }
  if (wi.z <= 0.0f) return false;
  pdf = binnedMixturePdf(B, cd, j, t, wo, wi);
  if (!(pdf > 0.0f)) return false;
  f = gltfPbrEval(p, wi, wo);
  return true;
}

// bsdfSample for a binned material: weight f cos / pdf, continuation min(1, luminance(weight)).
SHARED_FN bool binnedBsdfSample(RoughnessBins B, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                                OUT(float) pdf, OUT(float) continuation) {
  weight = vec3(0.0f);
  continuation = 0.0f;
  vec3 f;
  if (!binnedSample(B, p, wo, u, wi, pdf, f)) return false;
  weight = f * (wi.z / pdf);
  continuation = min(1.0f, luminance(weight));
  return true;
}

// The throughput roulette (ROULETTE_THROUGHPUT): from bounce ROULETTE_MIN_BOUNCE on, the walk goes on
// with probability q = min(1, max_c beta_c x etaScale) and the survivors are divided by q (unbiased:
// E[beta'] = q beta / q). beta already includes this bounce's sample weight. No channel grows: a
// survivor's largest channel becomes 1 / etaScale at most when q < 1. False: the walk ends.
SHARED_FN bool throughputRoulette(uint bounce, INOUT(vec3) beta, float etaScale, float u) {
  if (bounce < ROULETTE_MIN_BOUNCE) return true;
  float q = min(1.0f, maxComponent(beta) * etaScale);
  if (!(q > 0.0f) || u >= q) return false;
  beta = beta / q;
  return true;
}

SHARED_END
#endif
