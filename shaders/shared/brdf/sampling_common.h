// sampling_common.h: building blocks of the models' own samplers (the `analytic` strategy,
// shaders/shared/analytic_sampling.h): lobes around an axis, half-vector densities, the
// two-component mixture with cosine sampling. A model's header defines <fn>AnalyticSample and
// <fn>AnalyticPdf from these (docs/strategies.md has the derivations).
//
// Contract of a model's sampler (the dispatcher in analytic_sampling.h checks wo.z > 0 first):
//   bool <fn>AnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d): a direction d drawn with
//     two uniform numbers in [0, 1); false for a failed sample (e.g. a half vector with wo.h <= 0).
//     The dispatcher also rejects d.z <= 0 and then evaluates the density at d.
//   float <fn>AnalyticPdf(BrdfParams p, vec3 wo, vec3 wi): the density per solid angle of the
//     successful samples at wi, called only with wo.z > 0 and wi.z > 0.
#ifndef NUSSELT_BRDF_SAMPLING_COMMON_H
#define NUSSELT_BRDF_SAMPLING_COMMON_H
#include "common.h"
#include "../warp.h"
SHARED_BEGIN

// 1 - u^(1/(n+1)) for u in (0, 1]: the 1 - cos of a cos^n lobe sample, as -expm1(log(u) / (n+1))
// (accurate for n = 20000, where cos itself is 1 to float precision).
SHARED_FN float analyticLobeOneMinusCos(float u, float n) {
  float x = portableLog(u) / (n + 1.0f);  // <= 0
  if (x > -0.1f)
    return -x * (1.0f + x * (0.5f + x * (1.0f / 6.0f + x * (1.0f / 24.0f + x * (1.0f / 120.0f)))));
  return 1.0f - exp(x);
}

// The unit direction at 1 - cos = omc and azimuth phi around the unit axis a.
SHARED_FN vec3 analyticAround(vec3 a, float omc, float phi) {
  vec3 t;
  vec3 b;
  makeFrame(a, t, b);
  float s = sqrt(max(omc * (2.0f - omc), 0.0f));
  return normalize(t * (s * cos(phi)) + b * (s * sin(phi)) + a * (1.0f - omc));
}

// Solid-angle density of the cos^n lobe around the unit axis a: (n+1)/(2 pi) max(0, w.a)^n.
SHARED_FN float analyticLobePdf(vec3 a, float n, vec3 w) {
  return (n + 1.0f) * (0.5f * NUSSELT_INV_PI) * brdfPowOneMinus(brdfOneMinusDot(w, a), n);
}

// Half-vector density (per solid angle of h) of the (anisotropic) Beckmann slope distribution,
// written with H = wi + wo unnormalised: returns pdf_h(h) / (4 wo.h) = E |H|^2 / (2 pi ax ay H.z^3),
// E = exp(-((H.x/ax)^2 + (H.y/ay)^2) / H.z^2) (the same exponent as wardEval).
SHARED_FN float analyticBeckmannPdf(float ax, float ay, vec3 wi, vec3 wo) {
  vec3 H = wi + wo;
  if (H.z <= 0.0f) return 0.0f;
  float hx = H.x / ax;
  float hy = H.y / ay;
  float e = exp(-(hx * hx + hy * hy) / (H.z * H.z));
  return e * dot(H, H) / (NUSSELT_TWO_PI * ax * ay * H.z * H.z * H.z);
}

// Reflects wo about the half vector h; false when wo.h <= 0 (that h has no valid reflection: a
// failed sample) or the result is below the surface.
SHARED_FN bool analyticReflectHalf(vec3 wo, vec3 h, OUT(vec3) wi) {
  float c = dot(wo, h);
  wi = normalize(2.0f * c * h - wo);
  return c > 0.0f && wi.z > 0.0f;
}

// A reflection about a half vector of the (anisotropic) Beckmann slope distribution: slope space
// tan theta_h (cos phi_h / ax, sin phi_h / ay) has |.|^2 = -log(1 - ux).
SHARED_FN bool analyticBeckmannSample(float ax, float ay, vec3 wo, float ux, float phi, OUT(vec3) d) {
  float r = sqrt(max(-portableLog(1.0f - ux), 0.0f));
  return analyticReflectHalf(wo, normalize(vec3(r * ax * cos(phi), r * ay * sin(phi), 1.0f)), d);
}

// ---- The two-component mixture: cosine sampling, or the model's lobe ----
// Probability of the cosine component from the two components' weights (1: cosine only).
SHARED_FN float analyticMixtureProbability(float wd, float ws) {
  if (!(wd + ws > 0.0f)) return 1.0f;
  return wd / (wd + ws);
}

// Chooses a component with ux: true for the lobe (probability 1 - pd); ux is rescaled to a fresh
// uniform number in [0, 1) for the chosen component.
SHARED_FN bool analyticPickLobe(float pd, INOUT(float) ux) {
  if (ux >= pd) {
    ux = clamp((ux - pd) / (1.0f - pd), 0.0f, NUSSELT_ONE_MINUS_EPS);
    return true;
  }
  ux = ux / pd;
  return false;
}

// The cosine component's direction.
SHARED_FN bool analyticCosineSample(float ux, float uy, OUT(vec3) d) {
  d = squareToCosineHemisphere(vec2(min(ux, NUSSELT_ONE_MINUS_EPS), uy));
  return true;
}

// The mixture density: pd x cosine + (1 - pd) x the lobe's density spec.
SHARED_FN float analyticMix(float pd, vec3 wi, float spec) {
  return pd * (wi.z * NUSSELT_INV_PI) + (1.0f - pd) * spec;
}

SHARED_END
#endif
