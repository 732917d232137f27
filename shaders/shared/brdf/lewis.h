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

SHARED_END
#endif
