// primary_sample_integrator.cpp: the parts Metropolis and VEGAS share (primary_sample_integrator.h).
#include "render/primary_sample_integrator.h"

#include "../../shaders/shared/layout.h"
#include "util/error.h"

namespace nusselt {

namespace {
// More buffers than any integrator makes; makeBuffer refuses the next (pointers must stay valid).
constexpr std::size_t kMaxBuffers = 16;
}  // namespace

PrimarySampleIntegrator::PrimarySampleIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                                                 std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels)
    : m_ctx(ctx), m_globals(globals), m_settings(settings), m_paths(std::move(paths)), m_pixels(pixels) {
  m_buffers.reserve(kMaxBuffers);
  m_recorder = vk::createRecorder(m_ctx);
}

PrimarySampleIntegrator::~PrimarySampleIntegrator() {
  vkDeviceWaitIdle(m_ctx.device);
  vk::destroyRecorder(m_ctx, m_recorder);
  for (auto& p : m_kernels) vk::destroyComputePipeline(m_ctx, p);
  for (auto& b : m_buffers) vk::destroyBuffer(m_ctx, b);
}

std::uint64_t PrimarySampleIntegrator::deviceBytes() const {
  std::uint64_t total = m_paths->deviceBytes();
  for (const vk::Buffer& b : m_buffers) total += b.size;
  return total;
}

vk::Buffer* PrimarySampleIntegrator::makeBuffer(VkDeviceSize bytes, const std::string& what, bool hostVisible) {
  if (m_buffers.size() == kMaxBuffers) throw Error("internal: an integrator made more than 16 buffers");
  m_buffers.push_back(vk::createBuffer(m_ctx, bytes, 0, hostVisible, what));
  return &m_buffers.back();
}

void PrimarySampleIntegrator::createKernels(const std::string& shader, std::uint32_t count) {
  for (std::uint32_t k = 0; k < count; ++k) {
    std::vector<std::uint32_t> spec(14, 0u);
    spec[13] = k;  // constant 13: the kernel (MLT_KERNEL, VEGAS_KERNEL)
    m_kernels.push_back(vk::createComputePipeline(m_ctx, m_globals.layout(), shader, spec));
  }
}

VkCommandBuffer PrimarySampleIntegrator::begin() {
  VkCommandBuffer cmd = vk::beginRecording(m_ctx, m_recorder);
  const VkDescriptorSet set = m_globals.set();
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_globals.layout(), 0, 1, &set, 0, nullptr);
  return cmd;
}

void PrimarySampleIntegrator::submit() {
  vk::submitAndWait(m_ctx, m_recorder);
  m_paths->foldStats();
}

void PrimarySampleIntegrator::dispatch(VkCommandBuffer cmd, std::uint32_t kernel, std::uint32_t n) {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_kernels[kernel].pipeline);
  vkCmdDispatch(cmd, (n + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, 1, 1);
  vk::computeBarrier(cmd);
}

}  // namespace nusselt
