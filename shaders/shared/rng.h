// rng.h: stateless random numbers, identical on the CPU and the GPU.
//
// A uniform number is a hash of (pixel, sample index, dimension, seed): no state is stored per
// path, a sample can be recomputed anywhere (resume, --spp-offset, splitting a frame across
// machines), and a quasi-Monte Carlo sequence or primary-sample-space mutations (Metropolis) can
// replace it later by changing this one function. Dimensions are assigned per bounce
// (rngDimension), so each decision of the random walk draws from its own dimension.
#ifndef NUSSELT_RNG_H
#define NUSSELT_RNG_H
#include "prelude.h"
SHARED_BEGIN

// Camera jitter uses dimensions 0 and 1; each bounce then owns RNG_DIMS_PER_BOUNCE dimensions.
#define RNG_DIMS_PER_BOUNCE 16u
#define RNG_DIM_LIGHT_SELECT 0u
#define RNG_DIM_LIGHT_POINT 1u   // and 2
#define RNG_DIM_BSDF 3u          // and 4
#define RNG_DIM_ROULETTE 5u
#define RNG_DIM_COMPONENT 6u
// Rejection loops (the quadtree sampler) draw from their own stream: dimension | this bit.
#define RNG_REJECTION_STREAM 0x80000000u

SHARED_FN uint rngDimension(uint bounce, uint slot) { return 2u + bounce * RNG_DIMS_PER_BOUNCE + slot; }

// pcg4d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020).
SHARED_FN uvec4 pcg4d(uvec4 v) {
  v = v * 1664525u + uvec4(1013904223u);
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v = v ^ (v >> uvec4(16u));
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

// Two uniform numbers in [0, 1) (24 bits each: never 1.0).
SHARED_FN vec2 rng2(uint pixel, uint sampleIndex, uint dimension, uint seed) {
  uvec4 h = pcg4d(uvec4(pixel, sampleIndex, dimension, seed));
  return vec2(float(h.x >> 8u), float(h.y >> 8u)) * (1.0f / 16777216.0f);
}

SHARED_FN float rng1(uint pixel, uint sampleIndex, uint dimension, uint seed) {
  return rng2(pixel, sampleIndex, dimension, seed).x;
}

SHARED_END
#endif
