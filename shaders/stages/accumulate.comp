#version 460
#extension GL_GOOGLE_include_directive : require
// accumulate: add each finished path to its pixel. The invocation of a pixel's first path in this
// chunk adds all of the pixel's paths of the chunk, in sample order: no float atomics, and the
// film is bit-identical run to run and whatever the number of samples per pass (the same sums
// in the same order). Non-finite samples are dropped and counted.
#include "shared/stage_common.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= g.chunkPaths) return;
  uint pixel = (g.chunkFirst + i) / g.passSamples;
  if (i > 0u && (g.chunkFirst + i - 1u) / g.passSamples == pixel) return;  // not the pixel's first path here
  vec4 sum = g.film.v[pixel];
  vec4 sumSq = g.filmSq.v[pixel];
  for (uint j = i; j < g.chunkPaths && (g.chunkFirst + j) / g.passSamples == pixel; ++j) {
    vec3 L = loadVec4(g.pathRadiance, j).xyz;
    if (!(isFinite(L.x) && isFinite(L.y) && isFinite(L.z))) {
      atomicAdd(g.stats.v[STAT_NONFINITE_SAMPLES], 1u);
      L = vec3(0.0f);
    }
    sum += vec4(L, 1.0f);
    sumSq += vec4(L * L, 0.0f);
  }
  g.film.v[pixel] = sum;
  g.filmSq.v[pixel] = sumSq;
}
