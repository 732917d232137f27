// lambert: ideal diffuse reflection (Lambert 1760; the random-walk source's diffuse BRDF).
//   f = rho / pi            rho: colour in [0, 1]
// Measure: BRDF value [1/sr], zero unless wi.z > 0 and wo.z > 0.
#ifndef NUSSELT_BRDF_LAMBERT_H
#define NUSSELT_BRDF_LAMBERT_H
#include "../layout.h"
SHARED_BEGIN

#define LAMBERT_RHO 0u

SHARED_FN vec3 lambertEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  return brdfParam3(p, LAMBERT_RHO) * NUSSELT_INV_PI;
}

SHARED_END
#endif
