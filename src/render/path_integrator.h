// path_integrator.h: the wavefront path tracer. Each pass traces one path per pixel through the
// stages
//   camera -> [intersect (+ the previous bounce's shadow rays) -> escape -> shade(slot)] x (max depth + 1)
//          -> accumulate
// (escape only for scenes with an environment)
// with queues between them: a queue is a count plus path ids, and every push keeps the queue's
// indirect dispatch size current, so every stage processes only live paths.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "render/integrator.h"

namespace nusselt {

class DeviceGuide;

// How the path tracer draws a path's random numbers (stage_common.glsl, "primary sample source").
struct PathOptions {
  // 0: every number hashes (pixel, sample index, dimension, seed), the default. > 0: the stages
  // are specialised with PRIMARY_SAMPLES (constant 11) and path slot i of a chunk reads its first
  // primaryDims 2-D draws from primarySamples() (draw d at shared::primarySampleIndex(i, d,
  // primaryDims), layout.h): a path is then a function of that vector (primaryDimsFor covers
  // every draw of a path).
  std::uint32_t primaryDims = 0;
  // With primaryDims: draw 0 places the camera ray anywhere on the image and the path's pixel
  // follows from it (camera constant 12, IMAGE_SAMPLES; Metropolis chains move across pixels).
  bool imageSamples = false;
  // Path slots (paths per chunk); 0: capacityFor(settings, pixels, samplesPerPass).
  std::uint32_t capacity = 0;
};

class PathIntegrator : public Integrator {
 public:
  // slotKeys: the material table's shade slots (one specialised shade pipeline each).
  // guide: path guiding's device state, or null (unguided: no guiding code in the pipelines).
  // pixels: the film's size; a pass of at most `samplesPerPass` samples per pixel traces
  // pixels x samples paths in chunks of at most `capacity`.
  PathIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                 const std::vector<std::vector<std::uint32_t>>& slotKeys, std::uint64_t pixels,
                 std::uint32_t samplesPerPass, const std::vector<std::string>& slotNames,
                 DeviceGuide* guide = nullptr, const PathOptions& options = {});
  ~PathIntegrator() override;

  // Paths traced together in one chunk of a pass of `samples` samples per pixel (one indirect
  // dispatch covers a whole queue: its group count must stay <= 65535).
  static std::uint32_t capacityFor(const RenderSettings& settings, std::uint64_t pixels, std::uint32_t samples);
  // The samples per pass a render uses: settings.samplesPerPass, or when 0 enough to put about
  // 2^18 paths in flight on a CPU device and 2^21 on a GPU, at most 64 and at most spp; never so
  // many that pixels x samples overflows 32 bits.
  static std::uint32_t samplesPerPassFor(const RenderSettings& settings, std::uint64_t pixels, bool cpuDevice);
  // Device bytes of the path state and queues (and of the primary sample vectors, primaryDims per path).
  static std::uint64_t bytesFor(std::uint32_t capacity, std::size_t slots, std::uint32_t primaryDims = 0);
  // The 2-D draws a path of at most maxDepth bounces can make: the camera's and every bounce's
  // dimensions (rng.h, rngDimension), so that with PathOptions::primaryDims = this no number hashes.
  static std::uint32_t primaryDimsFor(std::uint32_t maxDepth);

  void renderPass(std::uint32_t sampleIndex, std::uint32_t samples) override;
  // For integrators that drive the path tracer (mlt, vegas): records the tracing of path slots
  // 0 .. paths - 1 (camera and bounces, no accumulation into the film) into cmd, with the globals
  // the caller uploaded (chunkFirst 0, chunkPaths = paths, passSamples 1); after the submission
  // has completed, foldStats() adds its counters to stats().
  void recordTrace(VkCommandBuffer cmd, std::uint32_t paths) { recordPass(cmd, paths, false); }
  // For integrators that weigh the traced paths before they reach the film (vegas): records the
  // accumulate stage over path slots 0 .. paths - 1 of the chunk the globals describe.
  void recordAccumulate(VkCommandBuffer cmd, std::uint32_t paths);
  // The path guide's photon pre-pass (guided renders with settings.guidePhotons > 0): traces
  // `photons` photons from the lights (photon.comp, the shade stages in photon mode) in chunks of
  // capacity() and gives each chunk's records to the guide (DeviceGuide::consumePhotons), in photon
  // order. Its rays are not counted in stats().
  void photonPass(std::uint32_t photons);
  void foldStats();
  RenderStats stats() const override { return m_totals; }
  void addStats(const RenderStats& carried) override;
  // Forgets the counters, rays per bounce and stage times of the passes so far (a resumed guided
  // render's retraining passes, Renderer::retrainGuide).
  void clearCounters();
  const std::vector<std::pair<std::string, double>>& stageSeconds() const override { return m_stageSeconds; }
  std::uint64_t deviceBytes() const override;
  const std::vector<std::uint64_t>& raysPerBounce() const override { return m_raysPerBounce; }
  double pipelineSeconds() const { return m_pipelineSeconds; }
  // Paths per chunk (the slots of the path state).
  std::uint32_t capacity() const { return m_capacity; }
  // Per path slot: the radiance of its last traced path (rgb).
  const vk::Buffer& pathRadiance() const { return *m_pathRadiance; }
  // Per path slot: (pixel, sample index, bounces shaded (with primary samples), 0) (layout.h).
  const vk::Buffer& pathInfo() const { return *m_pathInfo; }
  // primarySampleSlots(capacity()) x PathOptions::primaryDims vec2s (only when primaryDims > 0).
  vk::Buffer& primarySamples() { return *m_primarySamples; }

 private:
  void createPipelines();
  // start: the stage that starts the paths (the camera's unless given: the photon pass's).
  void recordPass(VkCommandBuffer cmd, std::uint32_t chunkCount, bool accumulate = true,
                  const vk::ComputePipeline* start = nullptr);
  // Empties queues [first, first + count): their counts and indirect dispatch sizes.
  void emptyQueues(VkCommandBuffer cmd, std::uint32_t first, std::uint32_t count);
  // Empties the trace stage's dispatch size ARGS_TRACE0 + parity.
  void emptyTraceArgs(VkCommandBuffer cmd, std::uint32_t parity);
  void mark(VkCommandBuffer cmd, const char* stage);

  vk::Context& m_ctx;
  StageGlobals& m_globals;
  RenderSettings m_settings;
  std::vector<std::vector<std::uint32_t>> m_slotKeys;
  std::uint64_t m_pixels = 0;
  std::uint32_t m_capacity = 0;
  RenderStats m_totals;
  double m_pipelineSeconds = 0;

  std::vector<vk::Buffer> m_buffers;  // path state, destroyed together
  vk::Buffer* m_queues = nullptr;
  vk::Buffer* m_args = nullptr;
  vk::Buffer* m_stats = nullptr;

  vk::ComputePipeline m_camera, m_intersect, m_escape, m_accumulate;
  vk::ComputePipeline m_photon;  // the guide's photon pre-pass (only when it has photons)
  bool m_hasEscape = false;
  bool m_hasTextures = false;  // spec constant HAS_TEXTURES of the shade stages
  bool m_hasAlpha = false;     // spec constant HAS_ALPHA of the tracing stages
  bool m_hasBins = false;      // spec constant HAS_BINS of the shade stages (binned sampling)
  DeviceGuide* m_guide = nullptr;  // path guiding (guide.h): its records are read after every chunk
  vk::Buffer* m_pathRadiance = nullptr;
  vk::Buffer* m_pathInfo = nullptr;
  PathOptions m_options;
  vk::Buffer* m_primarySamples = nullptr;
  std::vector<vk::ComputePipeline> m_shade;  // one per slot
  vk::Recorder m_recorder;
  VkQueryPool m_queryPool = VK_NULL_HANDLE;
  std::uint32_t m_queryCapacity = 0;
  std::vector<const char*> m_marks;  // stage name of each timestamp after the first
  std::vector<std::pair<std::string, double>> m_stageSeconds;
  std::vector<std::string> m_shadeMarks;        // "shade <model>" per slot (timing marks)
  std::vector<std::uint64_t> m_raysPerBounce;  // STAT_BOUNCE_SLOTS totals
};

}  // namespace nusselt
