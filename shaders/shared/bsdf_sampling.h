// bsdf_sampling.h: how the integrator draws a new direction at a surface, for any model.
//
// Measures: directions in the local frame (normal +z), wo towards the viewer, wi towards the
// light; pdf is per unit solid angle; weight = f(wi, wo) cos(theta_i) / pdf (rgb).
// Failure: returns false (no direction below the surface, zero pdf) and the path ends.
//
// Every non-delta model is sampled here. Today that is cosine sampling of the projected disc,
// exact for lambert and unbiased for all (its pdf is positive wherever f can be); the quadtree
// sampler of the generic-sampling paper replaces it per model without touching the stages.
#ifndef NUSSELT_BSDF_SAMPLING_H
#define NUSSELT_BSDF_SAMPLING_H
#include "brdf/dispatch.h"
#include "warp.h"
SHARED_BEGIN

SHARED_FN float bsdfPdf(uint model, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f) return 0.0f;
  return cosineHemispherePdf(wi);
}

SHARED_FN bool bsdfSample(uint model, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                          OUT(float) pdf) {
  wi = squareToCosineHemisphere(u);
  pdf = cosineHemispherePdf(wi);
  weight = vec3(0.0f);
  if (wo.z <= 0.0f || pdf <= 0.0f) return false;
  weight = brdfEval(model, p, wi, wo) * (wi.z / pdf);
  return true;
}

SHARED_END
#endif
