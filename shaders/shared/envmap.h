// envmap.h: the environment light: an equirectangular (lat-long) radiance map around the scene,
// its bilinear lookup, and its importance sampling in proportion to luminance x solid angle with
// an exact density (for MIS). Shared by the CPU (tests, builder) and the GPU (escape stage, light
// sampling in stage_common.glsl). Map data: GpuEnvironment (layout.h); builder:
// src/render/environment.cpp; documentation: docs/environment.md.
//
// Convention (issue 17): +Y is up; a direction d of the map's frame has
//   u = 0.5 + atan2(d.x, -d.z) / (2 pi),   v = acos(d.y) / pi,
// with v = 0 the top row of the image. The centre of the map (u = 0.5, v = 0.5) lies along -Z,
// the view direction of a default glTF camera, and +X appears to its right (u > 0.5).
// World and map frames differ by the rotation about +Y by the angle a (--env-rotate, counter-
// clockwise seen from above): d_world = R(a) d_map.
//
// Texel (x, y) covers u in [x/w, (x+1)/w), v in [y/h, (y+1)/h); its value sits at the centre.
// Lookup is bilinear between texel centres, wrapping in u and clamped in v. The sampling
// weight of a texel is the luminance of that bilinear function integrated over the texel (the
// separable kernel 1/8, 3/4, 1/8 of the texel and its neighbours) times sin(theta) at the
// texel's centre: positive wherever the lookup is, so light sampling alone is unbiased.
// Solid-angle density of a direction with map coordinates (u, v):
//   pdf(d) = p_uv(u, v) / (2 pi^2 sin theta),  theta = v pi.
#ifndef NUSSELT_ENVMAP_H
#define NUSSELT_ENVMAP_H
#include "distribution2d.h"
#include "layout.h"

#ifdef __cplusplus
SHARED_BEGIN
// The host view of an environment: the GPU struct plus host pointers to its arrays.
struct EnvHostView {
  GpuEnvironment e;
  const vec4* texels = nullptr;
  const float* distribution = nullptr;
};
typedef EnvHostView EnvView;
SHARED_END
#define ENV_INFO(E) (E.e.info)
#define ENV_ROTATION(E) (E.e.rotation)
#define ENV_TEXEL(E, i) (E.texels[i])
#define ENV_DIST(E) (E.distribution)
#else
#define EnvView GpuEnvironment
#define ENV_INFO(E) (E.info)
#define ENV_ROTATION(E) (E.rotation)
#define ENV_TEXEL(E, i) loadVec4(E.texels, i)  // 64-bit loads (layout.h)
#define ENV_DIST(E) (E.distribution)
#endif

SHARED_BEGIN

// ---- The convention ------------------------------------------------------------------------------

// Map coordinates of a unit direction of the map's frame (u in [0, 1], v in [0, 1]).
SHARED_FN vec2 envDirectionToUv(vec3 d) {
  float u = 0.5f + portableAtan2(d.x, -d.z) * (1.0f / NUSSELT_TWO_PI);
  float v = portableAcos(d.y) * NUSSELT_INV_PI;
  return vec2(u, v);
}

// The unit direction (map frame) at map coordinates uv; sinTheta = sin(v pi) >= 0.
SHARED_FN vec3 envUvToDirection(vec2 uv, OUT(float) sinTheta) {
  float theta = uv.y * NUSSELT_PI;
  float phi = (uv.x - 0.5f) * NUSSELT_TWO_PI;
  sinTheta = sin(theta);
  return vec3(sinTheta * sin(phi), cos(theta), -sinTheta * cos(phi));
}

// World <-> map frame: rotation about +Y by the angle a with (cos a, sin a) = rotation.xy.
SHARED_FN vec3 envWorldToMap(vec4 rotation, vec3 d) {
  float c = rotation.x;
  float s = rotation.y;
  return vec3(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}
SHARED_FN vec3 envMapToWorld(vec4 rotation, vec3 d) {
  float c = rotation.x;
  float s = rotation.y;
  return vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

// ---- Lookup -------------------------------------------------------------------------------------

// Bilinear radiance at map coordinates uv (between texel centres; u wraps, v clamps).
SHARED_FN vec3 envLookupUv(EnvView E, vec2 uv) {
  uint w = ENV_INFO(E).x;
  uint h = ENV_INFO(E).y;
  float fx = uv.x * float(w) - 0.5f;
  float fy = uv.y * float(h) - 0.5f;
  float x0f = floor(fx);
  float y0f = floor(fy);
  float tx = fx - x0f;
  float ty = fy - y0f;
  int x0 = int(x0f);
  int y0 = int(y0f);
  int iw = int(w);
  int ih = int(h);
  // uv.x in [0, 1] gives x0 in [-1, w - 1] (GLSL's % is undefined for negative operands).
  if (x0 < 0) x0 += iw;
  if (x0 >= iw) x0 -= iw;
  int x1 = x0 + 1 < iw ? x0 + 1 : 0;
  int y1 = clamp(y0 + 1, 0, ih - 1);
  y0 = clamp(y0, 0, ih - 1);
  vec3 a = vec3(ENV_TEXEL(E, uint(y0 * iw + x0)));
  vec3 b = vec3(ENV_TEXEL(E, uint(y0 * iw + x1)));
  vec3 c = vec3(ENV_TEXEL(E, uint(y1 * iw + x0)));
  vec3 e = vec3(ENV_TEXEL(E, uint(y1 * iw + x1)));
  return (a * (1.0f - tx) + b * tx) * (1.0f - ty) + (c * (1.0f - tx) + e * tx) * ty;
}

// Radiance arriving from the world direction d (unit), i.e. seen looking along d.
SHARED_FN vec3 envRadiance(EnvView E, vec3 d) {
  return envLookupUv(E, envDirectionToUv(envWorldToMap(ENV_ROTATION(E), d)));
}

// ---- Sampling -------------------------------------------------------------------------------------

// Solid-angle density with which envSample draws the world direction d (unit); 0 at the poles.
SHARED_FN float envPdf(EnvView E, vec3 d) {
  vec3 m = envWorldToMap(ENV_ROTATION(E), d);
  float sinTheta = safeSqrt(1.0f - m.y * m.y);
  if (!(sinTheta > 0.0f)) return 0.0f;
  vec2 uv = envDirectionToUv(m);
  uv.x = min(uv.x, NUSSELT_ONE_MINUS_EPS);  // u = 1 (atan2 = pi) is the seam's left side, u = 0
  uv.y = min(uv.y, NUSSELT_ONE_MINUS_EPS);
  float p = dist2dPdf(ENV_DIST(E), ENV_INFO(E).x, ENV_INFO(E).y, uv);
  return p / (2.0f * NUSSELT_PI * NUSSELT_PI * sinTheta);
}

// A world direction d from u in [0,1)^2 with its solid-angle density pdf (0: no sample; the map
// has no mass, or the sample fell on a pole).
SHARED_FN vec3 envSample(EnvView E, vec2 u, OUT(float) pdf) {
  float pUv;
  uvec2 cell;
  vec2 uv = dist2dSample(ENV_DIST(E), ENV_INFO(E).x, ENV_INFO(E).y, u, pUv, cell);
  float sinTheta;
  vec3 m = envUvToDirection(uv, sinTheta);
  pdf = (pUv > 0.0f && sinTheta > 0.0f) ? pUv / (2.0f * NUSSELT_PI * NUSSELT_PI * sinTheta) : 0.0f;
  return envMapToWorld(ENV_ROTATION(E), m);
}

SHARED_END
#endif
