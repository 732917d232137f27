// primary_sample_integrator.h: what the integrators that drive the path tracer over primary
// sample vectors of their own choosing (Metropolis, mlt_integrator.h; VEGAS, vegas_integrator.h)
// share: the path tracer they own (it traces their vectors; its counters, stage times and rays per
// bounce are theirs), the kernels of their one shader (a specialization constant picks the kernel),
// their buffers, and one command recorder for their submissions.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "render/integrator.h"
#include "render/path_integrator.h"

namespace nusselt {

class PrimarySampleIntegrator : public Integrator {
 public:
  ~PrimarySampleIntegrator() override;
  PrimarySampleIntegrator(const PrimarySampleIntegrator&) = delete;
  PrimarySampleIntegrator& operator=(const PrimarySampleIntegrator&) = delete;

  RenderStats stats() const override { return m_paths->stats(); }
  void addStats(const RenderStats& carried) override { m_paths->addStats(carried); }
  const std::vector<std::pair<std::string, double>>& stageSeconds() const override { return m_paths->stageSeconds(); }
  const std::vector<std::uint64_t>& raysPerBounce() const override { return m_paths->raysPerBounce(); }
  // The path tracer's bytes and the buffers made with makeBuffer.
  std::uint64_t deviceBytes() const override;
  PathIntegrator& paths() { return *m_paths; }

 protected:
  PrimarySampleIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                          std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels);
  // A device buffer owned (and freed) here (at most 16 per integrator).
  vk::Buffer* makeBuffer(VkDeviceSize bytes, const std::string& what, bool hostVisible);
  // Kernels 0 .. count - 1 of the stage `shader`, kernel k with specialization constant 13 = k.
  void createKernels(const std::string& shader, std::uint32_t count);
  // Begins the recorder's command buffer with the stage globals bound.
  VkCommandBuffer begin();
  // Submits it, waits, and folds the path tracer's counters.
  void submit();
  // Records kernel k over n invocations and a barrier.
  void dispatch(VkCommandBuffer cmd, std::uint32_t kernel, std::uint32_t n);

  vk::Context& m_ctx;
  StageGlobals& m_globals;
  RenderSettings m_settings;
  std::unique_ptr<PathIntegrator> m_paths;
  std::uint64_t m_pixels = 0;

 private:
  std::vector<vk::Buffer> m_buffers;  // reserved: makeBuffer's pointers stay valid
  std::vector<vk::ComputePipeline> m_kernels;
  vk::Recorder m_recorder;
};

}  // namespace nusselt
