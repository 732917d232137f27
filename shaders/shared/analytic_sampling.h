// analytic_sampling.h: the `analytic` BSDF sampling strategy (SAMPLER_ANALYTIC): each model's own
// importance sampling where the literature gives one, cosine-weighted hemisphere sampling
// elsewhere. Shared by the CPU (tests, `nusselt sample --cpu`) and the GPU (shade stage).
// The samplers live in the models' headers (<fn>AnalyticSample / <fn>AnalyticPdf, present when
// <NAME>_ANALYTIC is 1; their building blocks in brdf/sampling_common.h); this file dispatches
// to them through the model list (brdf/models.h).
//
// Convention as everywhere: brdfEval(model, p, wi, wo), wi = the SAMPLED direction (first
// argument), wo = the known direction (viewer); local frame, normal +z; pdf per unit solid angle.
//
// Models with their own sampler (each header's "Analytic sampling" section; derivations in
// docs/strategies.md): lambert (cosine), phong_specular, phong, lewis (cos^n lobes around R(wo)),
// blinn, ward, torrance_sparrow, ashikhmin_shirley (half-vector lobes), lafortune (one lobe per
// lobe), each mixed with cosine sampling by its diffuse weight. All other models: cosine.
//
// The pdf is the TRUE density of the returned samples. A lobe sample may land below the surface
// (or, for half-vector sampling, come from an h with wo.h <= 0): that sample FAILS (returns false;
// the estimator counts it as 0). The successful samples then have density = the mixture density
// restricted to the upper hemisphere, which integrates to less than 1 (the lost mass is the
// probability of failure). analyticPdf returns exactly that restricted density, so
// E[f cos / pdf; success] = integral of f cos over the upper hemisphere: unbiased, as long as the
// density is > 0 wherever f > 0, which holds for every component (the cosine component covers the
// hemisphere; each lobe covers the region where its own term of f is non-zero).
#ifndef NUSSELT_ANALYTIC_SAMPLING_H
#define NUSSELT_ANALYTIC_SAMPLING_H
#include "brdf/dispatch.h"
#include "warp.h"
SHARED_BEGIN

#define NUSSELT_ANALYTIC_HAS_1(NAME, fn) case MODEL_##NAME: return true;
#define NUSSELT_ANALYTIC_HAS_0(NAME, fn)
#define NUSSELT_ANALYTIC_HAS(id, NAME, fn) NUSSELT_CAT(NUSSELT_ANALYTIC_HAS_, NAME##_ANALYTIC)(NAME, fn)
// Does the model have its own sampler here (else analyticSample is cosine sampling)?
SHARED_FN bool analyticHasSampler(uint model) {
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_ANALYTIC_HAS)
    default: break;
  }
  return false;
}

#define NUSSELT_ANALYTIC_PDF_1(NAME, fn) case MODEL_##NAME: return fn##AnalyticPdf(p, wo, wi);
#define NUSSELT_ANALYTIC_PDF_0(NAME, fn)
#define NUSSELT_ANALYTIC_PDF(id, NAME, fn) NUSSELT_CAT(NUSSELT_ANALYTIC_PDF_, NAME##_ANALYTIC)(NAME, fn)
// Density per unit solid angle of analyticSample's successful samples at wi (0 below the surface).
SHARED_FN float analyticPdf(uint model, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_ANALYTIC_PDF)
    default: break;
  }
  return wi.z * NUSSELT_INV_PI;
}

#define NUSSELT_ANALYTIC_SAMPLE_1(NAME, fn) case MODEL_##NAME: ok = fn##AnalyticSample(p, wo, u, d); break;
#define NUSSELT_ANALYTIC_SAMPLE_0(NAME, fn)
#define NUSSELT_ANALYTIC_SAMPLE(id, NAME, fn) NUSSELT_CAT(NUSSELT_ANALYTIC_SAMPLE_, NAME##_ANALYTIC)(NAME, fn)
// Draws wi for the known direction wo (wo.z > 0) with two uniform numbers in [0, 1); returns false
// (wi = (0, 0, 1), pdf = 0) for a failed sample (below the surface: see the header comment).
SHARED_FN bool analyticSample(uint model, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(float) pdf) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  if (wo.z <= 0.0f) return false;
  vec3 d = vec3(0.0f, 0.0f, 1.0f);
  bool ok;
  switch (model) {
    NUSSELT_DISPATCH_MODELS(NUSSELT_ANALYTIC_SAMPLE)
    default: ok = analyticCosineSample(u.x, u.y, d); break;
  }
  if (!ok || !(d.z > 0.0f)) return false;
  wi = d;
  pdf = analyticPdf(model, p, wo, wi);
  return pdf > 0.0f;
}

SHARED_END
#endif
