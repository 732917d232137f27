// renderer.h: one render of one scene on one device, put together from its parts:
//   DeviceScene    triangles, BVH or acceleration structures, lights (device_scene.h)
//   MaterialTable  shade slots, GPU materials and the sampling plan (material_table.h)
//   Film           the accumulated image (film.h)
//   Integrator     the wavefront path tracer (path_integrator.h); others sit beside it
// and the stage globals that let every stage see all of them. The render loop (render_loop.h)
// drives it for `render`, `preview` and `merge`.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/image.h"
#include "render/device_scene.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/material_table.h"
#include "render/settings.h"
#include "scene/scene.h"
#include "vk/vk.h"

namespace nusselt {

struct SceneSummary {
  std::size_t triangles = 0;
  std::size_t materials = 0;
  std::size_t lights = 0;
  std::vector<std::string> models;  // models the render's shade stages contain ("a+b": combined)
  Traversal traversal = Traversal::Bvh;  // what traces the rays (never Auto here)
  double bvhSeconds = 0;                 // 0 and no nodes when ray queries trace
  std::uint32_t bvhNodes = 0;
  double accelerationSeconds = 0;        // acceleration structure builds (ray queries only)
  std::uint64_t accelerationBytes = 0;
  double pipelineSeconds = 0;       // creating the pipelines (lavapipe compiles at first dispatch)
  double samplerSeconds = 0;        // building (or loading) the quadtrees
  std::uint32_t samplerTrees = 0;
  std::uint64_t samplerBytes = 0;
  std::uint32_t samplerCacheHits = 0, samplerCacheMisses = 0, samplerCacheRejected = 0;
  std::uint32_t roughnessBins = 0;  // binned sampling's bins (0: none built), their bytes in binBytes
  std::uint64_t binBytes = 0;
  std::uint32_t constantBrdfs = 0;  // materials and components sampled by cosine, their exact sampler (SamplerPlanSummary)
  std::uint64_t deviceBytes = 0;
  bool guiding = false;             // path guiding (docs/guiding.md)
  std::uint32_t guideTrainSpp = 0;  // its training samples per pixel
};

// The traversal a render with `requested` uses on this context. Auto: ray queries where the
// device offers them and is a GPU; the GLSL BVH on CPU devices (lavapipe runs its ray-query
// traversal as shader code, and there the GLSL BVH measured 1.6-2.2x faster: docs/performance.md)
// and on devices without ray queries. Throws nusselt::Error for RayQuery on a context without them.
Traversal resolveTraversal(const vk::Context& ctx, Traversal requested);

class DeviceGuide;
class PathIntegrator;
class MltIntegrator;
class VegasIntegrator;

class Renderer {
 public:
  // Throws nusselt::Error (naming what does not fit) for an empty or too large image, a render
  // that does not fit the device's memory, a scene the material table refuses, or
  // Traversal::RayQuery on a context without ray queries. settings().traversal is the traversal
  // used (resolveTraversal).
  Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Traces one pass: `samples` more samples per pixel (0: samplesPerPass(); never more than
  // samplesPerPass()), sample indices from sampleOffset + samplesDone(). The image does not depend
  // on how samples are grouped into passes (guided renders: for the same samples per pass; their
  // passes end at the guide's training iterations, after which the guide is refined).
  void renderPass(std::uint32_t samples = 0);
  // Passes until samplesDone() reaches spp.
  void render(std::uint32_t spp);
  std::uint32_t samplesDone() const { return m_samples; }
  // The samples per pixel of a full pass (RenderSettings::samplesPerPass, or chosen for the device).
  std::uint32_t samplesPerPass() const { return m_samplesPerPass; }
  // The current estimate: film sum / samples; variance of the mean when withVariance. The raw
  // sums (Image::sum, Image::sumSq) are always included, for resuming and merging.
  Image image(bool withVariance = false) { return m_film->download(withVariance); }
  // Continue from a saved accumulation (Image::sum/sumSq of `spp` samples of this render's
  // settings): the next pass traces sample index sampleOffset + spp, so a resumed render equals
  // an uninterrupted one bit for bit. Throws nusselt::Error when the image does not fit.
  void restoreAccumulation(const Image& saved, std::uint32_t spp);
  // Path guiding, before restoreAccumulation of a guided render saved at `spp` samples: trains the
  // guide again on samples 0 .. min(spp, training spp) - 1, in the passes the saved render traced
  // them in, so the guide equals the one the saved render had learned (training is deterministic:
  // docs/guiding.md, "Resume"). The film and the statistics of these passes are discarded.
  // Returns the samples traced (0 for unguided renders).
  std::uint32_t retrainGuide(std::uint32_t spp);
  // Adds counts carried over from a resumed render to the statistics.
  void addStats(const RenderStats& carried) { m_integrator->addStats(carried); }
  RenderStats stats() const { return m_integrator->stats(); }
  // GPU time per stage name (camera, intersect, "shade <model>" per shade pipeline, shadow,
  // accumulate) summed over all passes so far; empty unless RenderSettings::timeStages.
  const std::vector<std::pair<std::string, double>>& stageSeconds() const { return m_integrator->stageSeconds(); }
  // Extension rays per bounce over all passes so far (Integrator::raysPerBounce).
  const std::vector<std::uint64_t>& raysPerBounce() const { return m_integrator->raysPerBounce(); }
  const SceneSummary& summary() const { return m_summary; }
  // Path guiding's state (null for unguided renders): its training reports and times.
  const DeviceGuide* guide() const { return m_guide.get(); }
  DeviceGuide* guide() { return m_guide.get(); }
  // Path guiding: the samples per pixel the guide has trained on so far (at most the training
  // spp), across resets; 0 for unguided renders.
  std::uint32_t guideTrainedSpp() const {
    return m_guide ? std::min(m_guideSamples, guideTrainingSpp(m_settings)) : 0;
  }
  // Path guiding: ends the training where it stands, at the end of an iteration (guideTrainedSpp()
  // of the form 2^k - 1, k >= 1); later passes sample the guide of that iteration without training.
  // settings().guideTrainSpp and summary().guideTrainSpp become the samples trained. False (and
  // nothing changes) elsewhere, or when training is over or the render is unguided.
  bool endTraining();
  const RenderSettings& settings() const { return m_settings; }
  // The path tracer that traces this render's paths (tests read and write its path state).
  PathIntegrator& paths() { return *m_paths; }
  // The Metropolis integrator of an mlt render (its chains' report), null otherwise.
  const MltIntegrator* mlt() const { return m_mlt; }
  // The VEGAS integrator of a vegas render (its warp's report), null otherwise.
  const VegasIntegrator* vegas() const { return m_vegas; }

  // ---- Progressive use (the preview window) ----
  // Restart accumulation: the film is cleared and the sample index goes back to 0.
  void reset();
  // Move the camera; restarts accumulation.
  void setCamera(const Camera& camera);
  // Change the lighting estimator (a run-time value of the shaders: no pipeline is rebuilt);
  // restarts accumulation. Statistics keep accumulating.
  void setLighting(LightingMode mode);
  const Camera& camera() const { return m_camera; }
  // Extra stages (e.g. the preview's display stage) run with the renderer's pipeline layout and
  // descriptor set, so they see the same Globals; Globals.display is theirs to point at a buffer.
  vk::Context& context() { return m_ctx; }
  VkPipelineLayout pipelineLayout() const { return m_globals->layout(); }
  VkDescriptorSet descriptorSet() const { return m_globals->set(); }
  void setDisplayBuffer(VkDeviceAddress address);

 private:
  void writeCamera(const Camera& camera);

  vk::Context& m_ctx;
  RenderSettings m_settings;
  SceneSummary m_summary;
  std::uint32_t m_samples = 0;
  bool m_photonsTraced = false;  // the guide's photon pre-pass ran (renderPass)
  std::uint32_t m_guideSamples = 0;  // samples the guide has seen (renderPass): not reset by reset()
  std::uint32_t m_samplesPerPass = 1;
  Camera m_camera;
  std::unique_ptr<StageGlobals> m_globals;
  std::unique_ptr<DeviceScene> m_scene;
  std::unique_ptr<MaterialTable> m_materials;
  std::unique_ptr<Film> m_film;
  std::unique_ptr<DeviceGuide> m_guide;
  std::unique_ptr<Integrator> m_integrator;
  PathIntegrator* m_paths = nullptr;  // m_integrator's path tracer
  MltIntegrator* m_mlt = nullptr;     // m_integrator when it is Metropolis
  VegasIntegrator* m_vegas = nullptr; // m_integrator when it is VEGAS
};

}  // namespace nusselt
