#version 460
#extension GL_GOOGLE_include_directive : require
// accumulate: add each finished path to its pixel. One invocation owns one pixel (no float
// atomics), so the film is bit-identical run to run. Non-finite samples are dropped and counted.
#include "shared/stage_common.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= g.chunkPixels) return;
  uint pixel = g.chunkFirstPixel + i;
  vec3 L = g.pathRadiance.v[i].xyz;
  if (!(isFinite(L.x) && isFinite(L.y) && isFinite(L.z))) {
    atomicAdd(g.stats.v[STAT_NONFINITE_SAMPLES], 1u);
    L = vec3(0.0f);
  }
  g.film.v[pixel] += vec4(L, 1.0f);
  g.filmSq.v[pixel] += vec4(L * L, 0.0f);
}
