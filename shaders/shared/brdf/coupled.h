// coupled: Kelemen & Szirmay-Kalos 2001 coupled specular-matte model (docs/brdf-models.md 2.17):
//   f_s = Fschlick(cb; f0) Dbeck(h; m) / (4 cb^2)
//   f_m = rd (1 - a_s(theta_i)) (1 - a_s(theta_o)) / (pi (1 - abar_s))
//   rd, f0: colour in [0, 1]; m in (0, 1].
// The specular albedo a_s is linear in f0 (Schlick): a_s = f0 A1(theta) + A2(theta) with
//   A1 = int (1 - (1 - cb)^5) D / (4 cb^2) co dw,  A2 = int (1 - cb)^5 D / (4 cb^2) co dw.
// Both tables (COUPLED_TABLE_SIZE samples each, at cos theta = (j / (N - 1))^2, the first at
// cos(89.999 deg), piecewise linear in sqrt(cos theta)) and their cosine-weighted averages
// Abar1, Abar2 (computed from the interpolants, so the matte term integrates exactly to
// rd (1 - a_s(theta_i))) live in the parameter block; the registry's packing computes them on the
// CPU (src/brdf/albedo.cpp, fillCoupledTables, integrating over the half vector in double
// precision). No extra buffer is needed; GpuMaterial.info.z stays unused for coupled.
#ifndef NUSSELT_BRDF_COUPLED_H
#define NUSSELT_BRDF_COUPLED_H
#include "common.h"
SHARED_BEGIN

#define COUPLED_RD 0u
#define COUPLED_F0 3u
#define COUPLED_M 6u
#define COUPLED_ABAR1 7u
#define COUPLED_ABAR2 8u
#define COUPLED_TABLE1 9u
#define COUPLED_TABLE2 20u
#define COUPLED_TABLE_SIZE 11

// Specular part (also used by the CPU to build the tables).
SHARED_FN vec3 coupledSpecular(vec3 f0, float m, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 h = brdfHalf(wi, wo);
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  return fresnelSchlick3(cb, f0) * (beckmannD(h, m) / (4.0f * cb * cb));
}

// Table abscissa of sample j: sqrt(cos theta).
SHARED_FN float coupledTableX(int j) {
  if (j == 0) return 0.0041791f;  // sqrt(cos(89.999 degrees))
  return float(j) / float(COUPLED_TABLE_SIZE - 1);
}

// Interpolated table value at cosine c (offset = COUPLED_TABLE1 or COUPLED_TABLE2).
SHARED_FN float coupledTable(BrdfParams p, uint offset, float c) {
  float s = sqrt(clamp(c, 0.0f, 1.0f)) * float(COUPLED_TABLE_SIZE - 1);
  int j = min(int(s), COUPLED_TABLE_SIZE - 2);
  float x0 = coupledTableX(j);
  float x1 = coupledTableX(j + 1);
  float t = clamp((s / float(COUPLED_TABLE_SIZE - 1) - x0) / (x1 - x0), 0.0f, 1.0f);
  return mix(brdfParam(p, offset + uint(j)), brdfParam(p, offset + uint(j) + 1u), t);
}

SHARED_FN vec3 coupledSpecularAlbedo(BrdfParams p, float c) {
  return brdfParam3(p, COUPLED_F0) * coupledTable(p, COUPLED_TABLE1, c) + vec3(coupledTable(p, COUPLED_TABLE2, c));
}

SHARED_FN vec3 coupledEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 f0 = brdfParam3(p, COUPLED_F0);
  vec3 abar = f0 * brdfParam(p, COUPLED_ABAR1) + vec3(brdfParam(p, COUPLED_ABAR2));
  vec3 ai = min(coupledSpecularAlbedo(p, wi.z), vec3(1.0f));
  vec3 ao = min(coupledSpecularAlbedo(p, wo.z), vec3(1.0f));
  vec3 matte = brdfParam3(p, COUPLED_RD) * (vec3(1.0f) - ai) * (vec3(1.0f) - ao) /
               (NUSSELT_PI * max(vec3(1.0f) - abar, vec3(1e-6f)));
  return coupledSpecular(f0, brdfParam(p, COUPLED_M), wi, wo) + matte;
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// COUPLED_DELTA: 0 (evaluated and light-sampled).
// COUPLED_ANALYTIC: 0: the analytic strategy samples the cosine.
#define COUPLED_DELTA 0
#define COUPLED_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt {
void fillCoupledTables(shared::BrdfParams& params);  // src/brdf/albedo.cpp: the specular albedo tables
}  // namespace nusselt
namespace nusselt::models {
inline void coupledSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "coupled";
  m.summary = "Kelemen & Szirmay-Kalos 2001 coupled specular-matte";
  m.params.push_back(colour("rd", COUPLED_RD, 0.6f, 0.0f, 1.0f, "matte albedo"));
  m.params.push_back(colour("f0", COUPLED_F0, 0.05f, 0.0f, 1.0f, "Fresnel reflectance at normal incidence"));
  m.params.push_back(scalar("m", COUPLED_M, 0.2f, 0.01f, 1.0f, false,
                            "Beckmann rms slope (>= 0.01: the specular albedo table is computed at load)"));
  m.typical = {N("rd", 0.6), N("f0", 0.05), N("m", 0.2)};
  m.hard = {N("rd", 0.9), N("f0", 0.9), N("m", 0.02)};
  m.finishParams = &fillCoupledTables;
}
}  // namespace nusselt::models
#endif

#endif
