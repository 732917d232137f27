#version 460
#extension GL_GOOGLE_include_directive : require
// vegas: the two kernels of VEGAS on the primary sample space (docs/vegas.md,
// src/render/vegas_integrator.cpp), one per pipeline (constant 13, VEGAS_KERNEL_*), around the
// path tracer's stages: warp writes each path slot's primary draws before the path tracer traces
// them, weigh multiplies the traced radiance by 1 / p(x) before the path tracer's accumulate stage
// adds it to the film. One invocation per path slot of the chunk; slot i is sample
// g.sampleIndex + (chunkFirst + i) % passSamples of pixel (chunkFirst + i) / passSamples, as in
// the path tracer (camera.comp).
#include "shared/stage_common.glsl"
#include "shared/vegas.h"

layout(constant_id = 13) const uint VEGAS_KERNEL = 0u;


void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= g.chunkPaths) return;
  GpuVegas V = g.vegas.v[0];
  uint axes = V.info.x;
  uint bins = V.info.y;
  uint dims = V.info.z;
  uint bounces = V.info.w;
  Vec2s primary = g.primarySamples;
  Floats cdf = V.cdf;

  if (VEGAS_KERNEL == VEGAS_KERNEL_WARP) {
    uint global = g.chunkFirst + i;
    uint pixel = global / g.passSamples;
    uint sampleIndex = g.sampleIndex + global % g.passSamples;
    for (uint d = 0u; d < dims; ++d) {
      // The path tracer's own number of this draw (pathSample2 without primary samples).
      vec2 u = sample2(g.rngMode, pixel, sampleIndex, d, g.seed);
      // A warped draw's numbers: from the source the pass's table allows (vegasNumbers).
      bool warped = vegasAxisOf(d, 0u, bounces) != 0xffffffffu || vegasAxisOf(d, 1u, bounces) != 0xffffffffu;
      if (warped && V.epoch.y != VEGAS_NUMBERS_RENDER) u = vegasNumbers(V.epoch.y, g.rngMode, pixel, sampleIndex, d, g.seed);
      for (uint c = 0u; c < 2u; ++c) {
        uint a = vegasAxisOf(d, c, bounces);
        if (a == 0xffffffffu) continue;
        float pdf;
        uint bin;
        u[c] = vegasWarp(cdf, a * (bins + 1u), bins, u[c], pdf, bin);
      }
      primary.v[primarySampleIndex(i, d, dims)] = u;
    }
  } else if (VEGAS_KERNEL == VEGAS_KERNEL_WEIGH) {
    // 1 / p(x), p the product of the axes' densities at the draws the path read.
    float weight = 1.0f;
    for (uint a = 0u; a < axes; ++a) {
      float x = primary.v[primarySampleIndex(i, vegasAxisDimension(a), dims)][vegasAxisComponent(a)];
      weight /= vegasDensity(cdf, a * (bins + 1u), bins, vegasBin(x, bins));
    }
    vec4 R = g.pathRadiance.v[i];
    vec3 L = R.xyz * weight;
    g.pathRadiance.v[i] = vec4(L, R.w);
    // Non-finite radiance: the accumulate stage drops and counts it; it teaches nothing here.
    if (!(isFinite(L.x) && isFinite(L.y) && isFinite(L.z))) return;
    float F = max(luminance(L), 0.0f);
    if (!(F > 0.0f) || V.epoch.z == 0u) return;  // nothing to learn, or the table is frozen
    Uints sums = V.sums;
    for (uint a = 0u; a < axes; ++a) {
      float x = primary.v[primarySampleIndex(i, vegasAxisDimension(a), dims)][vegasAxisComponent(a)];
      atomicAddFixed64(sums, (a * bins + vegasBin(x, bins)) * 2u, min(F * F, VEGAS_SUM_CLAMP), VEGAS_FIXED_SCALE);
    }
  }
}
