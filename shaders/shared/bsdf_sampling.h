// bsdf_sampling.h: how the integrator draws a new direction at a surface, for any model.
//
// Measures: directions in the local frame (normal +z on the side the path arrived from), wo
// towards the viewer (wo.z > 0), wi towards the light; pdf is per unit solid angle, 0 for a
// delta (specular) sample; weight = f(wi, wo) cos(theta_i) / pdf (rgb), or the delta lobe's
// reflectance/transmittance for delta samples; continuation = probability of continuing the
// random walk after this sample (Russian roulette), see below.
// Failure: returns false (no direction, zero pdf) and the path ends.
//
// Non-delta models: cosine sampling of the projected disc, exact for lambert and unbiased for
// all (its pdf is positive wherever f can be); the quadtree sampler of the generic-sampling paper
// replaces it per model without touching the stages. Delta models (mirror, dielectric) are
// sampled analytically.
#ifndef NUSSELT_BSDF_SAMPLING_H
#define NUSSELT_BSDF_SAMPLING_H
#include "brdf/dispatch.h"
#include "warp.h"
SHARED_BEGIN

SHARED_FN float bsdfPdf(uint model, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || modelIsDelta(model)) return 0.0f;
  return cosineHemispherePdf(wi);
}

// inside: the path arrived from the inside (the back side of the surface's front face), which
// matters for refraction only: the dielectric's relative index is then 1/eta.
SHARED_FN bool bsdfSample(uint model, BrdfParams p, vec3 wo, bool inside, vec2 u, OUT(vec3) wi, OUT(vec3) weight,
                          OUT(float) pdf, OUT(float) continuation) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  weight = vec3(0.0f);
  pdf = 0.0f;
  continuation = 0.0f;
  if (wo.z <= 0.0f) return false;
  if (model == MODEL_MIRROR) {
    wi = brdfReflectZ(wo);
    weight = mirrorReflectance(p, wo.z);
    continuation = min(1.0f, luminance(weight));
    return true;
  }
  if (model == MODEL_DIELECTRIC) {
    // Reflect with probability R (Fresnel), refract otherwise: weight 1 for either, times the
    // radiance scaling (n_wo / n_wi)^2 across the interface for refraction (catalogue 2.19).
    float eta = brdfParam(p, DIELECTRIC_ETA);
    float etaRel = inside ? 1.0f / eta : eta;  // n(wi side) / n(wo side) for transmission
    float R = fresnelDielectric(wo.z, etaRel);
    if (u.x < R) {
      wi = brdfReflectZ(wo);
      weight = vec3(1.0f);
    } else {
      vec3 t;
      if (!dielectricRefract(etaRel, wo, t)) {  // cannot happen when R < 1, kept for safety
        wi = brdfReflectZ(wo);
        weight = vec3(1.0f);
      } else {
        wi = t;
        weight = vec3(1.0f / (etaRel * etaRel));
      }
    }
    // The walk does not end at a lossless interface: the radiance scaling is not an albedo.
    continuation = 1.0f;
    return true;
  }
  wi = squareToCosineHemisphere(u);
  pdf = cosineHemispherePdf(wi);
  if (pdf <= 0.0f) return false;
  weight = brdfEval(model, p, wi, wo) * (wi.z / pdf);
  // With sampling proportional to f cos, the weight is the directional albedo: continuing with
  // probability equal to it is the random-walk source's albedo roulette.
  continuation = min(1.0f, luminance(weight));
  return true;
}

SHARED_END
#endif
