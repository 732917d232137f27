// sample_run.h: draw N directions with the generic sampler for one known direction, on the GPU
// (stage sample_tool) or the CPU (the same shared code), for `nusselt sample` and the tests.
// Sample i uses u = rng2(i, 0, RNG_DIM_BSDF, seed) (and the quadtree the stream of u) on both devices.
#pragma once
#include <cstdint>
#include <vector>

#include "../../shaders/shared/bsdf_sampling.h"
#include "quadtree/sampler_tables.h"
#include "sampling/tabulated.h"
#include "vk/vk.h"

namespace nusselt::quadtree {

struct SampleBatch {
  std::vector<shared::vec4> wPdf;  // direction (local frame), pdf per unit solid angle (0: failed)
  std::vector<shared::vec4> fOk;   // f rgb, 1 if the sample succeeded
  std::uint64_t boundViolations = 0, trialFailures = 0;
  std::uint64_t trials = 0;        // CPU only: rejection trials in total (proposal draws)
  std::uint64_t evaluations = 0;   // CPU only: trials that evaluated f (inside leaf & disc)
  std::uint64_t nodeReads = 0;     // CPU only: inner nodes read by the tree descents
  std::vector<std::uint64_t> leafEvaluations, leafAccepted;  // CPU only: per leaf of `tables`
  double seconds = 0;
  double medianSecondsPerSample = 0;  // GPU with timingRepeats > 0: median of the repeated timings
};

// bins (model gltf_pbr): binned sampling (bsdf_sampling.h, binnedSample) of the texel parameters
// `params` with the bins' sets bins->first .. of `tables`, as sampleGpu's; `set` is unused then.
SampleBatch sampleCpu(const SamplerTables& tables, std::uint32_t set, std::uint32_t model, const shared::BrdfParams& params,
                      shared::vec3 v, std::uint32_t n, std::uint32_t seed, unsigned threads = 0,
                      const shared::RoughnessBins* bins = nullptr);

// The theta tables that lookups at the known direction thetaDeg read (quadGrid: the two around it),
// with one more on each side for the float rounding of the angle: a build of only these
// (QuadtreeSettings::onlyThetaTables) samples that direction as the full grid does.
std::vector<std::uint32_t> thetaTablesAround(double thetaDeg, std::uint32_t thetaTables);

// The other strategies (SAMPLER_COSINE, SAMPLER_UNIFORM, SAMPLER_ANALYTIC, SAMPLER_TABULATED of
// shaders/shared/bsdf_sampling.h) on the CPU, with the same random numbers. tabulated needs `tab`
// and its TabSet index in `set`; the others ignore both.
SampleBatch sampleCpuStrategy(std::uint32_t strategy, const sampling::TabulatedTables* tab, std::uint32_t set,
                              std::uint32_t model, const shared::BrdfParams& params, shared::vec3 v, std::uint32_t n,
                              std::uint32_t seed, unsigned threads = 0);

// strategy: SAMPLER_QUADTREE (default; `set` indexes `tables`), SAMPLER_COSINE, SAMPLER_UNIFORM,
// SAMPLER_ANALYTIC or SAMPLER_TABULATED (needs `tab`; `set` then indexes its TabSets).
// seconds = wall time of the dispatches alone (pipeline and buffers are made before; the first
// dispatch includes lavapipe's lazy shader compilation unless warmUp).
// warmUp: run one small untimed dispatch first (for benchmarks).
// timingRepeats > 0: before the batch, time the dispatches of the first min(n, timingCount)
// samples that many times and report the median time per sample (medianSecondsPerSample).
SampleBatch sampleGpu(vk::Context& ctx, const SamplerTables& tables, std::uint32_t set, std::uint32_t model,
                      const shared::BrdfParams& params, shared::vec3 v, std::uint32_t n, std::uint32_t seed,
                      std::uint32_t strategy = SAMPLER_QUADTREE, const sampling::TabulatedTables* tab = nullptr,
                      bool warmUp = false, std::uint32_t timingRepeats = 0,
                      std::uint32_t timingCount = std::uint32_t(1) << 20, const shared::RoughnessBins* bins = nullptr,
                      std::uint32_t idleLanes = 0);
// idleLanes: subgroup lanes l with bit l set draw nothing (fOk.w = -1 there): partial subgroups, as
// the shade stages have, for the tests of the quadtree's shared trials (quadtree.h).
// bins (quadtree only, model gltf_pbr): binned sampling (bsdf_sampling.h, binnedSample) of the texel
// parameters `params` with the bins' sets bins->first .. of `tables` (the sample tool's BINNED
// specialization, constant 2); `set` is unused then.

}  // namespace nusselt::quadtree
