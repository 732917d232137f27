// mlt.h: primary-sample-space Metropolis (PSSMLT; Kelemen, Szirmay-Kalos et al. 2002; issue 19,
// docs/mlt.md): the chains' state (GpuMlt, the buffers of src/render/mlt_integrator.cpp) and the
// mutation kernel, shared by the mlt stage (shaders/stages/mlt.comp) and its C++ tests.
//
// A chain's state is a primary sample vector: the 2-D draws of a path (stage_common.glsl,
// pathSample2), which the path tracer turns into a path and its radiance L. Each step proposes a
// new vector, either a large step (every draw fresh and uniform: an independent path) with
// probability largeStep, or a small step (every coordinate the current path read moved by a normal
// deviate of standard deviation sigma, wrapped around the unit interval; the others fresh:
// mltExtent). Both proposals are symmetric, q(x -> y) = q(y -> x) (a large step's density is 1
// either way; a small step's depends only on the wrapped difference, whose distribution is
// symmetric about 0), so the acceptance is min(1, f(y) / f(x)) with f = luminance(L).
#ifndef NUSSELT_MLT_H
#define NUSSELT_MLT_H
#include "prelude.h"
#include "layout.h"
#include "rng.h"
SHARED_BEGIN

// The kernels of the mlt stage (specialization constant 13 of shaders/stages/mlt.comp).
// A bootstrap chunk needs no kernel before its trace: its paths' draws are all fresh
// (PRIMARY_FRESH_POOL: slot c draws those of bootstrap path poolFirst + c where it reads them).
#define MLT_KERNEL_START 0u    // path slot c gets the vector of bootstrap path start[c] (chain c's start)
#define MLT_KERNEL_RECORD 1u   // pool[poolFirst + c] = f of the path slot c traced
#define MLT_KERNEL_ADOPT 2u    // chain c's state = the path slot c traced (its start), no splat
#define MLT_KERNEL_MUTATE 3u   // path slot c gets chain c's proposal (the draws it moves; the rest fresh)
#define MLT_KERNEL_ACCEPT 4u   // splat current and proposal, accept or reject
#define MLT_KERNEL_RESOLVE 5u  // the pass's splats into the film
// Light outside the chains (the part the chains do not carry, path-traced per pixel): pixels
// pool.x .. pool.x + pool.y - 1, outside.z samples each (numbers outside.x + k): path slot
// k x pool.y + c traces sample k of pixel pool.x + c with the path tracer's numbers
// (PRIMARY_FRESH_PIXEL, mltPixelDraw; no kernel before the trace); then invocation c adds its
// pixel's samples / outside.y to the film, in sample order (no atomics).
#define MLT_KERNEL_PIXEL_ADD 6u
#define MLT_KERNEL_ADVANCE 7u  // one invocation: the next step of the iteration (info.z + 1)
#define MLT_KERNELS 8u
// No kernel (MltIntegrator::traceBetween).
#define MLT_KERNEL_NONE 0xffffffffu
// Splats are sums of fixed-point integers (2^24 units per unit of luminance-normalised radiance),
// 64 bits per channel (two uints with carry): integer addition commutes, so the image does not
// depend on the order in which chains splat (same seed, same image, bit for bit).
#define MLT_FIXED_SCALE 16777216.0f
// Counters (GpuMlt.counters): proposals, accepted, large-step proposals, large steps accepted.
#define MLT_COUNTERS 4u
// GpuMlt.extent and .written: the bit that says the vector is in the second buffer (vectorsB), and
// the count below it.
#define MLT_SIDE_B 0x80000000u
#define MLT_COUNT 0x7fffffffu
// The draws of a step that are not a coordinate (large or small, accept): dimension index.
#define MLT_DIM_STEP 0xffffffffu
// Streams of the hash (the fourth key component): chains' mutations, the bootstrap pool, chain starts.
#define MLT_STREAM_MUTATE 0x6d75u
#define MLT_STREAM_POOL 0x706fu
#define MLT_STREAM_START 0x7374u

// The chains' state: GpuMlt (layout.h, Globals.mlt).

SHARED_FN float mltUnit(uint bits) { return float(bits >> 8u) * (1.0f / 16777216.0f); }

// The hash of one step's draws: chain, iteration, dimension (or MLT_DIM_STEP), seed.
SHARED_FN uvec4 mltHash(uint chain, uint iteration, uint dimension, uint seed) {
  return pcg4d(uvec4(chain, iteration, dimension, seed ^ (MLT_STREAM_MUTATE << 16u)));
}

// Bootstrap path i's vector, draw `dimension`: independent uniforms (24 bits, never 1).
SHARED_FN vec2 mltPoolSample(uint i, uint dimension, uint seed) {
  uvec4 h = pcg4d(uvec4(i, dimension, seed, MLT_STREAM_POOL));
  return vec2(mltUnit(h.x), mltUnit(h.y));
}

// Draw `dimension` of sample `number` of a pixel of an image of `size` in a path-traced pass:
// the path tracer's draw (rng.h, sample2 of the render's mode: QMC by default), except that draw 0,
// the jitter in the pixel, places the ray on the image (camera.comp, IMAGE_SAMPLES) within it.
SHARED_FN vec2 mltPixelDraw(uint mode, uint pixel, uint number, uint dimension, uint seed, uvec2 size) {
  vec2 u = sample2(mode, pixel, number, dimension, seed);
  if (dimension == 0u) u = (vec2(float(pixel % size.x), float(pixel / size.x)) + u) / vec2(float(size.x), float(size.y));
  return u;
}

// x wrapped into [0, 1) (x - floor(x) rounds to 1 for tiny negative x: that is 0 on the circle).
SHARED_FN float mltWrap(float x) {
  x = x - floor(x);
  return x < 1.0f ? x : 0.0f;
}

// The small step of draw u: both coordinates plus sigma x a standard normal pair (Box-Muller on
// h.x, h.y), wrapped. The displacement's law is that of sigma N(0, I) wrapped on the torus,
// whatever u: symmetric.
SHARED_FN vec2 mltSmallStep(vec2 u, uvec4 h, float sigma) {
  float u1 = (float(h.x >> 8u) + 1.0f) * (1.0f / 16777216.0f);  // (0, 1]: log finite
  float a = 6.28318530717958647692f * mltUnit(h.y);
  float r = sigma * sqrt(-2.0f * log(u1));
  return vec2(mltWrap(u.x + r * cos(a)), mltWrap(u.y + r * sin(a)));
}

// The draws a path with `bounces` shaded vertices read: the camera's (dimensions 0 and 1) and each
// shaded bounce's RNG_DIMS_PER_BOUNCE (rng.h; the shade stage records the bounces), at most dims.
// A small step moves these draws of the current vector and draws every later one fresh, as a large
// step does. That is the same chain, in law, as moving every draw: f does not depend on draws the
// current path did not read, so under the chain's target their conditional law is uniform, and
// redrawing them uniformly is a Gibbs step that leaves the target invariant (which draws it
// redraws depends only on the draws the path read, which it keeps); the small step then moves
// uniform draws to uniform draws. What it saves: the normal deviates and the copies of every draw
// a short path never reads.
SHARED_FN uint mltExtent(uint bounces, uint dims) { return min(rngDimension(bounces, 0u), dims); }

// The draws of a chain's vector that matter: those an unguided path may read (rng.h; mlt renders
// are never guided). The others are never read, so a step neither moves nor keeps them: in law a
// Gibbs redraw (as for the draws beyond the extent, above), and no work.
SHARED_FN bool mltReadsDraw(uint dimension) { return rngReadUnguided(dimension); }

// The large step's draw: fresh uniforms from h.z, h.w.
SHARED_FN vec2 mltLargeStep(uvec4 h) { return vec2(mltUnit(h.z), mltUnit(h.w)); }

// The proposal for draw u of a step with that draw's hash h: fresh (a large step, or a draw the
// current path did not read: mltExtent) or moved by the small step. (The mutation kernel stores
// only the moved draws, mltSmallStep; the stages compute the fresh ones, mltFreshSample.)
SHARED_FN vec2 mltPropose(vec2 u, uvec4 h, bool fresh, float sigma) {
  return fresh ? mltLargeStep(h) : mltSmallStep(u, h, sigma);
}

// A fresh draw that a pass leaves out of the path slots' vectors (layout.h, PRIMARY_FRESH_*), as
// the stages compute it where they read it and the mlt kernels where they keep it: POOL, draw
// `dimension` of bootstrap path key.x with the bootstrap's seed key.y (mltPoolSample); MUTATE, the
// step's fresh draw of chain `slot` at iteration key.x with the render's seed key.y (mltLargeStep).
// (PIXEL: mltPixelDraw, which needs the image's size.)
SHARED_FN vec2 mltFreshSample(uint mode, uint slot, uint dimension, uvec2 key) {
  if (mode == PRIMARY_FRESH_POOL) return mltPoolSample(key.x, dimension, key.y);
  return mltLargeStep(mltHash(slot, key.x, dimension, key.y));
}

SHARED_END
#endif
