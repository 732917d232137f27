// sample_run.cpp: see sample_run.h.
#include "quadtree/sample_run.h"

#include "brdf/merl.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <thread>

#include "../../shaders/shared/layout.h"

namespace nusselt::quadtree {

using namespace shared;

SampleBatch sampleCpu(const SamplerTables& tables, std::uint32_t set, std::uint32_t model, const BrdfParams& params, vec3 v,
                      std::uint32_t n, std::uint32_t seed, unsigned threads, const RoughnessBins* bins) {
  auto t0 = std::chrono::steady_clock::now();
  SampleBatch out;
  out.wPdf.assign(n, vec4(0.0f));
  out.fOk.assign(n, vec4(0.0f));
  unsigned nt = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<std::uint64_t> viol{0}, fail{0}, trials{0}, evals{0}, nodeReads{0};
  std::vector<std::vector<std::uint64_t>> leafEval(nt, std::vector<std::uint64_t>(tables.leaves.size(), 0)),
      leafAcc(nt, std::vector<std::uint64_t>(tables.leaves.size(), 0));
  auto work = [&](unsigned t) {
    QuadHostScope scope(tables);
    scope.countPerLeaf(leafEval[t].data(), leafAcc[t].data());
    for (std::uint32_t i = t; i < n; i += nt) {
      vec2 u = rng2(i, 0u, RNG_DIM_BSDF, seed);
      vec3 w, f;
      float pdf;
      bool ok = bins ? binnedSample(*bins, params, v, u, w, pdf, f) : quadSample(set, model, params, v, u, w, pdf, f);
      out.wPdf[i] = vec4(w, ok ? pdf : 0.0f);
      out.fOk[i] = vec4(f, ok ? 1.0f : 0.0f);
    }
    viol += scope.counters().boundViolations;
    fail += scope.counters().trialFailures;
    trials += scope.counters().trials;
    evals += scope.counters().evaluations;
    nodeReads += scope.counters().nodeReads;
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < nt; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  out.boundViolations = viol;
  out.trialFailures = fail;
  out.trials = trials;
  out.evaluations = evals;
  out.nodeReads = nodeReads;
  out.leafEvaluations.assign(tables.leaves.size(), 0);
  out.leafAccepted.assign(tables.leaves.size(), 0);
  for (unsigned t = 0; t < nt; ++t)
    for (std::size_t l = 0; l < tables.leaves.size(); ++l) {
      out.leafEvaluations[l] += leafEval[t][l];
      out.leafAccepted[l] += leafAcc[t][l];
    }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::vector<std::uint32_t> thetaTablesAround(double thetaDeg, std::uint32_t thetaTables) {
  const double step = 90.0 / thetaTables;
  const long k = long(std::floor(thetaDeg / step));
  std::vector<std::uint32_t> out;
  for (long i = k - 1; i <= k + 2; ++i)
    if (i >= 0 && i < long(thetaTables)) out.push_back(std::uint32_t(i));
  return out;
}

SampleBatch sampleCpuStrategy(std::uint32_t strategy, const sampling::TabulatedTables* tab, std::uint32_t set,
                              std::uint32_t model, const BrdfParams& params, vec3 v, std::uint32_t n, std::uint32_t seed,
                              unsigned threads) {
  if (strategy == SAMPLER_TABULATED && !tab) throw std::invalid_argument("sampleCpuStrategy: tabulated needs its tables");
  auto t0 = std::chrono::steady_clock::now();
  SampleBatch out;
  out.wPdf.assign(n, vec4(0.0f));
  out.fOk.assign(n, vec4(0.0f));
  unsigned nt = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  auto work = [&](unsigned t) {
    std::unique_ptr<sampling::TabHostScope> scope;
    if (tab) scope = std::make_unique<sampling::TabHostScope>(*tab);
    for (std::uint32_t i = t; i < n; i += nt) {
      vec2 u = rng2(i, 0u, RNG_DIM_BSDF, seed);
      vec3 w, f;
      float pdf;
      bool ok = strategySample(strategy, model, set, params, v, u, w, pdf, f);
      out.wPdf[i] = vec4(w, ok ? pdf : 0.0f);
      out.fOk[i] = vec4(f, ok ? 1.0f : 0.0f);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < nt; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& th : pool) th.join();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

SampleBatch sampleGpu(vk::Context& ctx, const SamplerTables& tables, std::uint32_t set, std::uint32_t model,
                      const BrdfParams& params, vec3 v, std::uint32_t n, std::uint32_t seed, std::uint32_t strategy,
                      const sampling::TabulatedTables* tab, bool warmUp, std::uint32_t timingRepeats,
                      std::uint32_t timingCount, const RoughnessBins* bins, std::uint32_t idleLanes) {
  if (strategy == SAMPLER_TABULATED && !tab) throw std::invalid_argument("sampleGpu: tabulated needs its tables");
  SampleBatch out;
  auto upload = [&](const void* data, std::size_t bytes, const char* what) {
    vk::Buffer b = vk::createBuffer(ctx, std::max<std::size_t>(bytes, 16), 0, false, what);
    if (bytes) vk::uploadBuffer(ctx, b, data, bytes);
    return b;
  };
  GpuMaterial mat{};
  mat.info = uvec4(model, bins ? MATERIAL_BINNED : 0u, set, 0u);
  mat.params = params;
  // A measured table goes to the GPU as table 0 of the measured buffer.
  const bool measured = model == MODEL_MERL;
  if (measured) mat.params.v[0][MERL_SLOT] = 0.0f;
  vk::Buffer measuredTables = measured ? upload(merlTable(params).rgb.data(), MERL_TABLE_FLOATS * sizeof(float), "measured table")
                                       : upload(nullptr, 0, "measured table");
  vk::Buffer materials = upload(&mat, sizeof mat, "sampler materials");
  vk::Buffer sets = upload(tables.sets.data(), tables.sets.size() * sizeof(QuadSet), "quadtree sets");
  vk::Buffer tabs = upload(tables.tables.data(), tables.tables.size() * sizeof(QuadTable), "quadtree tables");
  vk::Buffer nodes = upload(tables.nodes.data(), tables.nodes.size() * sizeof(QuadNode), "quadtree nodes");
  vk::Buffer leaves = upload(tables.leaves.data(), tables.leaves.size() * sizeof(QuadLeaf), "quadtree leaves");
  vk::Buffer tSets = tab ? upload(tab->sets.data(), tab->sets.size() * sizeof(TabSet), "tabulated sets")
                         : upload(nullptr, 0, "tabulated sets");
  vk::Buffer tTables = tab ? upload(tab->tables.data(), tab->tables.size() * sizeof(TabTable), "tabulated tables")
                           : upload(nullptr, 0, "tabulated tables");
  vk::Buffer tData = tab ? upload(tab->data.data(), tab->data.size() * sizeof(float), "tabulated cdfs")
                         : upload(nullptr, 0, "tabulated cdfs");
  vk::Buffer film = vk::createBuffer(ctx, std::max<std::size_t>(n, 1) * 16, 0, true, "sample output");
  vk::Buffer filmSq = vk::createBuffer(ctx, std::max<std::size_t>(n, 1) * 16, 0, true, "sample output f");
  vk::Buffer stats = vk::createBuffer(ctx, STAT_COUNT * 4, 0, true, "sampler stats");
  std::memset(stats.mapped, 0, STAT_COUNT * 4);
  vk::Buffer globals = vk::createBuffer(ctx, sizeof(Globals), 0, true, "sampler globals");
  Globals g{};
  g.materials = materials.address;
  g.film = film.address;
  g.filmSq = filmSq.address;
  g.stats = stats.address;
  g.quadSets = sets.address;
  g.quadTables = tabs.address;
  g.quadNodes = nodes.address;
  g.quadLeaves = leaves.address;
  g.tabSets = tSets.address;
  g.tabTables = tTables.address;
  g.tabData = tData.address;
  g.measured = measuredTables.address;
  if (bins) g.roughnessBins = *bins;

  // Binding 0 = the Globals block, as the renderer's stages.
  std::memcpy(globals.mapped, &g, sizeof g);
  vk::GlobalsBinding binding = vk::createGlobalsBinding(ctx, globals.buffer, STAGE_PUSH_BYTES);
  VkPipelineLayout layout = binding.layout;
  VkDescriptorSet dset = binding.set;
  vk::ComputePipeline pipe = bins ? vk::createComputePipeline(ctx, layout, "sample_tool", {model, strategy, 1u})
                                  : vk::createComputePipeline(ctx, layout, "sample_tool", {model, strategy});

  SampleToolConstants pc{};
  pc.seed = seed;
  pc.idleLanes = idleLanes;
  pc.v = vec4(v, 0.0f);
  if (warmUp) {  // lavapipe compiles the shader at its first dispatch: keep that out of the timing
    pc.count = std::min<std::uint32_t>(n, WORKGROUP_SIZE);
    pc.first = 0;
    VkCommandBuffer cmd = vk::beginOneShot(ctx);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &dset, 0, nullptr);
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::endOneShot(ctx, cmd);
    std::memset(stats.mapped, 0, STAT_COUNT * 4);
  }
  // Samples [0, count) in chunks of at most 65535 workgroups (maxComputeWorkGroupCount on lavapipe).
  auto dispatchSamples = [&](std::uint32_t count) {
    const std::uint32_t chunk = 65535u * WORKGROUP_SIZE;
    for (std::uint32_t first = 0; first < count; first += chunk) {
      pc.count = std::min(chunk, count - first);
      pc.first = first;
      VkCommandBuffer cmd = vk::beginOneShot(ctx);
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe.pipeline);
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &dset, 0, nullptr);
      vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
      vkCmdDispatch(cmd, (pc.count + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, 1, 1);
      vk::endOneShot(ctx, cmd);
    }
  };
  if (timingRepeats > 0) {
    // The benchmarks' time per sample: the median of repeated timings of the same dispatches
    // (deterministic: they rewrite the same outputs), robust to a busy machine's spikes. Before
    // the batch, so that their sampler counters are cleared.
    const std::uint32_t m = std::min(n, timingCount);
    std::vector<double> perSample;
    for (std::uint32_t r = 0; r < timingRepeats && m > 0; ++r) {
      auto t = std::chrono::steady_clock::now();
      dispatchSamples(m);
      perSample.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count() / m);
    }
    if (!perSample.empty()) {
      std::sort(perSample.begin(), perSample.end());
      const std::size_t h = perSample.size() / 2;
      out.medianSecondsPerSample = perSample.size() % 2 ? perSample[h] : 0.5 * (perSample[h - 1] + perSample[h]);
    }
    std::memset(stats.mapped, 0, STAT_COUNT * 4);
  }
  auto t0 = std::chrono::steady_clock::now();
  dispatchSamples(n);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.wPdf.resize(n);
  out.fOk.resize(n);
  if (n) {
    std::memcpy(out.wPdf.data(), film.mapped, std::size_t(n) * 16);
    std::memcpy(out.fOk.data(), filmSq.mapped, std::size_t(n) * 16);
  }
  const std::uint32_t* s = static_cast<const std::uint32_t*>(stats.mapped);
  out.boundViolations = s[STAT_SAMPLER_BOUND_VIOLATIONS];
  out.trialFailures = s[STAT_SAMPLER_TRIAL_FAILURES];

  vk::destroyComputePipeline(ctx, pipe);
  vk::destroyGlobalsBinding(ctx, binding);
  for (vk::Buffer* b : {&measuredTables, &materials, &sets, &tabs, &nodes, &leaves, &tSets, &tTables, &tData, &film, &filmSq, &stats, &globals}) vk::destroyBuffer(ctx, *b);
  return out;
}

}  // namespace nusselt::quadtree
