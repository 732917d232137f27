// warp.h: maps from uniform numbers to directions and points, with their densities.
// The unit disc is nusselt's sampling domain: a uniform point on the disc lifted to the
// hemisphere is cosine distributed (the Nusselt analog), which is the diffuse sampling of the
// random-walk source.
#ifndef NUSSELT_WARP_H
#define NUSSELT_WARP_H
#include "prelude.h"
SHARED_BEGIN

// Uniform point on the unit disc (polar map; density 1/pi per unit area).
SHARED_FN vec2 squareToDiscPolar(vec2 u) {
  float r = sqrt(u.x);
  float phi = NUSSELT_TWO_PI * u.y;
  return vec2(r * cos(phi), r * sin(phi));
}

// Lift a disc point to the upper hemisphere: z = sqrt(1 - r^2), computed as sqrt((1-r)(1+r))
// for accuracy near the rim (grazing directions).
SHARED_FN vec3 discToHemisphere(vec2 d) {
  float r = sqrt(d.x * d.x + d.y * d.y);
  return vec3(d.x, d.y, cosFromSin(min(r, 1.0f)));
}

// Cosine-weighted hemisphere direction (normal +z). pdf (solid angle) = cos(theta) / pi.
SHARED_FN vec3 squareToCosineHemisphere(vec2 u) { return discToHemisphere(squareToDiscPolar(u)); }
SHARED_FN float cosineHemispherePdf(vec3 w) { return w.z > 0.0f ? w.z * NUSSELT_INV_PI : 0.0f; }

// Uniform barycentrics on a triangle: (b1, b2) weights of v1 and v2 (Turk 1990, sqrt warp).
SHARED_FN vec2 squareToTriangle(vec2 u) {
  float s = sqrt(u.x);
  return vec2(s * (1.0f - u.y), s * u.y);
}

// Orthonormal basis around a unit normal n (Duff et al., "Building an Orthonormal Basis,
// Revisited", JCGT 6(1), 2017): t and b with (t, b, n) right-handed.
SHARED_FN void makeFrame(vec3 n, OUT(vec3) t, OUT(vec3) b) {
  float s = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

SHARED_FN vec3 toLocal(vec3 v, vec3 t, vec3 b, vec3 n) { return vec3(dot(v, t), dot(v, b), dot(v, n)); }
SHARED_FN vec3 toWorld(vec3 v, vec3 t, vec3 b, vec3 n) { return t * v.x + b * v.y + n * v.z; }

// Power heuristic with beta = 2 (Veach 1997) for two strategies; a = the one that sampled.
SHARED_FN float powerHeuristic(float a, float b) {
  float a2 = a * a;
  float b2 = b * b;
  return a2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

SHARED_END
#endif
