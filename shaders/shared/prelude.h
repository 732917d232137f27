// prelude.h: the bridge that lets one source file compile as GLSL 4.60 and as C++17 (GLM).
//
// Every header under shaders/shared/ includes this first. Rules for shared code
// (see README "Writing shared code"):
//   - write float literals with an f suffix (0.5f): a bare 0.5 is a double in C++;
//   - no swizzles (v.xy), no recursion, no GLSL built-in block variables;
//   - out/inout parameters through OUT(T) / INOUT(T);
//   - functions are declared SHARED_FN (inline in C++, nothing in GLSL), constants SHARED_CONST;
//   - structs hold only vec4 / uvec4 / float / uint members, so that std430, scalar and
//     C++ layouts coincide; every struct has a static_assert on its size in C++.
#ifndef NUSSELT_PRELUDE_H
#define NUSSELT_PRELUDE_H

#ifdef __cplusplus
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/packing.hpp>  // unpackHalf2x16 (exact, as GLSL's)
namespace nusselt {
namespace shared {
using namespace glm;
using uint = std::uint32_t;
}  // namespace shared
}  // namespace nusselt
#define SHARED_BEGIN namespace nusselt { namespace shared {
#define SHARED_END } }
#define SHARED_FN inline
#define OUT(T) T&
#define INOUT(T) T&
#define CONST_ARRAY(T) static constexpr T
#define SHARED_CONST inline constexpr
#define STATIC_ASSERT_SIZE(T, n) static_assert(sizeof(T) == (n), #T " layout changed")
// GLSL built-ins that GLM lacks or names differently.
SHARED_BEGIN
SHARED_FN float uintBitsToFloat(uint u) { float f; std::memcpy(&f, &u, 4); return f; }
SHARED_FN uint floatBitsToUint(float f) { uint u; std::memcpy(&u, &f, 4); return u; }
SHARED_FN float inversesqrt(float x) { return 1.0f / std::sqrt(x); }
SHARED_FN bool isFinite(float x) { return std::isfinite(x); }
SHARED_END
#else
#define SHARED_BEGIN
#define SHARED_END
#define SHARED_FN
#define OUT(T) out T
#define INOUT(T) inout T
#define CONST_ARRAY(T) const T
#define SHARED_CONST const
#define STATIC_ASSERT_SIZE(T, n)
bool isFinite(float x) { return !isnan(x) && !isinf(x); }
#endif

SHARED_BEGIN

#define NUSSELT_PI 3.14159265358979323846f
#define NUSSELT_INV_PI 0.31830988618379067154f
#define NUSSELT_TWO_PI 6.28318530717958647692f
// The largest float below 1: uniform numbers live in [0, 1) (STYLE.md: never return 1.0).
#define NUSSELT_ONE_MINUS_EPS 0.99999994f

// Token pasting after expansion of both operands (the model list, brdf/models.h).
#define NUSSELT_CAT2(a, b) a##b
#define NUSSELT_CAT(a, b) NUSSELT_CAT2(a, b)

// Rec. 709 / sRGB-primaries luminance: the scalar used for sampling and Russian roulette.
SHARED_FN float luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

SHARED_FN float sqr(float x) { return x * x; }

SHARED_FN float safeSqrt(float x) { return sqrt(max(x, 0.0f)); }

// cos from sin without cancellation near 1: sqrt((1 - s)(1 + s)).
SHARED_FN float cosFromSin(float s) { return safeSqrt((1.0f - s) * (1.0f + s)); }

SHARED_FN float maxComponent(vec3 v) { return max(v.x, max(v.y, v.z)); }

// ---- A logarithm that is the same on CPU and GPU ------------------------------------------------
// Vulkan allows log/log2 an ABSOLUTE error of 2^-21 for arguments in [0.5, 2] (lavapipe's is of
// that order), so log of a lobe's cosine near 1, multiplied by an exponent of 5000, would differ
// by 0.1 % between the two builds. Here: x = m 2^e (frexp, exact), m in [0.707, 1.414), and
// log(m) = 2 atanh(z), z = (m - 1)/(m + 1), |z| <= 0.172, by its series (7 terms: truncation
// below 1e-12); ln 2 split in two for accuracy. Returns -3.4e38 (not -inf: no 0 * inf NaN in
// exp(n log x) with n = 0) for x <= 0.
SHARED_FN float portableLog(float x) {
  if (!(x > 0.0f)) return -3.4e38f;
  int e = 0;
  float m = frexp(x, e);
  if (m < 0.70710678f) {
    m *= 2.0f;
    e -= 1;
  }
  float z = (m - 1.0f) / (m + 1.0f);
  float z2 = z * z;
  float s = 2.0f * z * (1.0f + z2 * (1.0f / 3.0f + z2 * (1.0f / 5.0f + z2 * (1.0f / 7.0f + z2 * (1.0f / 9.0f +
            z2 * (1.0f / 11.0f + z2 * (1.0f / 13.0f)))))));
  float fe = float(e);
  return (fe * 0.693145751953125f + s) + fe * 1.428606765330187e-06f;
}

// ---- Inverse trigonometry that is the same on CPU and GPU -----------------------------------------
// Vulkan lets asin, acos and atan be thousands of ulps off (their precision is inherited from an
// approximated atan), and lavapipe's are ~1e-4 relative near +-1: a model written with the
// built-ins would evaluate differently on the two sides. Shared code uses these instead: the same
// float operations on both sides (Cephes' atanf polynomial, ~2e-7 relative), with asin and acos
// through atan2 and sqrt((1 - x)(1 + x)), accurate near +-1.
SHARED_FN float portableAtanUnit(float x) {  // x >= 0
  float y = 0.0f;
  float t = x;
  if (x > 2.414213562373095f) {  // tan(3 pi / 8)
    y = 1.5707963267948966f;
    t = -1.0f / x;
  } else if (x > 0.4142135623730950f) {  // tan(pi / 8)
    y = 0.7853981633974483f;
    t = (x - 1.0f) / (x + 1.0f);
  }
  float z = t * t;
  return y + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * t + t);
}

SHARED_FN float portableAtan(float x) { return x < 0.0f ? -portableAtanUnit(-x) : portableAtanUnit(x); }

// atan2(y, x) in (-pi, pi]; 0 for (0, 0).
SHARED_FN float portableAtan2(float y, float x) {
  float ax = abs(x);
  float ay = abs(y);
  float a = 0.0f;
  if (ax == 0.0f && ay == 0.0f) return 0.0f;
  if (ay <= ax) a = portableAtanUnit(ay / ax);
  else a = 1.5707963267948966f - portableAtanUnit(ax / ay);
  if (x < 0.0f) a = 3.14159265358979323846f - a;
  return y < 0.0f ? -a : a;
}

SHARED_FN float portableAsin(float x) {
  x = clamp(x, -1.0f, 1.0f);
  return portableAtan2(x, sqrt((1.0f - x) * (1.0f + x)));
}

SHARED_FN float portableAcos(float x) {
  x = clamp(x, -1.0f, 1.0f);
  return portableAtan2(sqrt((1.0f - x) * (1.0f + x)), x);
}

SHARED_END

#endif
