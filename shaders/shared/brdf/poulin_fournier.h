// poulin_fournier: parallel cylinders with Phong micro-reflection (Poulin & Fournier 1990, as
// re-derived in docs/brdf-models.md 2.16). Cylinders of radius 1 with axes along the tangent x,
// axis at height h in [-0.5, 0] above the base plane, flat gaps of width d >= 0; period
// W = 2 sqrt(1 - h^2) + d. Every micro-surface point reflects with the modified Phong
//   floc = kd / pi + ks (n + 2) / (2 pi) max(0, 2 (nu.wi)(nu.wo) - wi.wo)^n
// and, single scattering with exact shadowing and masking,
//   f(wi, wo) = 1 / (W ci co) * integral over the profile of floc (nu.wi)(nu.wo) V(wi) V(wo) ds.
// Visibility depends on the projection of a direction onto the y-z plane only (tilt
// phi = atan2(|w.y|, w.z)); only the next cylinder can occlude (h >= -0.5 keeps each shadowed set
// one interval). The arc is integrated with fixed Gauss-Legendre panels (8 nodes each,
// at most 8 panels: 64 evaluations) with breakpoints at the lobe centre psi* and psi* +- (1, 3, 8)
// / sqrt(n + 1); the flat gap has a constant integrand times its common visible length.
// kd, ks: colour in [0, 1]; n in [1, 10000]; d in [0, 10]; h in [-0.5, 0]. Anisotropic.
#ifndef NUSSELT_BRDF_POULIN_FOURNIER_H
#define NUSSELT_BRDF_POULIN_FOURNIER_H
#include "common.h"
SHARED_BEGIN

#define POULIN_FOURNIER_KD 0u
#define POULIN_FOURNIER_KS 3u
#define POULIN_FOURNIER_N 6u
#define POULIN_FOURNIER_D 7u
#define POULIN_FOURNIER_H 8u

CONST_ARRAY(float) PF_GL_X[8] = {-0.96028986f, -0.79666648f, -0.52553241f, -0.18343464f,
                                 0.18343464f, 0.52553241f, 0.79666648f, 0.96028986f};
CONST_ARRAY(float) PF_GL_W[8] = {0.10122854f, 0.22238103f, 0.31370665f, 0.36268378f,
                                 0.36268378f, 0.31370665f, 0.22238103f, 0.10122854f};

// Visible arc angles (psi from the top, positive towards +y) for direction w: (lo, hi).
SHARED_FN vec2 pfArcVisible(vec3 w, float W) {
  float phi = portableAtan2(abs(w.y), w.z);
  float c = clamp(W * cos(phi) - 1.0f, -1.0f, 1.0f);
  float K = W * sin(phi);
  float occ = portableAsin(c);
  if (K < 1.0f) occ = max(occ, portableAcos(K));
  float lo = phi - 0.5f * NUSSELT_PI;
  float hi = phi + occ;
  if (w.y < 0.0f) return vec2(-hi, -lo);
  return vec2(lo, hi);
}

// Shadowed part (y0, y1) of the gap [a, W - a] for direction w (empty when y1 <= y0).
SHARED_FN vec2 pfGapShadow(vec3 w, float W, float a, float h) {
  float phi = portableAtan2(abs(w.y), w.z);
  float sp = sin(phi);
  float cp = cos(phi);
  float y0 = max(a, W - (1.0f + h * sp) / max(cp, 1e-30f));
  float y1 = sp > 0.0f ? min(W - a, W - abs(h) * cp / sp) : a;
  if (y1 <= y0) return vec2(a, a);
  if (w.y < 0.0f) return vec2(W - y1, W - y0);
  return vec2(y0, y1);
}

SHARED_FN float pfLength(vec2 iv) { return max(iv.y - iv.x, 0.0f); }

SHARED_FN vec3 poulinFournierEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  float n = brdfParam(p, POULIN_FOURNIER_N);
  float d = brdfParam(p, POULIN_FOURNIER_D);
  float h = brdfParam(p, POULIN_FOURNIER_H);
  float a = sqrt(1.0f - h * h);
  float W = 2.0f * a + d;
  float psiMax = portableAcos(-h);
  float wiwo = dot(wi, wo);
  float lobeNorm = (n + 2.0f) * (0.5f * NUSSELT_INV_PI);

  // Arc: common visible interval.
  vec2 vi = pfArcVisible(wi, W);
  vec2 vo = pfArcVisible(wo, W);
  float A = max(-psiMax, max(vi.x, vo.x));
  float B = min(psiMax, min(vi.y, vo.y));
  float arcD = 0.0f;
  float arcS = 0.0f;
  if (B > A) {
    float center = portableAtan2(wi.y + wo.y, wi.z + wo.z);
    float w1 = 1.0f / sqrt(n + 1.0f);
    // Panel boundaries: A, center +- (8, 3, 1) w1, center, B (clipped, sorted by construction).
    float lastX = A;
    for (int k = 0; k < 8; ++k) {
      float off = k == 0 ? -8.0f : k == 1 ? -3.0f : k == 2 ? -1.0f : k == 3 ? 0.0f : k == 4 ? 1.0f : k == 5 ? 3.0f : 8.0f;
      float x = k == 7 ? B : clamp(center + off * w1, A, B);
      if (x > lastX) {
        float halfLen = 0.5f * (x - lastX);
        float mid = 0.5f * (x + lastX);
        for (int j = 0; j < 8; ++j) {
          float psi = mid + halfLen * PF_GL_X[j];
          float sn = sin(psi);
          float cs = cos(psi);
          float ni = max(wi.y * sn + wi.z * cs, 0.0f);
          float no = max(wo.y * sn + wo.z * cs, 0.0f);
          float cosAlpha = 2.0f * ni * no - wiwo;
          float g = halfLen * PF_GL_W[j] * ni * no;
          arcD += g;
          arcS += g * brdfPowOneMinus(1.0f - cosAlpha, n);
        }
        lastX = x;
      }
    }
  }
  // Flat gap: the local normal is +z; common visible length = gap - |shadow_i U shadow_o|.
  vec2 si = pfGapShadow(wi, W, a, h);
  vec2 so = pfGapShadow(wo, W, a, h);
  float overlap = max(min(si.y, so.y) - max(si.x, so.x), 0.0f);
  float visible = max(d - pfLength(si) - pfLength(so) + overlap, 0.0f);
  float flatLobe = brdfPowOneMinus(brdfOneMinusDot(brdfReflectZ(wi), wo), n);
  float ciCo = wi.z * wo.z;
  float diffuse = (arcD + visible * ciCo) / (W * ciCo);
  float specular = (arcS + visible * ciCo * flatLobe) / (W * ciCo);
  return brdfParam3(p, POULIN_FOURNIER_KD) * (NUSSELT_INV_PI * diffuse) +
         brdfParam3(p, POULIN_FOURNIER_KS) * (lobeNorm * specular);
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// POULIN_FOURNIER_DELTA: 0 (evaluated and light-sampled).
// POULIN_FOURNIER_ANALYTIC: 0: the analytic strategy samples the cosine.
#define POULIN_FOURNIER_DELTA 0
#define POULIN_FOURNIER_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
inline ModelTraits poulinFournierTraits(const BrdfParams&) {
  ModelTraits t;
  t.anisotropic = true;
  return t;
}
// The reflection cone of the cylinder axis (x): the line x = -v.x of the disc.
inline void poulinFournierFeatures(const BrdfParams&, const shared::vec3& v, ModelFeatures& out) {
  out.ridges.push_back({0, -double(v.x)});
}
inline void poulinFournierSpec(ModelSpec& m) {
  using namespace spec;
  m.name = "poulin_fournier";
  m.summary = "Poulin-Fournier 1990 parallel cylinders along x with Phong micro-reflection (re-derived)";
  m.params.push_back(colour("kd", POULIN_FOURNIER_KD, 0.3f, 0.0f, 1.0f, "local diffuse albedo"));
  m.params.push_back(colour("ks", POULIN_FOURNIER_KS, 0.6f, 0.0f, 1.0f, "local specular albedo"));
  m.params.push_back(scalar("n", POULIN_FOURNIER_N, 40.0f, 1.0f, 10000.0f, false, "local Phong exponent"));
  m.params.push_back(scalar("d", POULIN_FOURNIER_D, 0.5f, 0.0f, 10.0f, false, "flat gap between cylinders (radius 1)"));
  m.params.push_back(scalar("h", POULIN_FOURNIER_H, 0.0f, -0.5f, 0.0f, false, "height of the cylinder axes above the base"));
  m.typical = {N("kd", 0.3), N("ks", 0.6), N("n", 40), N("d", 0.5), N("h", 0)};
  m.hard = {N("kd", 0), N("ks", 1), N("n", 400), N("d", 0), N("h", 0)};
  m.traits = &poulinFournierTraits;
  m.features = &poulinFournierFeatures;
}
}  // namespace nusselt::models
#endif

#endif
