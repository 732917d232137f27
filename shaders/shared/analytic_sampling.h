// analytic_sampling.h: the `analytic` BSDF sampling strategy (SAMPLER_ANALYTIC): each model's own
// importance sampling where the literature gives one, cosine-weighted hemisphere sampling
// elsewhere. Shared by the CPU (tests, `nusselt sample --cpu`) and the GPU (shade stage).
//
// Convention as everywhere: brdfEval(model, p, wi, wo), wi = the SAMPLED direction (first
// argument), wo = the known direction (viewer); local frame, normal +z; pdf per unit solid angle.
//
// Strategies (docs/strategies.md has the derivations):
//   lambert                 cosine (pdf cos / pi)
//   phong_specular          cos^n lobe around the mirror direction R(wo): pdf (n+1)/(2 pi) cos^n alpha
//   phong, lewis            mixture: cosine with probability lum(kd) / (lum(kd) + lum(ks)), else
//                           the cos^n lobe around R(wo) (Lafortune & Willems 1994)
//   blinn                   mixture with cosine; half vector h with pdf_h = (n+1)/(2 pi) cos^n theta_h,
//                           wi = reflect(wo, h), pdf = pdf_h / (4 wo.h)
//   ward, torrance_sparrow  mixture with cosine; h from the (anisotropic) Beckmann distribution of
//                           slopes: pdf_h = exp(-tan^2 theta_h (cos^2 phi_h / ax^2 + sin^2 phi_h / ay^2))
//                           / (pi ax ay cos^3 theta_h) (Walter 2005, "Notes on the Ward BRDF"; Ward
//                           1992 eq. 6), torrance_sparrow with ax = ay = m (= Beckmann D(h) cos theta_h)
//   ashikhmin_shirley       mixture with cosine (weight lum(rd (1 - rs)) against lum(rs)); h with
//                           pdf_h = sqrt((nu+1)(nv+1)) / (2 pi) cos theta_h^(nu cos^2 phi + nv sin^2 phi)
//                           (Ashikhmin & Shirley 2000, eq. 9 and its sampling formulas)
//   lafortune               mixture of cosine (weight lum(rho_d)) and one cos^n_j lobe per lobe j
//                           around the axis a_j = (Cx wo.x, Cy wo.y, Cz wo.z) / |.| (weight
//                           |a_j|^n_j 2 pi / (n_j + 1): the lobe's integral over its hemisphere)
//   all other models        cosine
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

// Does the model have its own sampler here (else analyticSample is cosine sampling)?
SHARED_FN bool analyticHasSampler(uint model) {
  return model == MODEL_LAMBERT || model == MODEL_PHONG_SPECULAR || model == MODEL_PHONG || model == MODEL_LEWIS ||
         model == MODEL_BLINN || model == MODEL_WARD || model == MODEL_TORRANCE_SPARROW ||
         model == MODEL_ASHIKHMIN_SHIRLEY || model == MODEL_LAFORTUNE;
}

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

// Ashikhmin-Shirley half-vector density pdf_h(h) / (4 wo.h) (exponent as ashikhminShirleyEval).
SHARED_FN float analyticAshikhminPdf(float nu, float nv, vec3 wi, vec3 wo) {
  vec3 h = brdfHalf(wi, wo);
  if (h.z <= 0.0f) return 0.0f;
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  float s2 = brdfSin2(h);
  float lobe = exp((nu * h.x * h.x + nv * h.y * h.y) * 0.5f * brdfLog1mOverX(s2));
  return sqrt((nu + 1.0f) * (nv + 1.0f)) * (0.5f * NUSSELT_INV_PI) * lobe / (4.0f * cb);
}

// Blinn half-vector density pdf_h(h) / (4 wo.h), pdf_h = (n+1)/(2 pi) cos^n theta_h.
SHARED_FN float analyticBlinnPdf(float n, vec3 wi, vec3 wo) {
  vec3 h = brdfHalf(wi, wo);
  if (h.z <= 0.0f) return 0.0f;
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  return (n + 1.0f) * (0.5f * NUSSELT_INV_PI) * brdfPowOneMinus(brdfOneMinusCos(h), n) / (4.0f * cb);
}

// Lafortune: the lobe axis of lobe j for wo (unnormalised) and its log mixture weight
// n log|a| + log(2 pi / (n + 1)); returns false for a lobe with a zero axis (no weight).
SHARED_FN bool analyticLafortuneLobe(BrdfParams p, uint j, vec3 wo, OUT(vec3) axis, OUT(float) n, OUT(float) logWeight) {
  uint o = LAFORTUNE_LOBES + 4u * j;
  vec3 a = vec3(brdfParam(p, o) * wo.x, brdfParam(p, o + 1u) * wo.y, brdfParam(p, o + 2u) * wo.z);
  n = brdfParam(p, o + 3u);
  float len = length(a);
  axis = vec3(0.0f, 0.0f, 1.0f);
  logWeight = -3.4e38f;
  if (!(len > 1e-20f)) return false;
  axis = a / len;
  logWeight = n * portableLog(len) + portableLog(NUSSELT_TWO_PI / (n + 1.0f));
  return true;
}

// Lafortune mixture weights, normalised: the diffuse one returned, the lobes' in w (index j).
// Lobe j's weight in (wA, wB) (two vec4: 8 slots >= LAFORTUNE_MAX_LOBES; no array parameters in
// shared code).
SHARED_FN float analyticWeightAt(vec4 wA, vec4 wB, int j) { return j < 4 ? wA[j] : wB[j - 4]; }
SHARED_FN float analyticLafortuneWeights(BrdfParams p, vec3 wo, OUT(vec4) wA, OUT(vec4) wB) {
  float w[LAFORTUNE_MAX_LOBES];
  uint count = uint(brdfParam(p, LAFORTUNE_LOBE_COUNT) + 0.5f);
  float lw[LAFORTUNE_MAX_LOBES];
  bool ok[LAFORTUNE_MAX_LOBES];
  float rho = luminance(brdfParam3(p, LAFORTUNE_RHO_D));
  float ld = rho > 0.0f ? portableLog(rho) : -3.4e38f;
  float mx = ld;
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    vec3 axis;
    float n;
    ok[j] = uint(j) < count && analyticLafortuneLobe(p, uint(j), wo, axis, n, lw[j]);
    if (ok[j]) mx = max(mx, lw[j]);
  }
  float wd = rho > 0.0f ? exp(ld - mx) : 0.0f;
  float sum = wd;
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    w[j] = ok[j] ? exp(lw[j] - mx) : 0.0f;
    sum += w[j];
  }
  wA = vec4(0.0f);
  wB = vec4(0.0f);
  if (!(sum > 0.0f)) return 1.0f;  // nothing reflects: all cosine
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    if (j < 4) wA[j] = w[j] / sum;
    else wB[j - 4] = w[j] / sum;
  }
  return wd / sum;
}

// Probability of the cosine component of the two-component models (1: cosine only).
SHARED_FN float analyticDiffuseProbability(uint model, BrdfParams p) {
  float wd = 1.0f;
  float ws = 0.0f;
  if (model == MODEL_PHONG_SPECULAR) {
    wd = 0.0f;
    ws = 1.0f;
  } else if (model == MODEL_PHONG || model == MODEL_LEWIS) {
    wd = luminance(brdfParam3(p, PHONG_KD));
    ws = luminance(brdfParam3(p, PHONG_KS));
  } else if (model == MODEL_BLINN) {
    wd = luminance(brdfParam3(p, BLINN_KD));
    ws = luminance(brdfParam3(p, BLINN_KS));
  } else if (model == MODEL_WARD) {
    wd = luminance(brdfParam3(p, WARD_KD));
    ws = luminance(brdfParam3(p, WARD_KS));
  } else if (model == MODEL_TORRANCE_SPARROW) {
    wd = luminance(brdfParam3(p, TORRANCE_SPARROW_KD));
    ws = luminance(brdfParam3(p, TORRANCE_SPARROW_KS));
  } else if (model == MODEL_ASHIKHMIN_SHIRLEY) {
    vec3 rs = brdfParam3(p, ASHIKHMIN_SHIRLEY_RS);
    wd = luminance(brdfParam3(p, ASHIKHMIN_SHIRLEY_RD) * (vec3(1.0f) - rs));
    ws = luminance(rs);
  }
  if (!(wd + ws > 0.0f)) return 1.0f;
  return wd / (wd + ws);
}

// Density per unit solid angle of analyticSample's successful samples at wi (0 below the surface).
SHARED_FN float analyticPdf(uint model, BrdfParams p, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  float cosPdf = wi.z * NUSSELT_INV_PI;
  if (!analyticHasSampler(model) || model == MODEL_LAMBERT) return cosPdf;
  if (model == MODEL_LAFORTUNE) {
    vec4 wA;
    vec4 wB;
    float pd = analyticLafortuneWeights(p, wo, wA, wB);
    float sum = pd * cosPdf;
    for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
      float wj = analyticWeightAt(wA, wB, j);
      if (!(wj > 0.0f)) continue;
      vec3 axis;
      float n;
      float lw;
      analyticLafortuneLobe(p, uint(j), wo, axis, n, lw);
      sum += wj * analyticLobePdf(axis, n, wi);
    }
    return sum;
  }
  float pd = analyticDiffuseProbability(model, p);
  float spec = 0.0f;
  if (pd < 1.0f) {
    if (model == MODEL_PHONG_SPECULAR) {
      spec = analyticLobePdf(brdfReflectZ(wo), brdfParam(p, PHONG_SPECULAR_N), wi);
    } else if (model == MODEL_PHONG || model == MODEL_LEWIS) {
      spec = analyticLobePdf(brdfReflectZ(wo), brdfParam(p, PHONG_N), wi);
    } else if (model == MODEL_BLINN) {
      spec = analyticBlinnPdf(brdfParam(p, BLINN_N), wi, wo);
    } else if (model == MODEL_WARD) {
      spec = analyticBeckmannPdf(brdfParam(p, WARD_AX), brdfParam(p, WARD_AY), wi, wo);
    } else if (model == MODEL_TORRANCE_SPARROW) {
      float m = brdfParam(p, TORRANCE_SPARROW_M);
      spec = analyticBeckmannPdf(m, m, wi, wo);
    } else if (model == MODEL_ASHIKHMIN_SHIRLEY) {
      spec = analyticAshikhminPdf(brdfParam(p, ASHIKHMIN_SHIRLEY_NU), brdfParam(p, ASHIKHMIN_SHIRLEY_NV), wi, wo);
    }
  }
  return pd * cosPdf + (1.0f - pd) * spec;
}

// Reflects wo about the half vector h; false when wo.h <= 0 (that h has no valid reflection: a
// failed sample) or the result is below the surface.
SHARED_FN bool analyticReflectHalf(vec3 wo, vec3 h, OUT(vec3) wi) {
  float c = dot(wo, h);
  wi = normalize(2.0f * c * h - wo);
  return c > 0.0f && wi.z > 0.0f;
}

// Draws wi for the known direction wo (wo.z > 0) with two uniform numbers in [0, 1); returns false
// (wi = (0, 0, 1), pdf = 0) for a failed sample (below the surface: see the header comment).
SHARED_FN bool analyticSample(uint model, BrdfParams p, vec3 wo, vec2 u, OUT(vec3) wi, OUT(float) pdf) {
  wi = vec3(0.0f, 0.0f, 1.0f);
  pdf = 0.0f;
  if (wo.z <= 0.0f) return false;
  float ux = u.x;
  bool cosine = true;
  vec3 d = vec3(0.0f, 0.0f, 1.0f);
  bool ok = true;
  if (model == MODEL_LAFORTUNE) {
    vec4 wA;
    vec4 wB;
    float pd = analyticLafortuneWeights(p, wo, wA, wB);
    if (ux >= pd) {
      cosine = false;
      float t = ux - pd;
      int chosen = -1;
      float wc = 0.0f;
      for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
        float wj = analyticWeightAt(wA, wB, j);
        if (!(wj > 0.0f)) continue;
        chosen = j;  // the last lobe with weight takes rounding leftovers
        wc = wj;
        if (t < wj) break;
        t -= wj;
      }
      if (chosen < 0) return false;
      ux = clamp(t / wc, 0.0f, NUSSELT_ONE_MINUS_EPS);
      vec3 axis;
      float n;
      float lw;
      analyticLafortuneLobe(p, uint(chosen), wo, axis, n, lw);
      d = analyticAround(axis, analyticLobeOneMinusCos(1.0f - ux, n), NUSSELT_TWO_PI * u.y);
    } else {
      ux = ux / pd;
    }
  } else if (analyticHasSampler(model) && model != MODEL_LAMBERT) {
    float pd = analyticDiffuseProbability(model, p);
    if (ux >= pd) {
      cosine = false;
      ux = clamp((ux - pd) / (1.0f - pd), 0.0f, NUSSELT_ONE_MINUS_EPS);
      float phi = NUSSELT_TWO_PI * u.y;
      if (model == MODEL_PHONG_SPECULAR || model == MODEL_PHONG || model == MODEL_LEWIS) {
        float n = brdfParam(p, model == MODEL_PHONG_SPECULAR ? PHONG_SPECULAR_N : PHONG_N);
        d = analyticAround(brdfReflectZ(wo), analyticLobeOneMinusCos(1.0f - ux, n), phi);
      } else if (model == MODEL_BLINN) {
        float omc = analyticLobeOneMinusCos(1.0f - ux, brdfParam(p, BLINN_N));
        float s = sqrt(max(omc * (2.0f - omc), 0.0f));
        ok = analyticReflectHalf(wo, normalize(vec3(s * cos(phi), s * sin(phi), 1.0f - omc)), d);
      } else if (model == MODEL_WARD || model == MODEL_TORRANCE_SPARROW) {
        float ax = model == MODEL_WARD ? brdfParam(p, WARD_AX) : brdfParam(p, TORRANCE_SPARROW_M);
        float ay = model == MODEL_WARD ? brdfParam(p, WARD_AY) : ax;
        // Slope space: tan theta_h (cos phi_h / ax, sin phi_h / ay) has |.|^2 = -log(1 - ux).
        float r = sqrt(max(-portableLog(1.0f - ux), 0.0f));
        ok = analyticReflectHalf(wo, normalize(vec3(r * ax * cos(phi), r * ay * sin(phi), 1.0f)), d);
      } else {  // MODEL_ASHIKHMIN_SHIRLEY
        float nu = brdfParam(p, ASHIKHMIN_SHIRLEY_NU);
        float nv = brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
        // tan phi_h = sqrt((nu+1)/(nv+1)) tan(2 pi u.y), in the quadrant of 2 pi u.y.
        vec2 cs = normalize(vec2(sqrt(nv + 1.0f) * cos(phi), sqrt(nu + 1.0f) * sin(phi)));
        float e = nu * cs.x * cs.x + nv * cs.y * cs.y;
        float omc = analyticLobeOneMinusCos(1.0f - ux, e);
        float s = sqrt(max(omc * (2.0f - omc), 0.0f));
        ok = analyticReflectHalf(wo, normalize(vec3(s * cs.x, s * cs.y, 1.0f - omc)), d);
      }
    } else {
      ux = ux / pd;
    }
  }
  if (cosine) d = squareToCosineHemisphere(vec2(min(ux, NUSSELT_ONE_MINUS_EPS), u.y));
  if (!ok || !(d.z > 0.0f)) return false;
  wi = d;
  pdf = analyticPdf(model, p, wo, wi);
  return pdf > 0.0f;
}

SHARED_END
#endif
