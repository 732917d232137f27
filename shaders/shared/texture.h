// texture.h: texture lookup, one source for the shade stages and the C++ tests (docs/scenes.md,
// "Textures"). Wrap modes REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT per axis; filters NEAREST and
// LINEAR (bilinear between the four nearest texel centres, in linear values: sRGB is decoded
// per texel before filtering, as GPUs do with sRGB formats); no mipmaps.
//   textureLookup(texels, t, uv): the filtered texel value (rgba, linear) at texture coordinate
//     uv of the texture's set, after its KHR_texture_transform. Non-finite coordinates read as 0.
// The texel buffer is a `Uints` buffer reference in GLSL and a `const std::uint32_t*` in C++.
#ifndef NUSSELT_TEXTURE_H
#define NUSSELT_TEXTURE_H
#include "layout.h"
SHARED_BEGIN

#ifdef __cplusplus
#define TEXEL_BUFFER const std::uint32_t*
#define TEXEL_AT(buffer, i) ((buffer)[i])
#else
#define TEXEL_BUFFER Uints
#define TEXEL_AT(buffer, i) ((buffer).v[i])
#endif

// The sRGB electro-optical transfer function (IEC 61966-2-1): code value in [0, 1] -> linear.
SHARED_FN float srgbToLinear(float c) {
  return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

// One texel (x in [0, width), y in [0, height), y = 0 the top row), decoded to [0, 1].
SHARED_FN vec4 textureTexel(TEXEL_BUFFER texels, GpuTexture t, uint x, uint y) {
  uint p = TEXEL_AT(texels, t.info.x + y * t.info.y + x);
  vec4 c = vec4(float(p & 255u), float((p >> 8u) & 255u), float((p >> 16u) & 255u), float(p >> 24u)) * (1.0f / 255.0f);
  if ((t.info.w & TEXTURE_FLAG_SRGB) != 0u) c = vec4(srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z), c.w);
  return c;
}

// A coordinate reduced to one period of its wrap mode (the same texels, small numbers): REPEAT to
// [0, 1], MIRRORED_REPEAT to [0, 2], CLAMP_TO_EDGE to [-1, 2]. Texel indices computed from it then
// lie in [-1, 2n], and no float-to-int conversion overflows.
SHARED_FN float textureReduce(float u, uint wrap) {
  if (!isFinite(u)) return 0.0f;
  if (wrap == TEXTURE_WRAP_CLAMP) return clamp(u, -1.0f, 2.0f);
  if (wrap == TEXTURE_WRAP_MIRROR) return u - 2.0f * floor(0.5f * u);
  return u - floor(u);
}

// Texel index i in [-1, 2n] of an axis of n texels -> [0, n) by the wrap mode.
SHARED_FN uint textureWrap(int i, uint n, uint wrap) {
  if (wrap == TEXTURE_WRAP_CLAMP) return uint(clamp(i, 0, int(n) - 1));
  if (wrap == TEXTURE_WRAP_MIRROR) {
    uint k = uint(i + 2 * int(n)) % (2u * n);  // period 2n: texels 0..n-1 then n-1..0
    return k < n ? k : 2u * n - 1u - k;
  }
  return uint(i + int(n)) % n;
}

// KHR_texture_transform: transform * (u, v, 1).
SHARED_FN vec2 textureTransform(GpuTexture t, vec2 uv) {
  return vec2(t.transform0.x * uv.x + t.transform0.z * uv.y + t.transform1.x,
              t.transform0.y * uv.x + t.transform0.w * uv.y + t.transform1.y);
}

SHARED_FN vec4 textureLookup(TEXEL_BUFFER texels, GpuTexture t, vec2 uvSet) {
  uint w = t.info.y;
  uint h = t.info.z;
  uint wrapS = t.info.w & 3u;
  uint wrapT = (t.info.w >> 2u) & 3u;
  vec2 uv = textureTransform(t, uvSet);
  float x = textureReduce(uv.x, wrapS) * float(w);
  float y = textureReduce(uv.y, wrapT) * float(h);
  if ((t.info.w & TEXTURE_FLAG_LINEAR) == 0u)
    return textureTexel(texels, t, textureWrap(int(floor(x)), w, wrapS), textureWrap(int(floor(y)), h, wrapT));
  // Bilinear: texel centres sit at half-integers.
  float fx = x - 0.5f;
  float fy = y - 0.5f;
  float x0f = floor(fx);
  float y0f = floor(fy);
  float ax = fx - x0f;
  float ay = fy - y0f;
  int x0 = int(x0f);
  int y0 = int(y0f);
  uint xa = textureWrap(x0, w, wrapS);
  uint xb = textureWrap(x0 + 1, w, wrapS);
  uint ya = textureWrap(y0, h, wrapT);
  uint yb = textureWrap(y0 + 1, h, wrapT);
  vec4 top = mix(textureTexel(texels, t, xa, ya), textureTexel(texels, t, xb, ya), ax);
  vec4 bottom = mix(textureTexel(texels, t, xa, yb), textureTexel(texels, t, xb, yb), ax);
  return mix(top, bottom, ay);
}

// The coordinate of set `set` (0 or 1) at barycentrics (b1, b2) of a triangle's corners.
SHARED_FN vec2 triangleTexcoord(GpuTriTexcoords c, uint set, float b1, float b2) {
  float b0 = 1.0f - b1 - b2;
  if (set == 0u)
    return vec2(b0 * c.a.x + b1 * c.a.z + b2 * c.b.x, b0 * c.a.y + b1 * c.a.w + b2 * c.b.y);
  return vec2(b0 * c.b.z + b1 * c.c.x + b2 * c.c.z, b0 * c.b.w + b1 * c.c.y + b2 * c.c.w);
}

// A texture of a triangle at barycentrics (b1, b2): its set's coordinate, then the lookup.
SHARED_FN vec4 textureAtHit(TEXEL_BUFFER texels, GpuTexture t, GpuTriTexcoords c, float b1, float b2) {
  uint set = (t.info.w & TEXTURE_FLAG_SET1) != 0u ? 1u : 0u;
  return textureLookup(texels, t, triangleTexcoord(c, set, b1, b2));
}

// The surface directions of a texture's axes under its transform (KHR_texture_transform), for
// the normal map's tangent frame. A map's x axis lies along increasing u of the coordinates it is
// read with, its y axis along s times increasing v (s = +1 or -1: the frame's handedness against
// the coordinates). In: (t, b) the unit directions of those axes for the untransformed coordinates
// (t along dS/du, b along s dS/dv) and lu = |dS/du|, lv = |dS/dv| on the triangle. Out: in (t, b)
// the (unnormalised) directions dS/du' and s dS/dv' of the transformed coordinates, from
// (u, v) = A^-1 ((u', v') - offset). The identity leaves lu t and lv b; a singular transform
// (no defined axes) leaves (t, b) unchanged.
SHARED_FN void textureTransformFrame(GpuTexture tex, float lu, float lv, float s, INOUT(vec3) t, INOUT(vec3) b) {
  float a = tex.transform0.x;  // u' = a u + c v + ...
  float bb = tex.transform0.y; // v' = bb u + d v + ...
  float c = tex.transform0.z;
  float d = tex.transform0.w;
  float det = a * d - bb * c;
  if (!(abs(det) > 1e-20f) || !isFinite(det)) return;
  vec3 su = lu * t;      // dS/du
  vec3 sv = lv * s * b;  // dS/dv
  t = (d * su - bb * sv) / det;      // dS/du' = (A^-1)_00 dS/du + (A^-1)_10 dS/dv
  b = s * (a * sv - c * su) / det;   // s dS/dv' = s ((A^-1)_01 dS/du + (A^-1)_11 dS/dv)
}

SHARED_END
#endif
