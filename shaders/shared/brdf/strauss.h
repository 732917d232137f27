// strauss: Strauss 1990, converted from reflected intensities to a BRDF by f = (Qd + Qs)/(pi ci)
// (docs/brdf-models.md 2.13). NOT reciprocal.
//   x(theta) = theta / (pi/2); Fs, Gs with kf = 1.12, kg = 1.01; d = 1 - m s; rd = (1 - s^3)(1 - t);
//   rn = (1 - t) - rd; j = Fs(xi) Gs(xi) Gs(xo); rj = min(1, rn + (rn + kj) j), kj = 0.1;
//   Cs = 1 + m (1 - Fs(xi)) (c - 1); hexp = 3 / (1 - s)
//   f = (d rd c + rj Cs max(0, cos alpha)^hexp / ci) / pi
//   c: colour in [0, 1]; s in [0, 0.99]; m, t in [0, 1].
#ifndef NUSSELT_BRDF_STRAUSS_H
#define NUSSELT_BRDF_STRAUSS_H
#include "phong_specular.h"
SHARED_BEGIN

#define STRAUSS_C 0u
#define STRAUSS_S 3u
#define STRAUSS_M 4u
#define STRAUSS_T 5u

SHARED_FN float straussF(float x) {
  float kf = 1.12f;
  return (1.0f / sqr(x - kf) - 1.0f / (kf * kf)) / (1.0f / sqr(1.0f - kf) - 1.0f / (kf * kf));
}
SHARED_FN float straussG(float x) {
  float kg = 1.01f;
  return (1.0f / sqr(1.0f - kg) - 1.0f / sqr(x - kg)) / (1.0f / sqr(1.0f - kg) - 1.0f / (kg * kg));
}

SHARED_FN vec3 straussEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 c = brdfParam3(p, STRAUSS_C);
  float s = brdfParam(p, STRAUSS_S);
  float m = brdfParam(p, STRAUSS_M);
  float t = brdfParam(p, STRAUSS_T);
  float xi = brdfTheta(wi.z) * (2.0f * NUSSELT_INV_PI);
  float xo = brdfTheta(wo.z) * (2.0f * NUSSELT_INV_PI);
  float d = 1.0f - m * s;
  float rd = (1.0f - s * s * s) * (1.0f - t);
  float rn = (1.0f - t) - rd;
  float fi = straussF(xi);
  float j = fi * straussG(xi) * straussG(xo);
  float rj = min(1.0f, rn + (rn + 0.1f) * j);
  vec3 cs = vec3(1.0f) + m * (1.0f - fi) * (c - vec3(1.0f));
  float hexp = 3.0f / (1.0f - s);
  float spec = rj * phongLobe(wi, wo, hexp) / wi.z;
  return (d * rd * c + spec * cs) * NUSSELT_INV_PI;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// STRAUSS_DELTA: 0 (evaluated and light-sampled).
// STRAUSS_ANALYTIC: 0: the analytic strategy samples the cosine.
#define STRAUSS_DELTA 0
#define STRAUSS_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
// The specular term carries 1 / cos(theta_i) of the SAMPLED direction (it is not reciprocal):
// f(., v) ~ 1 / cos at the rim wherever the lobe reaches it.
inline ModelTraits straussTraits(const BrdfParams&) {
  ModelTraits t;
  t.rimExponent = 1.0f;
  return t;
}
inline void straussSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "strauss";
  m.summary = "Strauss 1990 (intensity model converted to a BRDF; not reciprocal)";
  m.params.push_back(colour("c", STRAUSS_C, 0.8f, 0.0f, 1.0f, "surface colour"));
  m.params.push_back(scalar("s", STRAUSS_S, 0.6f, 0.0f, 0.99f, false, "smoothness (highlight exponent 3/(1-s))"));
  m.params.push_back(scalar("m", STRAUSS_M, 0.2f, 0.0f, 1.0f, false, "metalness"));
  m.params.push_back(scalar("t", STRAUSS_T, 0.0f, 0.0f, 1.0f, false, "transparency"));
  m.typical = {N("c", 0.8), N("s", 0.6), N("m", 0.2), N("t", 0)};
  m.hard = {N("c", 0.9), N("s", 0.97), N("m", 1), N("t", 0)};
  m.traits = &straussTraits;
}
}  // namespace nusselt::models
#endif

#endif
