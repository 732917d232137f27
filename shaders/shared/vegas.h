// vegas.h: VEGAS on the primary sample space (Lepage 1978; issue 19, docs/vegas.md): a separable
// warp of the path's first draws, shared by the vegas stage (shaders/stages/vegas.comp), the host
// that learns it (src/render/vegas_integrator.cpp) and its C++ tests.
//
// The warped axes: for each of the first `bounces` bounces, the light choice (x of its draw), the
// light point (x, y) and the BSDF draw (x, y): VEGAS_AXES_PER_BOUNCE axes, axis a of bounce
// a / VEGAS_AXES_PER_BOUNCE (vegasAxisDimension, vegasAxisComponent). Every other number of the
// path (the camera's jitter, roulette, component choice, deeper bounces, the light choice's unused
// y) stays the path tracer's uniform number.
//
// Each axis has a piecewise-constant density over `bins` equal bins of [0, 1), stored as its CDF
// (bins + 1 floats: cdf[0] = 0, cdf[bins] = 1). A uniform u maps to x through the inverse CDF
// (vegasWarp); the density at x is (cdf[i + 1] - cdf[i]) x bins for the bin i that holds x, the
// same differences the search inverts, so the density evaluated is the one sampled whatever the
// rounding of the table. The path's estimate is f(x) / prod_a p_a(x_a): unbiased for any table
// whose bins all have mass (the host mixes every learned density with the uniform one).
#ifndef NUSSELT_VEGAS_H
#define NUSSELT_VEGAS_H
#include "prelude.h"
#include "rng.h"
#include "distribution2d.h"  // dist2dSearch, Dist2dData (a Floats reference in GLSL, a float pointer in C++)
SHARED_BEGIN

// The kernels of the vegas stage (specialization constant 13 of shaders/stages/vegas.comp).
#define VEGAS_KERNEL_WARP 0u   // path slot i's primary draws: the hashed uniforms, warped on the axes
#define VEGAS_KERNEL_WEIGH 1u  // path slot i's radiance x 1 / p(x); F^2 into the axes' bin sums
#define VEGAS_AXES_PER_BOUNCE 5u
// Bin sums are 64-bit fixed-point integers (two uints with carry; 2^16 units per unit of F^2, F =
// luminance of the weighted radiance, each sample's F^2 clamped to VEGAS_SUM_CLAMP): integer
// addition commutes, so the learned tables, and the image, do not depend on the order of the
// atomics. The clamp and the rounding only shape the learned density, never the estimate.
#define VEGAS_FIXED_SCALE 65536.0f
#define VEGAS_SUM_CLAMP 16384.0f

// The draw (rng.h dimension) and its component (0: x, 1: y) of warped axis a.
SHARED_FN uint vegasAxisDimension(uint axis) {
  uint k = axis % VEGAS_AXES_PER_BOUNCE;
  uint slot = k == 0u ? RNG_DIM_LIGHT_SELECT : (k < 3u ? RNG_DIM_LIGHT_POINT : RNG_DIM_BSDF);
  return rngDimension(axis / VEGAS_AXES_PER_BOUNCE, slot);
}
SHARED_FN uint vegasAxisComponent(uint axis) {
  uint k = axis % VEGAS_AXES_PER_BOUNCE;
  return k == 0u ? 0u : (k - 1u) % 2u;
}

// The warped axis of component c of draw `dimension`, or INVALID (0xffffffff) when it stays
// uniform, for `bounces` warped bounces.
SHARED_FN uint vegasAxisOf(uint dimension, uint c, uint bounces) {
  if (dimension < 2u) return 0xffffffffu;
  uint b = (dimension - 2u) / RNG_DIMS_PER_BOUNCE;
  uint s = (dimension - 2u) % RNG_DIMS_PER_BOUNCE;
  if (b >= bounces) return 0xffffffffu;
  uint base = b * VEGAS_AXES_PER_BOUNCE;
  if (s == RNG_DIM_LIGHT_SELECT) return c == 0u ? base : 0xffffffffu;
  if (s == RNG_DIM_LIGHT_POINT) return base + 1u + c;
  if (s == RNG_DIM_BSDF) return base + 3u + c;
  return 0xffffffffu;
}

// Primary draws a path of the vegas integrator reads from the buffer: every draw up to the last
// warped one (the others hash as the path tracer's).
SHARED_FN uint vegasPrimaryDims(uint bounces) { return rngDimension(bounces - 1u, RNG_DIM_BSDF) + 1u; }

// Where a pass's warped numbers come from (GpuVegas.epoch.y). The table a pass warps with was
// learned from earlier passes; the path tracer's QMC points of a pixel are stratified against
// each other, so numbers from the same sequence would depend on the points the table was learned
// from, and E[f / p] given the table would not be the integral (measured in the white furnace:
// +0.28 %, IntegratorFurnace.Vegas). RENDER: the render's own numbers (the first pass, whose table
// is uniform, and alpha 1: the path tracer's numbers bit for bit). LEARN: a pass whose table was
// learned and may still change: independent hashes (the PCG sampler's numbers in a stream of their
// own), which nothing before can know. FROZEN: the table no longer changes (--vegas-learn tables
// learned): the render's sampler (QMC by default) with a seed of its own, whose scramble no earlier
// number shares (the first pass used the render's seed, every other pass hashes), so a frozen
// table's passes keep the QMC sequence's stratification over the rest of the render.
#define VEGAS_NUMBERS_RENDER 0u
#define VEGAS_NUMBERS_LEARN 1u
#define VEGAS_NUMBERS_FROZEN 2u
#define VEGAS_STREAM_NUMBERS 0x766eu
// The numbers of a LEARN or FROZEN pass (a RENDER pass keeps the render's own: vegas.comp).
SHARED_FN vec2 vegasNumbers(uint source, uint mode, uint pixel, uint sampleIndex, uint dimension, uint seed) {
  uint s = seed ^ (VEGAS_STREAM_NUMBERS << 16u) ^ (source << 8u);
  return source == VEGAS_NUMBERS_LEARN ? rng2(pixel, sampleIndex, dimension, s) : sample2(mode, pixel, sampleIndex, dimension, s);
}
// The bin of x in [0, 1) among n equal bins.
SHARED_FN uint vegasBin(float x, uint n) { return min(uint(x * float(n)), n - 1u); }

// Density of the axis whose CDF starts at t[base] (n bins) in bin i.
SHARED_FN float vegasDensity(Dist2dData t, uint base, uint n, uint i) {
  return (DIST2D_AT(t, base + i + 1u) - DIST2D_AT(t, base + i)) * float(n);
}

// x from u in [0, 1) through the inverse CDF, with the density at x (pdf) and x's bin. Within
// bin i the map is linear: x = (i + (u - cdf[i]) / P_i) / n. A uniform table (cdf[i] = i / n, n a
// power of two) gives x = u bit for bit.
SHARED_FN float vegasWarp(Dist2dData t, uint base, uint n, float u, OUT(float) pdf, OUT(uint) bin) {
  uint i = dist2dSearch(t, base, n, u);
  float c0 = DIST2D_AT(t, base + i);
  float p = DIST2D_AT(t, base + i + 1u) - c0;
  float x = (float(i) + (u - c0) / p) / float(n);
  x = min(max(x, 0.0f), NUSSELT_ONE_MINUS_EPS);
  // The density where x landed (rounding can put x on the next bin's edge).
  bin = vegasBin(x, n);
  pdf = vegasDensity(t, base, n, bin);
  return x;
}

SHARED_END
#endif
