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
