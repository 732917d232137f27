// htsg: He, Torrance, Sillion, Greenberg 1991, unpolarised; the directional-diffuse and uniform
// diffuse parts (docs/brdf-models.md 2.15). The specular (delta) part is not in htsgEval: its
// reflectance rho_sp(theta_i) is htsgSpecularReflectance (sample it like a mirror).
//   k0 = 2 pi / lam; K(t) = tan t erfc(tau / (2 sigma0 tan t));
//   (z0/sigma0)^2 = W((K(ti) + K(to))^2 / (8 pi)); sigma = sigma0 / sqrt(1 + (z0/sigma0)^2)
//   g = (k0 sigma (ci + co))^2; vxy^2 = k0^2 (H.x^2 + H.y^2)
//   D = pi^2 tau^2 / (4 lam^2) sum_{m>=1} g^m e^-g / (m! m) exp(-tau^2 vxy^2 / (4 m))
//   G = ((H.H) / (ci + co))^2; S(t) = (1 - erfc(a)/2) / (Lambda + 1), a = tau / (2 sigma0 tan t),
//   Lambda = (exp(-a^2) / (sqrt(pi) a) - erfc(a)) / 2
//   f = Fr(cb; n, k) G S(ti) S(to) D / (pi ci co) + rho_ud / pi
// sigma0 [um] rms height, tau [um] autocorrelation length, lam [um] wavelength (one for all
// channels: the directional-diffuse part is grey), n, k complex index, rho_ud colour.
// The series: at most HTSG_MAX_TERMS terms (lavapipe loop budget). Terms with m in
// [max(1, g - 8 sqrt g), g + 8 sqrt g + 10] matter (Poisson weights, log space); when there are
// more than HTSG_MAX_TERMS integers there, every stride-th is summed with weight stride (the
// trapezoidal rule on a Poisson bell of width sqrt(g) >= 3.4 strides: error far below float).
#ifndef NUSSELT_BRDF_HTSG_H
#define NUSSELT_BRDF_HTSG_H
#include "common.h"
SHARED_BEGIN

#define HTSG_SIGMA0 0u
#define HTSG_TAU 1u
#define HTSG_LAM 2u
#define HTSG_N 3u
#define HTSG_K 4u
#define HTSG_RHO_UD 5u
#define HTSG_MAX_TERMS 64

// ln(m!) for m = 0..7.
CONST_ARRAY(float) HTSG_LN_FACT[8] = {0.0f, 0.0f, 0.69314718f, 1.7917595f, 3.1780538f, 4.7874917f, 6.5792512f,
                                       8.5251614f};

// tan of the polar angle from its cosine c (> 0).
SHARED_FN float htsgTan(float c) { return cosFromSin(c) / c; }

SHARED_FN float htsgK(float c, float tau, float sigma0) {
  float t = htsgTan(c);
  if (t <= 0.0f) return 0.0f;
  return t * brdfErfc(tau / (2.0f * sigma0 * t));
}

// Shadowing-masking S(theta) (Smith, Gaussian surface), 1 at normal incidence, -> 0 at grazing.
SHARED_FN float htsgShadow(float c, float tau, float sigma0) {
  float t = htsgTan(c);
  if (t <= 1e-30f) return 1.0f;
  float a = tau / (2.0f * sigma0 * t);
  float e = brdfErfc(a);
  float lambda = 0.5f * (exp(-a * a) / (1.7724539f * a) - e);
  return (1.0f - 0.5f * e) / (max(lambda, 0.0f) + 1.0f);
}

// Effective roughness sigma for the pair of cosines (ci, co).
SHARED_FN float htsgSigma(float ci, float co, float tau, float sigma0) {
  float ks = htsgK(ci, tau, sigma0) + htsgK(co, tau, sigma0);
  float y2 = brdfLambertW(ks * ks / (8.0f * NUSSELT_PI));
  return sigma0 / sqrt(1.0f + y2);
}

// ln of the Poisson weight g^m e^-g / m!.
SHARED_FN float htsgLogPoisson(float m, float g) {
  if (m < 7.5f) return m * portableLog(g) - g - HTSG_LN_FACT[int(m + 0.5f)];
  // Stirling: ln m! = m ln m - m + ln(2 pi m)/2 + 1/(12 m) - 1/(360 m^3); m ln(g/m) + m - g
  // = m (ln(1 + x) - x), x = (g - m)/m, without cancellation.
  float x = (g - m) / m;
  float l1p = brdfLog1m(-x);
  return m * (l1p - x) - 0.5f * portableLog(NUSSELT_TWO_PI * m) - (1.0f / (12.0f * m) - 1.0f / (360.0f * m * m * m));
}

// The series sum_{m>=1} g^m e^-g / (m! m) exp(-c / m).
SHARED_FN float htsgSeries(float g, float c) {
  float sg = sqrt(g);
  float lo = max(1.0f, floor(g - 8.0f * sg));
  float hi = ceil(g + 8.0f * sg + 10.0f);
  float stride = max(1.0f, ceil((hi - lo + 1.0f) / float(HTSG_MAX_TERMS)));
  float sum = 0.0f;
  for (int j = 0; j < HTSG_MAX_TERMS; ++j) {
    float m = lo + float(j) * stride;
    if (m > hi) break;
    sum += exp(htsgLogPoisson(m, g) - portableLog(m) - c / m);
  }
  return sum * stride;
}

SHARED_FN vec3 htsgEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float sigma0 = brdfParam(p, HTSG_SIGMA0);
  float tau = brdfParam(p, HTSG_TAU);
  float lam = brdfParam(p, HTSG_LAM);
  float ci = wi.z;
  float co = wo.z;
  float k0 = NUSSELT_TWO_PI / lam;
  float sigma = htsgSigma(ci, co, tau, sigma0);
  float g = sqr(k0 * sigma * (ci + co));
  vec3 H = wi + wo;
  float vxy2 = k0 * k0 * (H.x * H.x + H.y * H.y);
  float D = NUSSELT_PI * NUSSELT_PI * tau * tau / (4.0f * lam * lam) * htsgSeries(g, tau * tau * vxy2 / 4.0f);
  float G = sqr(dot(H, H) / (ci + co));
  float S = htsgShadow(ci, tau, sigma0) * htsgShadow(co, tau, sigma0);
  float F = fresnelComplex(brdfHalfCos(wi, wo), brdfParam(p, HTSG_N), brdfParam(p, HTSG_K));
  float dd = F * G * S * D / (NUSSELT_PI * ci * co);
  return vec3(dd) + brdfParam3(p, HTSG_RHO_UD) * NUSSELT_INV_PI;
}

// Reflectance of the specular (delta) part at incidence cosine ci:
// rho_sp = Fr(ci; n, k) exp(-g_s) S(theta_i)^2, g_s = (2 k0 sigma_s ci)^2, sigma_s = sigma(ci, ci).
SHARED_FN float htsgSpecularReflectance(BrdfParams p, float ci) {
  if (ci <= 0.0f) return 0.0f;
  float sigma0 = brdfParam(p, HTSG_SIGMA0);
  float tau = brdfParam(p, HTSG_TAU);
  float k0 = NUSSELT_TWO_PI / brdfParam(p, HTSG_LAM);
  float sigmaS = htsgSigma(ci, ci, tau, sigma0);
  float gs = sqr(2.0f * k0 * sigmaS * ci);
  return fresnelComplex(ci, brdfParam(p, HTSG_N), brdfParam(p, HTSG_K)) * exp(-gs) * sqr(htsgShadow(ci, tau, sigma0));
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// HTSG_DELTA: 0 (evaluated and light-sampled).
// HTSG_ANALYTIC: 0: the analytic strategy samples the cosine.
#define HTSG_DELTA 0
#define HTSG_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void htsgSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "htsg";
  m.summary = "He-Torrance-Sillion-Greenberg 1991 (directional + uniform diffuse; specular spike apart)";
  m.params.push_back(scalar("sigma0", HTSG_SIGMA0, 0.25f, 0.0f, 5.0f, true, "rms roughness height [um]"));
  m.params.push_back(scalar("tau", HTSG_TAU, 2.5f, 0.0f, 50.0f, true, "autocorrelation length [um]"));
  m.params.push_back(scalar("lam", HTSG_LAM, 0.55f, 0.1f, 2.0f, false, "wavelength [um]"));
  m.params.push_back(scalar("n", HTSG_N, 1.5f, 0.0f, 10.0f, true, "real part of the relative index"));
  m.params.push_back(scalar("k", HTSG_K, 0.0f, 0.0f, 20.0f, false, "extinction coefficient"));
  m.params.push_back(colour("rho_ud", HTSG_RHO_UD, 0.1f, 0.0f, 1.0f, "uniform-diffuse albedo"));
  m.typical = {N("sigma0", 0.25), N("tau", 2.5), N("lam", 0.55), N("n", 1.5), N("k", 0), N("rho_ud", 0.1)};
  m.hard = {N("sigma0", 0.8), N("tau", 4.0), N("lam", 0.55), N("n", 1.5), N("k", 0), N("rho_ud", 0)};
  m.variants = {{"smooth", {N("sigma0", 0.04), N("tau", 0.4), N("lam", 0.55), N("n", 1.5), N("k", 0), N("rho_ud", 0)}}};
}
}  // namespace nusselt::models
#endif

#endif
