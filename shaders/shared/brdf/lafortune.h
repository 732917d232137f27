// lafortune: generalised cosine lobes of Lafortune et al. 1997 (docs/brdf-models.md 2.9):
//   f = rho_d / pi + sum_j max(0, Cx_j wi.x wo.x + Cy_j wi.y wo.y + Cz_j wi.z wo.z)^n_j
//   rho_d: colour in [0, 1]; up to LAFORTUNE_MAX_LOBES lobes (Cx, Cy, Cz, n), grey.
// Layout: rho_d at 0..2, the lobe count at 3, lobe j at 4 + 4 j (Cx, Cy, Cz, n).
#ifndef NUSSELT_BRDF_LAFORTUNE_H
#define NUSSELT_BRDF_LAFORTUNE_H
#include "sampling_common.h"
SHARED_BEGIN

#define LAFORTUNE_RHO_D 0u
#define LAFORTUNE_LOBE_COUNT 3u
#define LAFORTUNE_LOBES 4u
#define LAFORTUNE_MAX_LOBES 7

SHARED_FN vec3 lafortuneEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  uint count = uint(brdfParam(p, LAFORTUNE_LOBE_COUNT) + 0.5f);
  float sum = 0.0f;
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    if (uint(j) >= count) break;
    uint o = LAFORTUNE_LOBES + 4u * uint(j);
    float d = brdfParam(p, o) * wi.x * wo.x + brdfParam(p, o + 1u) * wi.y * wo.y +
              brdfParam(p, o + 2u) * wi.z * wo.z;
    if (d > 0.0f) sum += exp(brdfParam(p, o + 3u) * portableLog(d));
  }
  return brdfParam3(p, LAFORTUNE_RHO_D) * NUSSELT_INV_PI + vec3(sum);
}

// ---- Analytic sampling (sampling_common.h): a mixture of cosine (weight lum(rho_d)) and one
// cos^n_j lobe per lobe j around the axis a_j = (Cx wo.x, Cy wo.y, Cz wo.z) / |.| (weight
// |a_j|^n_j 2 pi / (n_j + 1): the lobe's integral over its hemisphere) ----
// The lobe axis of lobe j for wo (unnormalised) and its log mixture weight
// n log|a| + log(2 pi / (n + 1)); returns false for a lobe with a zero axis (no weight).
SHARED_FN bool lafortuneAnalyticLobe(BrdfParams p, uint j, vec3 wo, OUT(vec3) axis, OUT(float) n, OUT(float) logWeight) {
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

// Lobe j's weight in (wA, wB) (two vec4: 8 slots >= LAFORTUNE_MAX_LOBES; no array parameters in
// shared code).
SHARED_FN float lafortuneAnalyticWeightAt(vec4 wA, vec4 wB, int j) { return j < 4 ? wA[j] : wB[j - 4]; }

// The mixture weights, normalised: the diffuse one returned, the lobes' in (wA, wB).
SHARED_FN float lafortuneAnalyticWeights(BrdfParams p, vec3 wo, OUT(vec4) wA, OUT(vec4) wB) {
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
    ok[j] = uint(j) < count && lafortuneAnalyticLobe(p, uint(j), wo, axis, n, lw[j]);
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

SHARED_FN bool lafortuneAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) {
  vec4 wA;
  vec4 wB;
  float pd = lafortuneAnalyticWeights(p, wo, wA, wB);
  float ux = u.x;
  if (!(ux >= pd)) return analyticCosineSample(ux / pd, u.y, d);
  float t = ux - pd;
  int chosen = -1;
  float wc = 0.0f;
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    float wj = lafortuneAnalyticWeightAt(wA, wB, j);
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
  lafortuneAnalyticLobe(p, uint(chosen), wo, axis, n, lw);
  d = analyticAround(axis, analyticLobeOneMinusCos(1.0f - ux, n), NUSSELT_TWO_PI * u.y);
  return true;
}

SHARED_FN float lafortuneAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) {
  vec4 wA;
  vec4 wB;
  float pd = lafortuneAnalyticWeights(p, wo, wA, wB);
  float sum = pd * (wi.z * NUSSELT_INV_PI);
  for (int j = 0; j < LAFORTUNE_MAX_LOBES; ++j) {
    float wj = lafortuneAnalyticWeightAt(wA, wB, j);
    if (!(wj > 0.0f)) continue;
    vec3 axis;
    float n;
    float lw;
    lafortuneAnalyticLobe(p, uint(j), wo, axis, n, lw);
    sum += wj * analyticLobePdf(axis, n, wi);
  }
  return sum;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// LAFORTUNE_DELTA: 0 (evaluated and light-sampled).
// LAFORTUNE_ANALYTIC: 1, the analytic strategy uses lafortuneAnalyticSample / lafortuneAnalyticPdf.
#define LAFORTUNE_DELTA 0
#define LAFORTUNE_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits lafortuneTraits(const BrdfParams& p) {
  using shared::brdfParam;
  ModelTraits t;
  std::uint32_t count = std::uint32_t(brdfParam(p, LAFORTUNE_LOBE_COUNT) + 0.5f);
  for (std::uint32_t j = 0; j < count; ++j) {
    std::uint32_t o = LAFORTUNE_LOBES + 4 * j;
    if (brdfParam(p, o) != brdfParam(p, o + 1)) t.anisotropic = true;
  }
  return t;
}
// Each lobe peaks on its axis (Cx v.x, Cy v.y, Cz v.z), or on the rim where the axis points below.
inline void lafortuneFeatures(const BrdfParams& p, const shared::vec3& v, ModelFeatures& out) {
  using shared::brdfParam;
  std::uint32_t count = std::uint32_t(brdfParam(p, LAFORTUNE_LOBE_COUNT) + 0.5f);
  for (std::uint32_t j = 0; j < count && j < LAFORTUNE_MAX_LOBES; ++j) {
    std::uint32_t o = LAFORTUNE_LOBES + 4 * j;
    double ax = brdfParam(p, o) * v.x, ay = brdfParam(p, o + 1) * v.y, az = brdfParam(p, o + 2) * v.z;
    double n = std::sqrt(ax * ax + ay * ay + az * az);
    if (n <= 0) continue;
    double hr = std::sqrt(ax * ax + ay * ay);
    if (az > 0) out.peaks.push_back({ax / n, ay / n});
    else if (hr > 0) out.peaks.push_back({ax / hr, ay / hr});
  }
}
inline void lafortuneSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "lafortune";
  m.summary = "Lafortune 1997 generalised cosine lobes";
  m.params.push_back(colour("rho_d", LAFORTUNE_RHO_D, 0.3f, 0.0f, 1.0f, "diffuse albedo"));
  const double c = std::pow(0.5 * 22.0 / (2.0 * M_PI), 1.0 / 20.0);
  ParamSpec lobes;
  lobes.name = "lobes";
  lobes.kind = ParamKind::Lobes;
  lobes.offset = LAFORTUNE_LOBE_COUNT;
  lobes.minValue = -10.0f;
  lobes.maxValue = 10.0f;
  lobes.lobeMaxExponent = 10000.0f;
  lobes.defaultLobes = {float(-c), float(-c), float(c), 20.0f};
  lobes.doc = "[[Cx, Cy, Cz, n], ...]: up to 7 lobes, coefficients in [-10, 10], n in (0, 10000]";
  m.params.push_back(lobes);
  const double c1 = std::pow(0.8 * 502.0 / (2.0 * M_PI), 1.0 / 500.0);
  const double c2 = std::pow(0.1 * 52.0 / (2.0 * M_PI), 1.0 / 50.0);
  m.typical = {N("rho_d", 0.3), {"lobes", arrayValue({lobe(-c, -c, c, 20)})}};
  m.hard = {N("rho_d", 0), {"lobes", arrayValue({lobe(-c1, -c1, 0.99 * c1, 500), lobe(c2, c2, c2, 50)})}};
  m.traits = &lafortuneTraits;
  m.features = &lafortuneFeatures;
}
}  // namespace nusselt::models
#endif

#endif
