// common.h: helpers shared by the reflectance models (C++17 + GLSL 4.60): accurate powers of
// cosines near 1, half vectors, Fresnel (exact complex-index and Schlick), Beckmann, erfc,
// Lambert W, log-factorial. Conventions: docs/brdf-models.md section 0.
#ifndef NUSSELT_BRDF_COMMON_H
#define NUSSELT_BRDF_COMMON_H
#include "../layout.h"
SHARED_BEGIN

// Marks a parameter unused (delta models' eval) without a C++ warning; nothing in GLSL.
#ifdef __cplusplus
#define BRDF_UNUSED(x) (void)(x)
#else
#define BRDF_UNUSED(x)
#endif

// Mirror direction about the normal +z.
SHARED_FN vec3 brdfReflectZ(vec3 w) { return vec3(-w.x, -w.y, w.z); }

// portableLog(1 - x) for x < 1, accurate to a few ulps on CPU and GPU alike. GLSL has no log1p, and
// Vulkan allows log/log2 an ABSOLUTE error of 2^-21 for arguments in [0.5, 2] (lavapipe's is of
// that order): portableLog(0.99) would carry a 3e-5 relative error, which exp(n portableLog(1 - x)) with
// n = 5000 turns into 0.15 %. So for 1 - x >= 0.5 the logarithm is computed by the series
// portableLog(1 - x) = -2 atanh(z) = -2 (z + z^3/3 + z^5/5 + ...), z = x / (2 - x) <= 1/3 (11 terms:
// truncation below 1e-11); below 0.5 the built-in log is accurate (3 ulp).
SHARED_FN float brdfLog1mSeriesOverX(float x) {  // portableLog(1 - x) / x for |x| <= 0.5
  float r = 1.0f / (2.0f - x);                   // z = x r
  float z = x * r;
  float z2 = z * z;
  float s = 1.0f + z2 * (1.0f / 3.0f + z2 * (1.0f / 5.0f + z2 * (1.0f / 7.0f + z2 * (1.0f / 9.0f + z2 * (1.0f / 11.0f +
            z2 * (1.0f / 13.0f + z2 * (1.0f / 15.0f + z2 * (1.0f / 17.0f + z2 * (1.0f / 19.0f + z2 / 21.0f)))))))));
  return -2.0f * r * s;
}

SHARED_FN float brdfLog1m(float x) {
  if (abs(x) <= 0.5f) return x * brdfLog1mSeriesOverX(x);
  return portableLog(max(1.0f - x, 1e-37f));
}

// portableLog(1 - x) / x (-> -1 as x -> 0), x < 1.
SHARED_FN float brdfLog1mOverX(float x) {
  if (abs(x) <= 0.5f) return brdfLog1mSeriesOverX(x);
  return portableLog(max(1.0f - x, 1e-37f)) / x;
}

// (1 - omc)^n for omc = 1 - cos in [0, 1], n >= 0: exp(n portableLog(1 - omc)), with no pow() of values
// near 1 (a float cos near 1 has too few bits for n = 20000). Zero for omc >= 1 (cos <= 0).
SHARED_FN float brdfPowOneMinus(float omc, float n) {
  if (omc >= 1.0f) return 0.0f;
  return exp(n * brdfLog1m(max(omc, 0.0f)));
}

// 1 - a.b for unit vectors, without cancellation when a ~ b: |a - b|^2 / 2.
SHARED_FN float brdfOneMinusDot(vec3 a, vec3 b) {
  vec3 d = a - b;
  return 0.5f * dot(d, d);
}

// sin^2 of the polar angle of a unit vector, accurate near the pole.
SHARED_FN float brdfSin2(vec3 w) { return w.x * w.x + w.y * w.y; }

// 1 - cos of the polar angle of a unit vector with w.z >= 0, accurate near the pole.
SHARED_FN float brdfOneMinusCos(vec3 w) { return brdfSin2(w) / (1.0f + max(w.z, 0.0f)); }

// Normalised half vector of two directions above the surface (never zero there).
SHARED_FN vec3 brdfHalf(vec3 wi, vec3 wo) { return normalize(wi + wo); }

// cos(beta) = wi.h = wo.h, computed as |wi + wo| / 2: symmetric in wi, wo and well conditioned
// when wi and wo are nearly opposite (dot(wi, h) is not: the unit-length error of float inputs
// divided by a small |wi + wo| breaks reciprocity by percents at grazing).
SHARED_FN float brdfHalfCos(vec3 wi, vec3 wo) { return 0.5f * length(wi + wo); }

// Cosine of the relative azimuth of wi and wo; 0 when either lies on the normal.
SHARED_FN float brdfCosPhi(vec3 wi, vec3 wo) {
  float d = (wi.x * wi.x + wi.y * wi.y) * (wo.x * wo.x + wo.y * wo.y);
  if (d < 1e-30f) return 0.0f;
  return clamp((wi.x * wo.x + wi.y * wo.y) / sqrt(d), -1.0f, 1.0f);
}

// Polar angle from the cosine, accurate near 0 and 90 degrees.
SHARED_FN float brdfTheta(float c) { return portableAtan2(cosFromSin(c), c); }

// Unpolarised Fresnel reflectance for relative complex index eta + i k at incidence cosine c
// (exact; eta < 1, k = 0 gives total internal reflection = 1). The formulation of
// Pharr-Jakob-Humphreys (PBRT-v3 FrConductor), valid for any k >= 0.
SHARED_FN float fresnelComplex(float c, float eta, float k) {
  c = clamp(c, 0.0f, 1.0f);
  float c2 = c * c;
  float s2 = 1.0f - c2;
  float eta2 = eta * eta;
  float k2 = k * k;
  float t0 = eta2 - k2 - s2;
  float a2b2 = sqrt(max(t0 * t0 + 4.0f * eta2 * k2, 0.0f));
  float t1 = a2b2 + c2;
  float a = sqrt(max(0.5f * (a2b2 + t0), 0.0f));
  float t2 = 2.0f * c * a;
  float rs = (t1 - t2) / max(t1 + t2, 1e-30f);
  float t3 = c2 * a2b2 + s2 * s2;
  float t4 = t2 * s2;
  float rp = rs * (t3 - t4) / max(t3 + t4, 1e-30f);
  return clamp(0.5f * (rs + rp), 0.0f, 1.0f);
}

SHARED_FN vec3 fresnelComplex3(float c, vec3 eta, vec3 k) {
  return vec3(fresnelComplex(c, eta.x, k.x), fresnelComplex(c, eta.y, k.y), fresnelComplex(c, eta.z, k.z));
}

// Unpolarised dielectric Fresnel (k = 0), with total internal reflection for eta < 1.
SHARED_FN float fresnelDielectric(float c, float eta) { return fresnelComplex(c, eta, 0.0f); }

SHARED_FN float schlickWeight(float c) {
  float m = clamp(1.0f - c, 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}
SHARED_FN vec3 fresnelSchlick3(float c, vec3 f0) { return f0 + (vec3(1.0f) - f0) * schlickWeight(c); }
SHARED_FN float fresnelSchlick(float c, float f0) { return f0 + (1.0f - f0) * schlickWeight(c); }

// Beckmann distribution from the half vector h (unit, h.z > 0), rms slope m, normalised so that
// the integral of D(h) h.z over the hemisphere is 1. tan^2 from the xy part (accurate at h = n).
SHARED_FN float beckmannD(vec3 h, float m) {
  float c2 = h.z * h.z;
  if (c2 <= 0.0f) return 0.0f;
  float tan2 = brdfSin2(h) / c2;
  float m2 = m * m;
  return exp(-tan2 / m2) / (NUSSELT_PI * m2 * c2 * c2);
}

// Complementary error function, fractional error < 1.2e-7 everywhere (Chebyshev fit of
// Numerical Recipes' erfcc). GLSL has no erfc; C++ uses the same code for identical results.
SHARED_FN float brdfErfc(float x) {
  float z = abs(x);
  float t = 1.0f / (1.0f + 0.5f * z);
  float r = t * exp(-z * z - 1.26551223f +
                    t * (1.00002368f + t * (0.37409196f + t * (0.09678418f + t * (-0.18628806f +
                    t * (0.27886807f + t * (-1.13520398f + t * (1.48851587f + t * (-0.82215223f +
                    t * 0.17087277f)))))))));
  return x >= 0.0f ? r : 2.0f - r;
}

// Principal branch of Lambert W for x >= 0 (Halley iterations from portableLog(1 + x); 8 fixed steps
// converge to float precision for x up to 1e30).
SHARED_FN float brdfLambertW(float x) {
  if (x <= 0.0f) return 0.0f;
  float w = portableLog(1.0f + x);
  if (x > 3.0f) w = w - portableLog(max(w, 1e-3f));
  for (int i = 0; i < 8; ++i) {
    float ew = exp(w);
    float f = w * ew - x;
    float d = ew * (w + 1.0f);
    w = w - f / (d - (w + 2.0f) * f / (2.0f * w + 2.0f));
  }
  return max(w, 0.0f);
}

SHARED_END
#endif
