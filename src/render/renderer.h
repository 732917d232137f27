// renderer.h: the wavefront path tracer. Owns the device buffers of one scene and runs sample
// passes: each pass traces one sample per pixel through the stages
//   camera -> [intersect -> shade(model) -> shadow] x (max depth + 1) -> accumulate
// with queues between the stages and indirect dispatches sized by the queues.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/image.h"
#include "scene/scene.h"
#include "vk/vk.h"

namespace nusselt {

enum class LightingMode : std::uint32_t { Mis = 0, NeeOnly = 1, BsdfOnly = 2 };
const char* lightingModeName(LightingMode mode);
// BSDF sampling strategy for non-delta models (SAMPLER_* in shaders/shared/bsdf_sampling.h).
enum class SamplerKind : std::uint32_t { Quadtree = 0, Cosine = 1, Uniform = 2, Analytic = 3, Tabulated = 4 };
const char* samplerName(SamplerKind kind);
// nullptr-safe parse: returns false for an unknown name.
bool parseSampler(const std::string& name, SamplerKind& kind);

// Random numbers: independent PCG hashes, or padded Owen-scrambled Sobol (quasi-Monte Carlo).
enum class RngMode : std::uint32_t { Pcg = 0, Qmc = 1 };
const char* rngModeName(RngMode mode);

// How a combined material chooses its component at a bounce (COMPONENTS_* in layout.h): albedo =
// the random-walk source's estimator (probability = the component's albedo for wo, the rest ends
// the walk); uniform = probability 1/n and a separate albedo roulette (for comparison).
enum class ComponentSelection : std::uint32_t { Albedo = 0, Uniform = 1 };
const char* componentSelectionName(ComponentSelection mode);
bool parseComponentSelection(const std::string& name, ComponentSelection& mode);

// Russian roulette (ROULETTE_* in layout.h): throughput = continue with the path throughput's
// largest channel from the third bounce on (the default: never amplifies a channel); albedo = the
// random-walk source's roulette by the sample's luminance albedo (for comparison).
enum class RouletteMode : std::uint32_t { Throughput = 0, Albedo = 1 };
const char* rouletteModeName(RouletteMode mode);
bool parseRouletteMode(const std::string& name, RouletteMode& mode);

struct RenderSettings {
  std::uint32_t width = 512;
  std::uint32_t height = 512;
  std::uint32_t spp = 64;
  std::uint32_t maxDepth = 8;       // pbrt's convention: 0 = emitted light only, 1 = direct light
  std::uint32_t seed = 0;
  LightingMode lighting = LightingMode::Mis;
  RngMode rng = RngMode::Pcg;
  SamplerKind sampler = SamplerKind::Quadtree;  // the generic sampler of Montes et al.
  ComponentSelection components = ComponentSelection::Albedo;  // combined materials only
  RouletteMode roulette = RouletteMode::Throughput;
  // The quadtree sampler's table counts (quadtree::QuadtreeSettings; the paper's 90 and 16 by
  // default; phi only for anisotropic sets). Fewer tables build faster (the hard-case tests use
  // 90 x 4 for the anisotropic hard sets) at the cost of a coarser grid in the outgoing direction:
  // a looser fit between tables, more variance (never bias).
  std::uint32_t samplerThetaTables = 90;
  std::uint32_t samplerPhiTables = 16;
  // Sample indices of this render start here (`--spp-offset`): a frame can be split across
  // machines into disjoint sample ranges and merged (`nusselt merge`).
  std::uint32_t sampleOffset = 0;
  // Time every stage with GPU timestamps (stageSeconds()); for benchmarks.
  bool timeStages = false;
  // Paths traced together in one chunk of a pass (path state memory ~128 bytes each).
  std::uint32_t maxPathsPerChunk = 1u << 20;
};

struct RenderStats {
  std::uint64_t rays = 0;
  std::uint64_t shadowRays = 0;
  std::uint64_t nonFiniteSamples = 0;
  std::uint64_t bvhStackOverflows = 0;
  std::uint64_t samplerBoundViolations = 0;
  std::uint64_t samplerTrialFailures = 0;
};

struct SceneSummary {
  std::size_t triangles = 0;
  std::size_t materials = 0;
  std::size_t lights = 0;
  std::vector<std::string> models;  // models the render's shade stages contain ("a+b": combined)
  double bvhSeconds = 0;
  std::uint32_t bvhNodes = 0;
  double pipelineSeconds = 0;       // creating the pipelines (lavapipe compiles at first dispatch)
  double samplerSeconds = 0;        // building (or loading) the quadtrees
  std::uint32_t samplerTrees = 0;
  std::uint64_t samplerBytes = 0;
  std::uint32_t samplerCacheHits = 0, samplerCacheMisses = 0, samplerCacheRejected = 0;
  std::uint64_t deviceBytes = 0;
};

class Renderer {
 public:
  Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Traces one more sample per pixel (sample index = samplesDone()).
  void renderPass();
  std::uint32_t samplesDone() const { return m_samples; }
  // The current estimate: film sum / samples; variance of the mean when withVariance. The raw
  // sums (Image::sum, Image::sumSq) are always included, for resuming and merging.
  Image image(bool withVariance = false);
  // Continue from a saved accumulation (Image::sum/sumSq of `spp` samples of this render's
  // settings): the next pass traces sample index sampleOffset + spp, so a resumed render equals
  // an uninterrupted one bit for bit. Throws nusselt::Error when the image does not fit.
  void restoreAccumulation(const Image& saved, std::uint32_t spp);
  // Adds counts carried over from a resumed render to the statistics.
  void addStats(const RenderStats& carried);
  RenderStats stats() const;
  // GPU time per stage name (camera, submit, intersect, shade, shadow, accumulate) summed over
  // all passes so far; empty unless RenderSettings::timeStages.
  const std::vector<std::pair<std::string, double>>& stageSeconds() const { return m_stageSeconds; }
  const SceneSummary& summary() const { return m_summary; }
  const RenderSettings& settings() const { return m_settings; }

  // ---- Progressive use (the preview window) ----
  // Restart accumulation: the film is cleared and the sample index goes back to 0.
  void reset();
  // Move the camera; restarts accumulation.
  void setCamera(const Camera& camera);
  // Change the lighting estimator (a run-time value of the shaders: no pipeline is rebuilt);
  // restarts accumulation. Statistics keep accumulating.
  void setLighting(LightingMode mode);
  const Camera& camera() const { return m_cameraState; }
  // Extra stages (e.g. the preview's display stage) run with the renderer's pipeline layout and
  // descriptor set, so they see the same Globals; Globals.display is theirs to point at a buffer.
  vk::Context& context() { return m_ctx; }
  VkPipelineLayout pipelineLayout() const { return m_pipelineLayout; }
  VkDescriptorSet descriptorSet() const { return m_set; }
  void setDisplayBuffer(VkDeviceAddress address);

 private:
  void uploadScene(const Scene& scene);
  void writeCamera(const Camera& camera);
  void createPipelines();
  void recordPass(VkCommandBuffer cmd, std::uint32_t chunkStart, std::uint32_t chunkCount);
  void dispatchSubmit(VkCommandBuffer cmd, std::uint32_t queueA, std::uint32_t zeroFirst, std::uint32_t zeroCount,
                      std::uint32_t argsFirst, std::uint32_t argsCount);

  vk::Context& m_ctx;
  RenderSettings m_settings;
  SceneSummary m_summary;
  std::uint32_t m_samples = 0;
  std::uint32_t m_capacity = 0;
  RenderStats m_totals;
  Camera m_cameraState;
  // Key of each shade slot: {0, model} (single model) or {n, model_0, ..., model_{n-1}} (combined).
  std::vector<std::vector<std::uint32_t>> m_slotKeys;

  // Host copy of the globals, rewritten before each chunk.
  std::vector<unsigned char> m_globals;
  vk::Buffer m_globalsBuffer;
  std::vector<vk::Buffer> m_buffers;  // everything else, destroyed together
  vk::Buffer* m_film = nullptr;
  vk::Buffer* m_filmSq = nullptr;
  vk::Buffer* m_queues = nullptr;
  vk::Buffer* m_args = nullptr;
  vk::Buffer* m_stats = nullptr;

  vk::GlobalsBinding m_binding;
  VkPipelineLayout m_pipelineLayout = VK_NULL_HANDLE;  // = m_binding.layout
  VkDescriptorSet m_set = VK_NULL_HANDLE;              // = m_binding.set
  vk::ComputePipeline m_camera, m_submit, m_intersect, m_shadow, m_accumulate;
  std::vector<vk::ComputePipeline> m_shade;  // one per slot
  VkCommandBuffer m_cmd = VK_NULL_HANDLE;
  VkQueryPool m_queryPool = VK_NULL_HANDLE;
  std::uint32_t m_queryCapacity = 0;
  std::vector<const char*> m_marks;  // stage name of each timestamp after the first
  std::vector<std::pair<std::string, double>> m_stageSeconds;
  void mark(VkCommandBuffer cmd, const char* stage);
  VkFence m_fence = VK_NULL_HANDLE;
};

}  // namespace nusselt
