#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
// display: the preview's tone mapping (`nusselt preview`, src/render/preview.cpp). For each pixel
// of the film: mean = sum / samples, times 2^exposure, tone map, sRGB OETF, 8 bits per channel,
// packed into g.display (one uint per pixel, row-major, top row first), which the preview then
// copies into the swapchain image. Runs with the renderer's pipeline layout and descriptor set
// after a pass has finished; it only reads the film.
//
// Push constants: DisplayConstants (layout.h): the exposure scale 2^stops and the flags
// DISPLAY_BGRA, DISPLAY_REINHARD.
// The default (clamp + exact sRGB OETF, rounded to nearest) is what `nusselt render --png` and
// writePng do, so a preview screenshot and a headless PNG of the same film agree to within one
// code value (float pow here, double pow there).
#include "shared/layout.h"

STAGE_PUSH(DisplayConstants);

layout(local_size_x = 8, local_size_y = 8) in;

uint toSrgb8(float linear) {
  if (!(linear > 0.0f)) return 0u;  // also NaN
  if (linear >= 1.0f) return 255u;
  float encoded = linear <= 0.0031308f ? 12.92f * linear : 1.055f * pow(linear, 1.0f / 2.4f) - 0.055f;
  return uint(clamp(encoded * 255.0f + 0.5f, 0.0f, 255.0f));
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  uint width = g.width;
  uint height = g.height;
  if (p.x >= width || p.y >= height) return;
  uint pixel = p.y * width + p.x;
  vec4 sum = g.film.v[pixel];
  vec3 c = sum.w > 0.0f ? sum.xyz / sum.w : vec3(0.0f);
  c *= pc.exposureScale;
  uint flags = pc.flags;
  if ((flags & DISPLAY_REINHARD) != 0u) c = c / (vec3(1.0f) + max(c, vec3(0.0f)));
  uint r = toSrgb8(c.x);
  uint gg = toSrgb8(c.y);
  uint b = toSrgb8(c.z);
  if ((flags & DISPLAY_BGRA) != 0u) {
    uint t = r;
    r = b;
    b = t;
  }
  g.display.v[pixel] = r | (gg << 8) | (b << 16) | (255u << 24);
}
