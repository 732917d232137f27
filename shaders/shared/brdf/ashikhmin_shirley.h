// ashikhmin_shirley: anisotropic Phong of Ashikhmin & Shirley 2000 (docs/brdf-models.md 2.8):
//   e(h) = (nu h.x^2 + nv h.y^2) / (1 - ch^2)
//   spec = sqrt((nu+1)(nv+1)) / (8 pi) ch^e(h) / (cb max(ci, co)) Fschlick(cb; rs)
//   diff = 28 rd / (23 pi) (1 - rs) (1 - (1 - ci/2)^5) (1 - (1 - co/2)^5)
//   rd, rs: colour in [0, 1]; nu, nv >= 1.
#ifndef NUSSELT_BRDF_ASHIKHMIN_SHIRLEY_H
#define NUSSELT_BRDF_ASHIKHMIN_SHIRLEY_H
#include "common.h"
SHARED_BEGIN

#define ASHIKHMIN_SHIRLEY_RD 0u
#define ASHIKHMIN_SHIRLEY_RS 3u
#define ASHIKHMIN_SHIRLEY_NU 6u
#define ASHIKHMIN_SHIRLEY_NV 7u

SHARED_FN float ashikhminShirleyPow5(float x) {
  float x2 = x * x;
  return x2 * x2 * x;
}

SHARED_FN vec3 ashikhminShirleyEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  vec3 rd = brdfParam3(p, ASHIKHMIN_SHIRLEY_RD);
  vec3 rs = brdfParam3(p, ASHIKHMIN_SHIRLEY_RS);
  float nu = brdfParam(p, ASHIKHMIN_SHIRLEY_NU);
  float nv = brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
  vec3 h = brdfHalf(wi, wo);
  float cb = max(brdfHalfCos(wi, wo), 1e-7f);
  // ch^e = exp(e log ch), e log ch = (nu hx^2 + nv hy^2) * 0.5 log(1 - s2) / s2 (finite at h = n).
  float s2 = brdfSin2(h);
  float lobe = exp((nu * h.x * h.x + nv * h.y * h.y) * 0.5f * brdfLog1mOverX(s2));
  float spec = sqrt((nu + 1.0f) * (nv + 1.0f)) * (0.125f * NUSSELT_INV_PI) * lobe / (cb * max(wi.z, wo.z));
  float diff = (28.0f / (23.0f * NUSSELT_PI)) * (1.0f - ashikhminShirleyPow5(1.0f - 0.5f * wi.z)) *
               (1.0f - ashikhminShirleyPow5(1.0f - 0.5f * wo.z));
  return spec * fresnelSchlick3(cb, rs) + diff * rd * (vec3(1.0f) - rs);
}

SHARED_END
#endif
