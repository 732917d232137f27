// prelude.h: the bridge that lets one source file compile as GLSL 4.60 and as C++17 (GLM).
//
// Every header under shaders/shared/ includes this first. Rules for shared code
// (see README "Writing shared code"):
//   - write float literals with an f suffix (0.5f): a bare 0.5 is a double in C++;
//   - no swizzles (v.xy), no recursion, no GLSL built-in block variables;
//   - out/inout parameters through OUT(T) / INOUT(T);
//   - functions are declared SHARED_FN (inline in C++, nothing in GLSL);
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
#define STATIC_ASSERT_SIZE(T, n)
bool isFinite(float x) { return !isnan(x) && !isinf(x); }
#endif

SHARED_BEGIN

#define NUSSELT_PI 3.14159265358979323846f
#define NUSSELT_INV_PI 0.31830988618379067154f
#define NUSSELT_TWO_PI 6.28318530717958647692f
// The largest float below 1: uniform numbers live in [0, 1) (STYLE.md: never return 1.0).
#define NUSSELT_ONE_MINUS_EPS 0.99999994f

// Rec. 709 / sRGB-primaries luminance: the scalar used for sampling and Russian roulette.
SHARED_FN float luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

SHARED_FN float sqr(float x) { return x * x; }

SHARED_FN float safeSqrt(float x) { return sqrt(max(x, 0.0f)); }

// cos from sin without cancellation near 1: sqrt((1 - s)(1 + s)).
SHARED_FN float cosFromSin(float s) { return safeSqrt((1.0f - s) * (1.0f + s)); }

SHARED_FN float maxComponent(vec3 v) { return max(v.x, max(v.y, v.z)); }

SHARED_END

#endif
