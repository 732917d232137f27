// lewis: Lewis 1994 "physically plausible Phong" = the normalised Phong of phong.h (one formula;
// docs/brdf-models.md 2.4). Same parameter layout (kd, ks, n); its own model id and defaults.
#ifndef NUSSELT_BRDF_LEWIS_H
#define NUSSELT_BRDF_LEWIS_H
#include "phong.h"
SHARED_BEGIN

#define LEWIS_KD PHONG_KD
#define LEWIS_KS PHONG_KS
#define LEWIS_N PHONG_N

SHARED_FN vec3 lewisEval(BrdfParams p, vec3 wi, vec3 wo) { return phongEval(p, wi, wo); }

// ---- Analytic sampling: phong's (same function) ----
SHARED_FN bool lewisAnalyticSample(BrdfParams p, vec3 wo, vec2 u, OUT(vec3) d) { return phongAnalyticSample(p, wo, u, d); }
SHARED_FN float lewisAnalyticPdf(BrdfParams p, vec3 wo, vec3 wi) { return phongAnalyticPdf(p, wo, wi); }

SHARED_END

// ---- Traits read by the model list (models.h) ----
// LEWIS_DELTA: 0 (evaluated and light-sampled).
// LEWIS_ANALYTIC: 1, the analytic strategy uses lewisAnalyticSample / lewisAnalyticPdf.
#define LEWIS_DELTA 0
#define LEWIS_ANALYTIC 1

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline void lewisSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "lewis";
  m.summary = "Lewis 1994 plausible Phong (= normalised phong)";
  m.params.push_back(colour("kd", LEWIS_KD, 0.6f, 0.0f, 1.0f, "diffuse albedo"));
  m.params.push_back(colour("ks", LEWIS_KS, 0.3f, 0.0f, 1.0f, "specular albedo at normal incidence"));
  m.params.push_back(scalar("n", LEWIS_N, 20.0f, 0.0f, 100000.0f, false, "exponent"));
  m.typical = {N("kd", 0.6f), N("ks", 0.3f), N("n", 20.0f)};
  m.hard = {N("kd", 0), N("ks", 1), N("n", 5000)};
}
}  // namespace nusselt::models
#endif

#endif
