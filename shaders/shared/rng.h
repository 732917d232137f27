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
#define RNG_DIM_GUIDE 7u         // and 8: path guiding's choice of the guide, its tree descent
#define RNG_DIM_GUIDE_CELL 9u    // and 10: the point in the guide's chosen cell
// The slots a bounce of an unguided path reads (a 1-D draw reads its slot's x): a draw in another
// slot is never read, which Metropolis uses (mlt.h, mltReadsDraw). A new slot that unguided paths
// read goes here (test PrimaryRender.DrawsOutsideTheReadSlotsAreNotRead replaces the others).
#define RNG_SLOTS_UNGUIDED ((1u << RNG_DIM_LIGHT_SELECT) | (1u << RNG_DIM_LIGHT_POINT) | (1u << RNG_DIM_BSDF) | \
                            (1u << RNG_DIM_ROULETTE) | (1u << RNG_DIM_COMPONENT))
// The quadtree sampler's stream of further numbers (rngStreamKey).
#define RNG_REJECTION_STREAM 0x80000000u

SHARED_FN uint rngDimension(uint bounce, uint slot) { return 2u + bounce * RNG_DIMS_PER_BOUNCE + slot; }

// Whether an unguided path may read draw `dimension`: the camera's draw 0 (draw 1 is not read) and
// the slots RNG_SLOTS_UNGUIDED of each bounce.
SHARED_FN bool rngReadUnguided(uint dimension) {
  return dimension == 0u ||
         (dimension >= 2u && ((RNG_SLOTS_UNGUIDED >> ((dimension - 2u) % RNG_DIMS_PER_BOUNCE)) & 1u) != 0u);
}

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

// ---- Streams of further numbers -----------------------------------------------------------------
// A sampler that consumes a variable count of numbers (the quadtree's rejection trials, the fresh
// numbers of a tree descent that ran out of resolution) draws them from a stream keyed on the
// primary numbers it received (a, b, c: their bits) and a stream id, never on the pixel, sample
// index or seed: a path is then a function of its primary numbers alone, as primary-sample-space
// Metropolis needs (issue 19), whatever sampler (hash, QMC, a Markov chain) produced them. The
// numbers should carry more bits than the sampler consumes deterministically (the quadtree keys on
// both of its numbers, the guide on its descent number and its cell point), so the stream adds
// resolution where the primary numbers run out of it. Draw i of the stream is pcg4d(key + (0, 0,
// 0, i)), a second hash of the key: one hash of keys that differ in one component only is
// correlated with the first (quadtree.h).
SHARED_FN uvec4 rngStreamKey(float a, float b, uint c, uint stream) {
  return pcg4d(uvec4(floatBitsToUint(a), floatBitsToUint(b), c, stream));
}

// ---- Quasi-Monte Carlo: padded, Owen-scrambled Sobol (0,2)-sequences ----------------------------
// Each 2D draw (a dimension of rngDimension) gets its own copy of the first two Sobol
// dimensions, a (0,2)-sequence, with the sample index shuffled and both coordinates Owen
// scrambled by hashes of (pixel, dimension, seed) (Burley, "Practical Hash-based Owen
// Scrambling", JCGT 9(4), 2020; pbrt-v4's PaddedSobolSampler). Every decision of the walk (light
// choice, light point, BSDF direction, roulette, component choice) has its own dimension, so
// each keeps its stratification over the samples of a pixel, as the random-walk source asks.
#define RNG_PCG 0u
#define RNG_QMC 1u

SHARED_FN uint rngReverseBits(uint x) {
  x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
  x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
  x = ((x >> 4u) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4u);
  x = ((x >> 8u) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8u);
  return (x >> 16u) | (x << 16u);
}

// Laine-Karras style hash that only propagates bits upwards: on bit-reversed values it is a
// nested uniform (Owen) scramble.
SHARED_FN uint rngLaineKarras(uint x, uint seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

SHARED_FN uint rngOwenScramble(uint x, uint seed) {
  return rngReverseBits(rngLaineKarras(rngReverseBits(x), seed));
}

// Second Sobol dimension, bit-reversed: generator rows v0 = 2^31, v(k+1) = v(k) ^ (v(k) >> 1), so
// bit 31 - i of v(k) is C(k, i) mod 2, which is 1 iff the bits of i are a subset of those of k
// (Lucas); the point is the xor of v(k) over the set bits k of the index. Bit i of the reversed
// point is thus the parity of the index bits k whose positions contain i: a superset-parity
// transform over the five bits of a position, one shift, mask and xor per position bit (the same
// numbers as a loop over the generator rows, one per set bit: Rng.Sobol1MatchesItsRows).
SHARED_FN uint rngSobol1Reversed(uint index) {
  uint a = index;
  a ^= (a >> 1u) & 0x55555555u;
  a ^= (a >> 2u) & 0x33333333u;
  a ^= (a >> 4u) & 0x0f0f0f0fu;
  a ^= (a >> 8u) & 0x00ff00ffu;
  a ^= (a >> 16u) & 0x0000ffffu;
  return a;
}

// Each 2D draw: the index shuffled by a nested uniform scramble (Owen scrambling in the bit order
// of the index: the first 2^m indices stay one aligned block of 2^m, a (0, m, 2)-net), then the
// first two Sobol dimensions, radical inverse and rngSobol1Reversed, each Owen scrambled. An Owen
// scramble is reverse(LK(reverse(x))), and both dimensions come bit-reversed, so one reversal each.
SHARED_FN vec2 qmc2(uint pixel, uint sampleIndex, uint dimension, uint seed) {
  uvec4 h = pcg4d(uvec4(pixel, dimension, seed, 0x9e3779b9u));
  uint index = rngOwenScramble(sampleIndex, h.x);  // shuffles the order of the points
  uint x = rngReverseBits(rngLaineKarras(index, h.y));
  uint y = rngReverseBits(rngLaineKarras(rngSobol1Reversed(index), h.z));
  return vec2(float(x >> 8u), float(y >> 8u)) * (1.0f / 16777216.0f);
}

// The sampler of a render: independent PCG hashes or QMC.
SHARED_FN vec2 sample2(uint mode, uint pixel, uint sampleIndex, uint dimension, uint seed) {
  if (mode == RNG_QMC) return qmc2(pixel, sampleIndex, dimension, seed);
  return rng2(pixel, sampleIndex, dimension, seed);
}

SHARED_FN float sample1(uint mode, uint pixel, uint sampleIndex, uint dimension, uint seed) {
  return sample2(mode, pixel, sampleIndex, dimension, seed).x;
}

SHARED_END
#endif
