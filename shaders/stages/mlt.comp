#version 460
#extension GL_GOOGLE_include_directive : require
// mlt: the kernels of primary-sample-space Metropolis (docs/mlt.md, src/render/mlt_integrator.cpp),
// one per pipeline (constant 13, MLT_KERNEL_*), around the path tracer's stages, which trace the
// vectors these kernels put into the path slots (g.primarySamples) and leave each slot's radiance
// in g.pathRadiance and its pixel in g.pathInfo.x. One invocation per chain (or bootstrap path, or
// pixel for the resolve). Vectors are stored as the path tracer reads them (layout.h,
// primarySampleIndex).
#include "shared/stage_common.glsl"
#include "shared/mlt.h"

layout(constant_id = 13) const uint MLT_KERNEL = 0u;

// A path's radiance, or 0 (counted) when it is not finite: f = 0 is never accepted nor splatted.
vec3 tracedRadiance(uint c) {
  vec3 L = g.pathRadiance.v[c].xyz;
  if (!(isFinite(L.x) && isFinite(L.y) && isFinite(L.z))) {
    atomicAdd(g.stats.v[STAT_NONFINITE_SAMPLES], 1u);
    return vec3(0.0f);
  }
  return max(L, vec3(0.0f));
}

// Adds v (>= 0, < 2^8 per channel) to a pixel's fixed-point sums (a 64-bit integer per channel).
void splat(GpuMlt m, uint pixel, vec3 v) {
  for (uint ch = 0u; ch < 3u; ++ch) atomicAddFixed64(m.splats, (pixel * 3u + ch) * 2u, min(v[ch], 255.0f), MLT_FIXED_SCALE);
}

// Adds n subgroup-wide to counter k (one atomic per subgroup).
void count(GpuMlt m, uint k, bool on) {
  uint n = subgroupBallotBitCount(subgroupBallot(on));
  if (subgroupElect() && n != 0u) atomicAdd(m.counters.v[k], n);
}

void main() {
  uint c = gl_GlobalInvocationID.x;
  GpuMlt m = g.mlt.v[0];
  uint chains = m.info.x;
  uint dims = m.info.y;
  uint iteration = m.info.z;
  Vec2s primary = g.primarySamples;

  if (MLT_KERNEL == MLT_KERNEL_START) {
    if (c >= chains) return;
    uint i = m.start.v[c];
    if (m.restart.x != 0u) {
      // A pass pool's path: the path tracer's numbers of its pixel and sample.
      uint pixel = i % m.info.w, number = m.restart.y + i / m.info.w;
      for (uint d = 0u; d < dims; ++d)
        primary.v[primarySampleIndex(c, d, dims)] = mltPixelDraw(g.rngMode, pixel, number, d, g.seed, uvec2(g.width, g.height));
    } else {
      for (uint d = 0u; d < dims; ++d) primary.v[primarySampleIndex(c, d, dims)] = mltPoolSample(i, d, m.pool.w);
    }
  } else if (MLT_KERNEL == MLT_KERNEL_RECORD) {
    if (c >= m.pool.y) return;
    m.poolF.v[m.pool.x + c] = luminance(tracedRadiance(c));
  } else if (MLT_KERNEL == MLT_KERNEL_ADOPT) {
    if (c >= chains) return;
    // The start's vector stays where MLT_KERNEL_START put it (primarySamples): the current vector.
    m.state.v[c] = vec4(tracedRadiance(c), uintBitsToFloat(g.pathInfo.v[c].x));
    m.extent.v[c] = mltExtent(g.pathInfo.v[c].z, dims);
  } else if (MLT_KERNEL == MLT_KERNEL_MUTATE) {
    if (c >= chains) return;
    bool large = mltUnit(mltHash(c, iteration, MLT_DIM_STEP, g.seed).x) < m.params.x;
    // A small step moves the draws the current path read and draws the rest fresh (mltExtent).
    // Only the moved draws are stored: the stages compute the fresh ones where they read them
    // (PRIMARY_FRESH_MUTATE, mltFreshSample), and most are never read.
    // The proposal goes into the buffer that does not hold the current vector.
    uint e = m.extent.v[c];
    bool currentB = (e & MLT_SIDE_B) != 0u;
    Vec2s current = currentB ? m.vectorsB : primary;
    Vec2s proposal = currentB ? primary : m.vectorsB;
    uint moved = large ? 0u : e & MLT_COUNT;
    for (uint d = 0u; d < moved; ++d) {
      if (!mltReadsDraw(d)) continue;
      uint at = primarySampleIndex(c, d, dims);
      proposal.v[at] = mltSmallStep(current.v[at], mltHash(c, iteration, d, g.seed), m.params.y);
    }
    m.written.v[c] = moved | (currentB ? 0u : MLT_SIDE_B);
  } else if (MLT_KERNEL == MLT_KERNEL_ACCEPT) {
    bool live = c < chains;
    bool large = false, accepted = false;
    if (live) {
      uvec4 h = mltHash(c, iteration, MLT_DIM_STEP, g.seed);
      large = mltUnit(h.x) < m.params.x;
      vec4 state = m.state.v[c];
      vec3 Lc = state.xyz;
      float fc = luminance(Lc);
      vec3 Lp = tracedRadiance(c);
      float fp = luminance(Lp);
      uint pp = g.pathInfo.v[c].x;
      float a = fc > 0.0f ? min(1.0f, fp / fc) : 1.0f;
      if (m.weights.x != 0.0f) {
        // Kelemen et al.: the chain's expected values a and 1 - a, and a large step's path once more
        // as an independent sample (1 / b: the resolve multiplies by b), each over f / b' + p.
        float ib = m.weights.y;
        float p = m.weights.w;
        float wp = (a * ib + (large ? m.weights.z : 0.0f)) / (fp * ib + p);
        if (fp > 0.0f && wp > 0.0f) splat(m, pp, Lp * wp);
        if (fc > 0.0f && a < 1.0f) splat(m, floatBitsToUint(state.w), Lc * ((1.0f - a) * ib / (fc * ib + p)));
      } else {
        // Expected values: the proposal weighted by its acceptance, the current state by the rest.
        if (fp > 0.0f && a > 0.0f) splat(m, pp, Lp * (a / fp));
        if (fc > 0.0f && a < 1.0f) splat(m, floatBitsToUint(state.w), Lc * ((1.0f - a) / fc));
      }
      accepted = mltUnit(h.y) < a;
      if (accepted) {
        // The proposal becomes the current vector in its buffer; of the draws the new path read
        // (the next step draws the others fresh), those the mutation did not store are stored now.
        uint extent = mltExtent(g.pathInfo.v[c].z, dims);
        uint w = m.written.v[c];
        Vec2s proposal = (w & MLT_SIDE_B) != 0u ? m.vectorsB : primary;
        for (uint d = w & MLT_COUNT; d < extent; ++d)
          if (mltReadsDraw(d))
            proposal.v[primarySampleIndex(c, d, dims)] = mltFreshSample(PRIMARY_FRESH_MUTATE, c, d, uvec2(iteration, g.seed));
        m.state.v[c] = vec4(Lp, uintBitsToFloat(pp));
        m.extent.v[c] = extent | (w & MLT_SIDE_B);
      }
    }
    count(m, 0u, live);
    count(m, 1u, accepted);
    count(m, 2u, live && large);
    count(m, 3u, accepted && large);
  } else if (MLT_KERNEL == MLT_KERNEL_PIXEL_ADD) {
    if (c >= m.pool.y) return;
    vec3 sum = vec3(0.0f);
    for (uint k = 0u; k < m.outside.z; ++k) {
      uint slot = k * m.pool.y + c;
      sum += tracedRadiance(slot);
      // The pass pool (GpuMlt.restart): f of the caustic light the path left to the chains, which
      // the shade and escape stages keep in its radiance's w.
      uint number = m.outside.x + k;
      if (m.restart.w != 0u && number >= m.restart.y && number - m.restart.y <= m.restart.w / m.info.w) {
        uint at = (number - m.restart.y) * m.info.w + m.pool.x + c;
        float f = g.pathRadiance.v[slot].w;
        if (at < m.restart.w) m.poolF.v[at] = isFinite(f) ? max(f, 0.0f) : 0.0f;
      }
    }
    g.film.v[m.pool.x + c].xyz += sum / float(m.outside.y);
  } else if (MLT_KERNEL == MLT_KERNEL_ADVANCE) {
    if (c == 0u) {
      Mlts state = g.mlt;
      state.v[0].info.z = iteration + 1u;
    }
  } else if (MLT_KERNEL == MLT_KERNEL_RESOLVE) {
    if (c >= m.info.w) return;
    vec3 sum;
    for (uint ch = 0u; ch < 3u; ++ch) {
      uint at = (c * 3u + ch) * 2u;
      sum[ch] = float(m.splats.v[at + 1u]) * 4294967296.0f + float(m.splats.v[at]);
      m.splats.v[at] = 0u;
      m.splats.v[at + 1u] = 0u;
    }
    g.film.v[c] += vec4(sum * m.params.z, m.params.w);
  }
}
