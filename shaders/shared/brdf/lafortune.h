// lafortune: generalised cosine lobes of Lafortune et al. 1997 (docs/brdf-models.md 2.9):
//   f = rho_d / pi + sum_j max(0, Cx_j wi.x wo.x + Cy_j wi.y wo.y + Cz_j wi.z wo.z)^n_j
//   rho_d: colour in [0, 1]; up to LAFORTUNE_MAX_LOBES lobes (Cx, Cy, Cz, n), grey.
// Layout: rho_d at 0..2, the lobe count at 3, lobe j at 4 + 4 j (Cx, Cy, Cz, n).
#ifndef NUSSELT_BRDF_LAFORTUNE_H
#define NUSSELT_BRDF_LAFORTUNE_H
#include "common.h"
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

SHARED_END
#endif
