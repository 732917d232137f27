// path_integrator.cpp: path state, queues, pipelines and the wavefront pass.
#include "render/path_integrator.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "../../shaders/shared/layout.h"
#include "../../shaders/shared/rng.h"
#include "render/guide.h"
#include "util/error.h"

namespace nusselt {

using shared::DispatchArgs;
using shared::Globals;
using shared::BounceConstants;

std::uint32_t PathIntegrator::capacityFor(const RenderSettings& settings, std::uint64_t pixels, std::uint32_t samples) {
  std::uint32_t maxChunk = std::min<std::uint32_t>(settings.maxPathsPerChunk, 65535u * WORKGROUP_SIZE);
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(pixels * std::max(1u, samples), maxChunk));
}

std::uint32_t PathIntegrator::samplesPerPassFor(const RenderSettings& settings, std::uint64_t pixels, bool cpuDevice) {
  std::uint64_t k = settings.samplesPerPass;
  if (k == 0) {
    const std::uint64_t target = cpuDevice ? (1u << 18) : (1u << 21);
    k = std::clamp<std::uint64_t>(target / std::max<std::uint64_t>(pixels, 1), 1, 64);
  }
  k = std::min<std::uint64_t>(k, std::max<std::uint32_t>(settings.spp, 1));
  // Path numbers (pixel x samples + k) are 32-bit on the device.
  k = std::min<std::uint64_t>(k, std::max<std::uint64_t>(1, 0xffffffffull / std::max<std::uint64_t>(pixels, 1)));
  return static_cast<std::uint32_t>(std::max<std::uint64_t>(k, 1));
}

std::uint64_t PathIntegrator::bytesFor(std::uint32_t capacity, std::size_t slots, std::uint32_t primaryDims) {
  // Nine vec4 arrays of path and shadow-ray state, the queues (counters and item arrays), the
  // primary sample vectors.
  return std::uint64_t(capacity) * 9 * 16 + (QUEUE_HEADER_UINTS + (QUEUE_SHADE_BASE + slots) * std::uint64_t(capacity)) * 4 +
         std::uint64_t(shared::primarySampleSlots(capacity)) * primaryDims * 8;
}

std::uint32_t PathIntegrator::primaryDimsFor(std::uint32_t maxDepth) {
  return shared::rngDimension(maxDepth, RNG_DIMS_PER_BOUNCE - 1u) + 1u;
}

PathIntegrator::PathIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                               const std::vector<std::vector<std::uint32_t>>& slotKeys, std::uint64_t pixels,
                               std::uint32_t samplesPerPass, const std::vector<std::string>& slotNames,
                               DeviceGuide* guide, const PathOptions& options)
    : m_ctx(ctx), m_globals(globals), m_settings(settings), m_slotKeys(slotKeys), m_pixels(pixels), m_guide(guide),
      m_options(options) {
  for (std::size_t s = 0; s < m_slotKeys.size(); ++s)
    m_shadeMarks.push_back("shade " + (s < slotNames.size() ? slotNames[s] : std::to_string(s)));
  m_capacity = options.capacity ? options.capacity : capacityFor(settings, pixels, samplesPerPass);
  const std::uint64_t cap = m_capacity;
  auto make = [&](VkDeviceSize bytes, const std::string& what, VkBufferUsageFlags usage = 0,
                  bool host = false) -> vk::Buffer* {
    m_buffers.push_back(vk::createBuffer(m_ctx, bytes, usage, host, what));
    return &m_buffers.back();
  };
  m_buffers.reserve(16);  // pointers into m_buffers stay valid
  Globals& g = m_globals.host();
  g.pathOrigin = make(cap * 16, "path origin")->address;
  g.pathDirection = make(cap * 16, "path direction")->address;
  g.pathThroughput = make(cap * 16, "path throughput")->address;
  // Guided renders read it after every training chunk: mapped where that costs the shaders nothing.
  m_pathRadiance = make(cap * 16, "path radiance", 0, guide && vk::sharesHostMemory(m_ctx));
  g.pathRadiance = m_pathRadiance->address;
  m_pathInfo = make(cap * 16, "path info");
  g.pathInfo = m_pathInfo->address;
  g.pathHit = make(cap * 16, "path hit")->address;
  g.shadowOrigin = make(cap * 16, "shadow ray origin")->address;
  g.shadowDirection = make(cap * 16, "shadow ray direction")->address;
  g.shadowRadiance = make(cap * 16, "shadow ray radiance")->address;
  std::uint64_t queueUints = QUEUE_HEADER_UINTS + (QUEUE_SHADE_BASE + m_slotKeys.size()) * cap;
  m_queues = make(queueUints * 4, "queue");
  g.queues = m_queues->address;
  m_args = make(ARGS_COUNT * sizeof(DispatchArgs), "dispatch arguments", VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  g.dispatchArgs = m_args->address;
  m_stats = make(STAT_BUFFER_UINTS * 4, "statistics", 0, true);
  std::memset(m_stats->mapped, 0, STAT_BUFFER_UINTS * 4);
  m_raysPerBounce.assign(STAT_BOUNCE_SLOTS, 0);
  g.stats = m_stats->address;
  // The primary sample vectors (none by default).
  if (m_options.primaryDims)
    m_primarySamples = make(std::uint64_t(shared::primarySampleSlots(m_capacity)) * m_options.primaryDims * 8, "primary samples");
  g.primaryDims = m_options.primaryDims;
  g.primarySamples = m_primarySamples ? m_primarySamples->address : 0;
  g.maxDepth = m_settings.maxDepth;
  g.pathCapacity = m_capacity;
  // The escape stage exists only for scenes with an environment (the device scene set it up).
  m_hasEscape = g.environmentLight != INVALID_INDEX;
  // Texture code only in the shade stages of a scene with textures (the material table set it).
  m_hasTextures = g.texturedScene != 0u;
  m_hasAlpha = g.alphaScene != 0u;
  // Binned sampling code only in the shade stages of a scene with binned materials (constant 12).
  m_hasBins = g.roughnessBins.count > 0u;

  auto t0 = std::chrono::steady_clock::now();
  createPipelines();
  m_pipelineSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  m_recorder = vk::createRecorder(m_ctx);
  if (settings.timeStages && m_ctx.properties.limits.timestampComputeAndGraphics) {
    m_queryCapacity = 8 + (settings.maxDepth + 1) * (8 + std::uint32_t(m_slotKeys.size()));
    VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    q.queryType = VK_QUERY_TYPE_TIMESTAMP;
    q.queryCount = m_queryCapacity;
    VK_CHECK(vkCreateQueryPool(m_ctx.device, &q, nullptr, &m_queryPool));
  }
}

PathIntegrator::~PathIntegrator() {
  VkDevice d = m_ctx.device;
  vkDeviceWaitIdle(d);
  vk::destroyRecorder(m_ctx, m_recorder);
  if (m_queryPool) vkDestroyQueryPool(d, m_queryPool, nullptr);
  for (auto* p : {&m_camera, &m_intersect, &m_escape, &m_accumulate, &m_photon})
    if (p->pipeline) vk::destroyComputePipeline(m_ctx, *p);
  for (auto& p : m_shade) vk::destroyComputePipeline(m_ctx, p);
  for (auto& b : m_buffers) vk::destroyBuffer(m_ctx, b);
}

std::uint64_t PathIntegrator::deviceBytes() const {
  std::uint64_t total = 0;
  for (const vk::Buffer& b : m_buffers) total += b.size;
  return total;
}

void PathIntegrator::mark(VkCommandBuffer cmd, const char* stage) {
  if (!m_queryPool) return;
  std::uint32_t index = static_cast<std::uint32_t>(m_marks.size()) + 1;
  if (stage == nullptr) index = 0;  // the start
  else m_marks.push_back(stage);
  if (index < m_queryCapacity) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_queryPool, index);
}

void PathIntegrator::createPipelines() {
  const VkPipelineLayout layout = m_globals.layout();
  // Constant 11 (stage_common.glsl): PRIMARY_SAMPLES, in the stages that draw a path's numbers
  // (camera, shade, escape) when the paths read primary sample vectors.
  const std::uint32_t primary = m_options.primaryDims ? 1u : 0u;
  // Constant 10 (stage_common.glsl): GUIDING, in the camera (a training pass's first records), shade
  // and escape stages of guided renders.
  const std::uint32_t guiding = m_guide ? 1u : 0u;
  if (primary || guiding)
    m_camera = vk::createComputePipeline(m_ctx, layout, "camera",
                                         {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, guiding, primary, m_options.imageSamples ? 1u : 0u});
  else m_camera = vk::createComputePipeline(m_ctx, layout, "camera");
  // The tracing stages' module for the traversal (the Renderer resolved Auto): <stage>_rq with ray
  // queries, <stage> with the GLSL BVH (CMakeLists.txt). Only the used one is compiled.
  const std::string tracing = m_settings.traversal == Traversal::RayQuery ? "_rq" : "";
  // Scenes with alpha (MASK or BLEND) test each candidate hit (HAS_ALPHA, constant 9, after
  // HAS_ENVIRONMENT and HAS_TEXTURES); the others keep the tracing stages without that code.
  std::vector<std::uint32_t> traceSpec;
  if (m_hasAlpha) traceSpec = {0u, 0u, 0u, 0u, 0u, 0u, 0u, m_hasEscape ? 1u : 0u, m_hasTextures ? 1u : 0u, 1u};
  // Modules with alpha coverage compiled in are <stage>_a (CMakeLists.txt, stage_common.glsl).
  const std::string alpha = m_hasAlpha ? "_a" : "";
  m_intersect = vk::createComputePipeline(m_ctx, layout, "intersect" + tracing + alpha, traceSpec);
  if (m_hasEscape) {
    if (m_guide || primary)
      m_escape = vk::createComputePipeline(m_ctx, layout, "escape_f",
                                           {0, 0, 0, 0, 0, 0, 0, 1u, m_hasTextures ? 1u : 0u, 0u, guiding, primary});
    else m_escape = vk::createComputePipeline(m_ctx, layout, "escape");
  }
  m_accumulate = vk::createComputePipeline(m_ctx, layout, "accumulate");
  if (m_guide && m_settings.guidePhotons > 0) m_photon = vk::createComputePipeline(m_ctx, layout, "photon");
  // Only the models (and combinations) this scene uses: one specialised shade pipeline each,
  // created on all cores (drivers compile at creation; lavapipe takes ~0.3 s per shade pipeline,
  // single-threaded). Single-model pipelines get exactly (MODEL_ID, SAMPLER); combined ones
  // (MODEL_ID unused, SAMPLER, COMPONENT_COUNT, MODEL_0..MODEL_3).
  const std::size_t slotCount = m_slotKeys.size();
  m_shade.resize(slotCount);
  std::vector<std::thread> workers;
  std::vector<std::string> errors(slotCount);
  const unsigned threads = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), unsigned(slotCount)));
  for (unsigned t = 0; t < threads; ++t)
    workers.emplace_back([&, t] {
      for (std::size_t s = t; s < slotCount; s += threads) {
        try {
          const std::vector<std::uint32_t>& key = m_slotKeys[s];
          const std::uint32_t sampler = static_cast<std::uint32_t>(m_settings.sampler);
          std::vector<std::uint32_t> spec{key[1], sampler};
          if (key[0] > 0) {
            spec.push_back(key[0]);
            for (std::uint32_t k = 0; k < MAX_COMPONENTS; ++k) spec.push_back(k < key[0] ? key[1 + k] : key[1]);
          }
          // Constant 7 (stage_common.glsl): HAS_ENVIRONMENT; ids 2..6 that a single-model module
          // lacks are ignored by Vulkan.
          spec.resize(7, 0u);
          spec.push_back(m_hasEscape ? 1u : 0u);
          spec.push_back(m_hasTextures ? 1u : 0u);  // constant 8: HAS_TEXTURES
          if (guiding || primary || m_hasBins) {
            spec.push_back(0u);       // constant 9: HAS_ALPHA (tracing stages only)
            spec.push_back(guiding);  // constant 10: GUIDING
            spec.push_back(primary);  // constant 11: PRIMARY_SAMPLES
          }
          // Constant 12: HAS_BINS (single-model quadtree modules with the scene features; binned
          // materials are textured, so the module is an _f one).
          if (m_hasBins) spec.push_back(1u);
          // One module per strategy (CMakeLists.txt): shade_sN / shade_combined_sN, and _f with the
          // texture and guiding code for the scenes and renders that use them.
          // Single-model materials under the quadtree strategy have a module per model,
          // shade_m<id>_s0 (CMakeLists.txt, SHADE_MODEL_SAMPLERS): ten times faster to create.
          // Combined materials of one or two components: the module without slots 2 and 3
          // (shade_combined_c2_sN; a test rendering two such materials: 52 s to 44 s as a process),
          // and when their models are all in models.h's lean list (glTF's, lambert, mirror), the
          // one that dispatches over those alone (shade_combined_c2l_sN).
          const bool perModel = key[0] == 0 && sampler == SAMPLER_QUADTREE;
          bool lean = key[0] > 0 && key[0] <= 2;
          for (std::uint32_t k = 0; lean && k < key[0]; ++k) lean = leanCombinationModel(key[1 + k]);
          const std::string combined = lean ? "shade_combined_c2l" : key[0] <= 2 ? "shade_combined_c2" : "shade_combined";
          const std::string module = std::string(key[0] > 0 ? combined : "shade") +
                                     (perModel ? "_m" + std::to_string(key[1]) : std::string()) + "_s" +
                                     std::to_string(sampler) + (m_hasTextures || guiding || primary ? "_f" : "");
          m_shade[s] = vk::createComputePipeline(m_ctx, layout, module, spec);
        } catch (const std::exception& e) {
          errors[s] = e.what();
        }
      }
    });
  for (auto& w : workers) w.join();
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

static_assert(QUEUE_COUNT <= QUEUE_SHARD_STRIDE && 2 * QUEUE_SHARD_STRIDE <= QUEUE_HEADER_UINTS,
              "both shards' counters fit the queue header");

void PathIntegrator::emptyQueues(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t count) {
  if (count == 0) return;
  vkCmdFillBuffer(cmd, m_queues->buffer, first * 4, count * 4, 0);
  vkCmdFillBuffer(cmd, m_queues->buffer, (QUEUE_SHARD_STRIDE + first) * 4, count * 4, 0);
  vkCmdFillBuffer(cmd, m_args->buffer, first * sizeof(DispatchArgs), count * sizeof(DispatchArgs), 0);
}

void PathIntegrator::emptyTraceArgs(VkCommandBuffer cmd, std::uint32_t parity) {
  vkCmdFillBuffer(cmd, m_args->buffer, (ARGS_TRACE0 + parity) * sizeof(DispatchArgs), sizeof(DispatchArgs), 0);
}

void PathIntegrator::recordPass(VkCommandBuffer cmd, std::uint32_t chunkCount, bool accumulate,
                                const vk::ComputePipeline* start) {
  const std::uint32_t slots = static_cast<std::uint32_t>(m_slotKeys.size());
  const VkPipelineLayout layout = m_globals.layout();
  const VkDescriptorSet set = m_globals.set();
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
  m_marks.clear();
  if (m_queryPool) vkCmdResetQueryPool(cmd, m_queryPool, 0, m_queryCapacity);
  mark(cmd, nullptr);
  // All queues start empty (counts and dispatch sizes).
  vkCmdFillBuffer(cmd, m_queues->buffer, 0, QUEUE_HEADER_UINTS * 4, 0);
  vkCmdFillBuffer(cmd, m_args->buffer, 0, VK_WHOLE_SIZE, 0);
  // The photon pre-pass's records start as "no record" (guiding_layout.h). A training pass's need
  // no clearing: the camera, shade and escape stages write every record the trainer reads
  // (guiding.h, guideRecordStart). Its test (tests/render/test_guiding.cpp) fills them with 1.0f
  // first (NUSSELT_TEST_POISON_GUIDE_RECORDS), which then must change nothing.
  if (m_guide && start == &m_photon) vkCmdFillBuffer(cmd, m_guide->records().buffer, 0, VK_WHOLE_SIZE, 0);
  else if (m_guide && m_guide->recording() && std::getenv("NUSSELT_TEST_POISON_GUIDE_RECORDS"))
    vkCmdFillBuffer(cmd, m_guide->records().buffer, 0, VK_WHOLE_SIZE, 0x3f800000u);
  vk::computeBarrier(cmd);

  BounceConstants pc{};
  auto bindAndPush = [&](const vk::ComputePipeline& p) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  };
  const std::uint32_t groups = (chunkCount + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE;
  bindAndPush(start ? *start : m_camera);
  vkCmdDispatch(cmd, groups, 1, 1);
  vk::computeBarrier(cmd);
  mark(cmd, "camera");

  // Queue sizes need no stage of their own: the pushes keep each queue's indirect dispatch size
  // current (queuePush, stage_common.glsl), and the consumers tally the rays they trace. A bounce
  // b is two dispatches: the trace stage (intersect.comp: ray queue b & 1 and the shadow rays of
  // bounce b - 1, shadow queue (b - 1) & 1) and shade. Before trace(b) the queues that bounce b - 1
  // consumed are emptied in one place: ray queue (b - 1) & 1, shadow queue b & 1, the escape and
  // shade queues, and trace(b - 1)'s dispatch size (shade(b) sizes trace(b + 1) there).
  for (std::uint32_t bounce = 0; bounce <= m_settings.maxDepth; ++bounce) {
    const std::uint32_t rayQueue = bounce & 1u;
    pc.bounce = bounce;
    if (bounce > 0) {
      static_assert(QUEUE_RAY0 == 0 && QUEUE_RAY1 == 1 && QUEUE_SHADOW0 == 2 && QUEUE_SHADOW1 == 3 &&
                    QUEUE_ESCAPE == 4 && QUEUE_SHADE_BASE == 5);
      const std::uint32_t consumedRays = rayQueue ^ 1u;
      const std::uint32_t consumedShadows = QUEUE_SHADOW0 + rayQueue;
      emptyQueues(cmd, consumedRays, 1);
      emptyQueues(cmd, consumedShadows, 1);
      emptyQueues(cmd, QUEUE_ESCAPE, QUEUE_SHADE_BASE + slots - QUEUE_ESCAPE);
      emptyTraceArgs(cmd, rayQueue ^ 1u);
      vk::computeBarrier(cmd);
    }
    if (m_queryPool) {  // timed runs only: rays and shadow rays on their own, to time them apart
      pc.traceMode = TRACE_RAYS;
      bindAndPush(m_intersect);
      vkCmdDispatchIndirect(cmd, m_args->buffer, rayQueue * sizeof(DispatchArgs));
      vk::computeBarrier(cmd);
      mark(cmd, "intersect");
      pc.traceMode = TRACE_SHADOWS;
      bindAndPush(m_intersect);
      vkCmdDispatchIndirect(cmd, m_args->buffer, (QUEUE_SHADOW0 + (rayQueue ^ 1u)) * sizeof(DispatchArgs));
      vk::computeBarrier(cmd);
      mark(cmd, "shadow");
      pc.traceMode = TRACE_BOTH;
    } else {
      bindAndPush(m_intersect);
      vkCmdDispatchIndirect(cmd, m_args->buffer, (ARGS_TRACE0 + rayQueue) * sizeof(DispatchArgs));
      vk::computeBarrier(cmd);
    }
    // escape, shade(model) <- escape and shade queues.
    if (m_hasEscape) {
      bindAndPush(m_escape);
      vkCmdDispatchIndirect(cmd, m_args->buffer, QUEUE_ESCAPE * sizeof(DispatchArgs));
      vk::computeBarrier(cmd);
      mark(cmd, "escape");
    }
    for (std::uint32_t s = 0; s < slots; ++s) {
      pc.modelSlot = s;
      bindAndPush(m_shade[s]);
      vkCmdDispatchIndirect(cmd, m_args->buffer, (QUEUE_SHADE_BASE + s) * sizeof(DispatchArgs));
      if (m_queryPool) {  // timed runs only: each shade pipeline on its own (a barrier between them)
        vk::computeBarrier(cmd);
        mark(cmd, m_shadeMarks[s].c_str());
      }
    }
    vk::computeBarrier(cmd);
    // (shade(maxDepth) queues no shadow rays: the last bounce takes no light sample.)
  }
  if (!accumulate) return;
  bindAndPush(m_accumulate);
  vkCmdDispatch(cmd, groups, 1, 1);
  vk::computeBarrier(cmd);
  mark(cmd, "accumulate");
}

void PathIntegrator::recordAccumulate(VkCommandBuffer cmd, std::uint32_t paths) {
  BounceConstants pc{};
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_accumulate.pipeline);
  vkCmdPushConstants(cmd, m_globals.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(cmd, (paths + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, 1, 1);
  vk::computeBarrier(cmd);
}

void PathIntegrator::renderPass(std::uint32_t sampleIndex, std::uint32_t samples) {
  samples = std::max(1u, samples);
  const std::uint64_t paths = m_pixels * samples;
  if (paths > 0xffffffffull) throw Error("a pass of " + std::to_string(samples) + " samples per pixel has too many paths");
  for (std::uint64_t start = 0; start < paths; start += m_capacity) {
    std::uint32_t count = static_cast<std::uint32_t>(std::min<std::uint64_t>(m_capacity, paths - start));
    Globals& g = m_globals.host();
    g.chunkFirst = static_cast<std::uint32_t>(start);
    g.chunkPaths = count;
    g.sampleIndex = sampleIndex;
    g.passSamples = samples;
    m_globals.upload();

    recordPass(vk::beginRecording(m_ctx, m_recorder), count);
    vk::submitAndWait(m_ctx, m_recorder);
    if (m_queryPool && !m_marks.empty()) {
      std::uint32_t n = std::min<std::uint32_t>(static_cast<std::uint32_t>(m_marks.size()) + 1, m_queryCapacity);
      std::vector<std::uint64_t> t(n);
      VK_CHECK(vkGetQueryPoolResults(m_ctx.device, m_queryPool, 0, n, n * 8, t.data(), 8,
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
      const double period = m_ctx.properties.limits.timestampPeriod * 1e-9;
      for (std::uint32_t i = 1; i < n; ++i) {
        const char* name = m_marks[i - 1];
        auto it = std::find_if(m_stageSeconds.begin(), m_stageSeconds.end(), [&](auto& e) { return e.first == name; });
        if (it == m_stageSeconds.end()) it = m_stageSeconds.insert(m_stageSeconds.end(), {name, 0.0});
        it->second += double(t[i] - t[i - 1]) * period;
      }
    }
    // Path guiding's training: this chunk's records and final radiance, splatted in path order.
    if (m_guide && m_guide->recording()) m_guide->consumeChunk(*m_pathRadiance, count);
    foldStats();
  }
}

void PathIntegrator::photonPass(std::uint32_t photons) {
  if (!m_guide || !m_photon.pipeline || photons == 0) return;
  Globals& g = m_globals.host();
  // The photons draw from their own streams (the seed mixed with a constant): photon p's numbers
  // are not those of pixel p's samples, which then sample the guide the photons trained.
  const std::uint32_t seed = g.seed;
  g.seed = seed ^ 0x6a09e667u;
  m_guide->setPhotons(true);
  for (std::uint32_t start = 0; start < photons; start += m_capacity) {
    const std::uint32_t count = std::min(m_capacity, photons - start);
    g.chunkFirst = start;
    g.chunkPaths = count;
    g.sampleIndex = 0;
    g.passSamples = 1;
    m_globals.upload();
    recordPass(vk::beginRecording(m_ctx, m_recorder), count, false, &m_photon);
    vk::submitAndWait(m_ctx, m_recorder);
    m_guide->consumePhotons(count);
    std::memset(m_stats->mapped, 0, STAT_BUFFER_UINTS * 4);  // not the render's rays
  }
  m_guide->setPhotons(false);
  g.seed = seed;
  m_globals.upload();
}

void PathIntegrator::foldStats() {
  // Fold the 32-bit device counters into 64-bit totals and restart them.
  std::uint32_t* s = static_cast<std::uint32_t*>(m_stats->mapped);
  m_totals.addDevice(s);
  for (std::uint32_t b = 0; b < STAT_BOUNCE_SLOTS; ++b) m_raysPerBounce[b] += s[STAT_PER_BOUNCE + b];
  std::memset(s, 0, STAT_BUFFER_UINTS * 4);
}

void PathIntegrator::addStats(const RenderStats& c) { m_totals.add(c); }

void PathIntegrator::clearCounters() {
  m_totals = RenderStats{};
  std::fill(m_raysPerBounce.begin(), m_raysPerBounce.end(), 0);
  m_stageSeconds.clear();
}

}  // namespace nusselt
