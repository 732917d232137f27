// alpha.h: the alpha test of glTF alphaMode (docs/scenes.md, "Alpha"), one rule for the GPU
// traversal (alphaPasses in stage_common.glsl) and its C++ twin (AlphaTester, texture_table.h,
// for bvhClosestHit). OPAQUE: every hit counts. MASK: a hit counts when alpha >= alphaCutoff.
// BLEND: stochastic transparency, a hit counts with probability alpha, decided by a hash of the
// triangle (its index in the GPU's triangle order) and the ray's origin and direction bits, so a
// render is a function of its seed.
#ifndef NUSSELT_ALPHA_H
#define NUSSELT_ALPHA_H
#include "texture_layout.h"
SHARED_BEGIN

// One step of a PCG-style integer hash (O'Neill's RXS-M-XS output on an LCG step), mixing in v.
SHARED_FN uint alphaHashStep(uint h, uint v) {
  h = (h ^ v) * 747796405u + 2891336453u;
  h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
  return (h >> 22u) ^ h;
}

// Whether a candidate hit of triangle tri with opacity alpha counts for the ray (origin, dir);
// mode: ALPHA_OPAQUE, ALPHA_MASK or ALPHA_BLEND.
SHARED_FN bool alphaTest(uint mode, float alpha, float cutoff, uint tri, vec3 origin, vec3 dir) {
  if (mode == ALPHA_MASK) return alpha >= cutoff;
  if (mode != ALPHA_BLEND) return true;
  uint h = alphaHashStep(tri * 0x9e3779b9u, floatBitsToUint(origin.x));
  h = alphaHashStep(h, floatBitsToUint(origin.y));
  h = alphaHashStep(h, floatBitsToUint(origin.z));
  h = alphaHashStep(h, floatBitsToUint(dir.x));
  h = alphaHashStep(h, floatBitsToUint(dir.y));
  h = alphaHashStep(h, floatBitsToUint(dir.z));
  return float(h >> 8u) * (1.0f / 16777216.0f) < alpha;
}

SHARED_END
#endif
