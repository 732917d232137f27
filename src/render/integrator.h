// integrator.h: what every integrator of the renderer offers (the wavefront path tracer today;
// Metropolis and VEGAS sit beside it). An integrator owns its device state and pipelines, reads
// the device scene and the material table through the stage globals, and adds samples to the film.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "render/settings.h"
#include "vk/vk.h"

namespace nusselt {

namespace shared {
struct Globals;
}

// The globals every stage reads (set 0, binding 0: scene, materials, film and path-state
// addresses, per-render constants) and the pipeline layout that binds them with the stages' push
// constants. The host copy is written by the renderer's parts and uploaded before each dispatch
// batch.
class StageGlobals {
 public:
  StageGlobals(vk::Context& ctx, std::uint32_t pushBytes);
  ~StageGlobals();
  StageGlobals(const StageGlobals&) = delete;
  StageGlobals& operator=(const StageGlobals&) = delete;

  shared::Globals& host() { return *m_host; }
  const shared::Globals& host() const { return *m_host; }
  // Copies the host globals into the (host-visible, coherent) device buffer.
  void upload();
  VkPipelineLayout layout() const { return m_binding.layout; }
  VkDescriptorSet set() const { return m_binding.set; }

 private:
  vk::Context& m_ctx;
  shared::Globals* m_host;
  vk::Buffer m_buffer;
  vk::GlobalsBinding m_binding;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Adds `samples` samples per pixel to the film, sample indices sampleIndex .. sampleIndex +
  // samples - 1 (the same index gives the same sample, so resumed and split renders equal
  // uninterrupted ones, whatever the samples per pass).
  virtual void renderPass(std::uint32_t sampleIndex, std::uint32_t samples) = 0;
  // Counters summed over all passes so far, plus what addStats carried over.
  virtual RenderStats stats() const = 0;
  virtual void addStats(const RenderStats& carried) = 0;
  // GPU time per stage name summed over all passes (empty unless RenderSettings::timeStages).
  virtual const std::vector<std::pair<std::string, double>>& stageSeconds() const = 0;
  // Extension rays traced per bounce (index = bounce; the last entry also counts deeper bounces),
  // summed over all passes so far.
  virtual const std::vector<std::uint64_t>& raysPerBounce() const = 0;
  // Device bytes of the integrator's own state.
  virtual std::uint64_t deviceBytes() const = 0;
};

}  // namespace nusselt
