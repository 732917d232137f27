// vk.h: the thin Vulkan layer: free functions and plain structs (zeux/niagara style).
// The loader is opened at run time through volk, so a machine without libvulkan gets a clear
// message instead of a dynamic-linker error.
#pragma once
#include <volk.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

namespace nusselt::vk {

// Checks a VkResult; on failure throws nusselt::Error naming the result, the call, file and line.
#define VK_CHECK(expr) ::nusselt::vk::check((expr), #expr, __FILE__, __LINE__)
void check(VkResult result, const char* expr, const char* file, int line);
const char* resultName(VkResult result);

struct DeviceInfo {
  std::uint32_t index = 0;
  std::string name;
  std::string type;  // "discrete GPU", "integrated GPU", "CPU", ...
  std::uint32_t apiVersion = 0;
  std::string driverInfo;  // driver name and version (e.g. "llvmpipe Mesa 25.0.7 (LLVM 15.0.6)")
  bool suitable = false;
  std::string whyNot;  // when not suitable
  std::uint64_t deviceLocalBytes = 0;
  bool rayQuery = false;  // offers VK_KHR_ray_query and VK_KHR_acceleration_structure (rayQueryUsable)
};

struct ContextOptions {
  int deviceIndex = -1;       // -1: choose (discrete GPU first, lavapipe accepted)
  bool validation = false;    // VK_LAYER_KHRONOS_validation with synchronization validation
  std::vector<std::string> instanceExtensions;  // e.g. surface extensions for the preview
  bool swapchain = false;     // enable VK_KHR_swapchain on the device
  bool rayQuery = true;       // enable ray queries when the device offers them (Context::rayQuery)
  // Keep every compute pipeline for the context's life and hand it out again when the same stage
  // is asked for with the same specialization (createComputePipeline). Off for benchmarks that
  // time pipeline creation or set-up per render.
  bool reusePipelines = true;
};

// The pipelines and layouts a context keeps (ContextOptions::reusePipelines): lavapipe spends
// 0.2 s (one-model shade stage) to 25 s (a combined material's) turning SPIR-V into a pipeline, and
// neither a VkPipelineCache nor Mesa's disk cache skips that part (measured on Mesa 25.0.7), so a
// process that creates the same pipeline twice (tests, tools, the preview) pays it once.
struct PipelineStore {
  std::mutex mutex;
  bool enabled = false;
  // The Globals layouts (createGlobalsBinding), by push-constant size: the set layout and the
  // pipeline layout, alive until destroyContext, so that a pipeline outlives the binding it was
  // created for.
  std::map<std::uint32_t, std::pair<VkDescriptorSetLayout, VkPipelineLayout>> layouts;
  std::map<std::tuple<VkPipelineLayout, std::string, std::vector<std::uint32_t>>, std::pair<VkShaderModule, VkPipeline>> pipelines;
  std::uint64_t created = 0, reused = 0;
};

struct Context {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t queueFamily = 0;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties{};
  VkPhysicalDeviceMemoryProperties memory{};
  std::string deviceName;
  std::string driverInfo;         // e.g. "llvmpipe Mesa 25.0.7 (LLVM 15.0.6)": driver name and version
  VkDeviceSize maxAllocation = 0; // largest single memory allocation (maxMemoryAllocationSize)
  // Ray queries are enabled (VK_KHR_ray_query, VK_KHR_acceleration_structure): the device offers
  // them and ContextOptions::rayQuery asked for them. Otherwise the GLSL BVH traces all rays.
  bool rayQuery = false;
  VkDeviceSize asScratchAlignment = 0;  // minAccelerationStructureScratchOffsetAlignment
  bool validation = false;
  PipelineStore pipelineStore;
  // Validation messages (warnings and errors) seen so far; tests require zero.
  std::atomic<std::uint64_t> validationMessages{0};
};

// Whether a device offers hardware ray queries: the extensions VK_KHR_acceleration_structure (with
// VK_KHR_deferred_host_operations, which it requires) and VK_KHR_ray_query and their features
// accelerationStructure and rayQuery. NUSSELT_FAULT_NO_RAY_QUERY=1 makes every device answer no
// (tests of the fallback on machines whose driver has them).
bool rayQueryUsable(VkPhysicalDevice device);

// Lists the devices with why each one is or is not usable. Throws when there is no loader.
std::vector<DeviceInfo> listDevices();

// Creates instance, device and queue. Throws nusselt::Error with a clear message (naming the
// Debian package to install) when there is no loader, no driver or no suitable device.
void createContext(Context& ctx, const ContextOptions& options);
void destroyContext(Context& ctx);

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  VkDeviceAddress address = 0;
  void* mapped = nullptr;  // host-visible buffers only
};

// A storage buffer with a device address. hostVisible: mapped, coherent (for small per-pass
// data and readback); otherwise device-local. `what` names it in out-of-memory errors.
Buffer createBuffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags extraUsage, bool hostVisible,
                    const std::string& what);
void destroyBuffer(Context& ctx, Buffer& buffer);
// Size of the largest device-local memory heap: what one render's buffers must fit into.
VkDeviceSize deviceLocalHeapSize(const Context& ctx);
// Whether the device's memory is the host's (a CPU device such as lavapipe, or an integrated GPU),
// so that the host can read a buffer the device writes in place, mapped, rather than through a
// staging copy (which on a discrete GPU keeps device-local memory fast for the shaders).
bool sharesHostMemory(const Context& ctx);
// Copies bytes into a buffer (through a staging buffer when it is not host visible).
void uploadBuffer(Context& ctx, Buffer& buffer, const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
void downloadBuffer(Context& ctx, const Buffer& buffer, void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);

// An acceleration structure and the buffer that holds it (ray queries only).
struct AccelerationStructure {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer buffer;
  VkDeviceAddress address = 0;  // vkGetAccelerationStructureDeviceAddressKHR
};
// Builds a bottom-level structure over `triangles` non-indexed triangles whose vertices (three
// floats each, three vertices per triangle) are at `vertices`, a buffer created with
// VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR. Primitive i is triangle i;
// the geometry is opaque (no any-hit shaders: closest hits need no candidate loop). Waits for the
// build. Throws nusselt::Error naming the buffer that does not fit.
AccelerationStructure buildBottomLevel(Context& ctx, const Buffer& vertices, std::uint32_t triangles);
// Builds a top-level structure holding one instance of `bottom` with the identity transform,
// instance index 0, mask 0xff and face culling disabled (both faces hit, as the BVH's
// Moller-Trumbore test). Waits for the build.
AccelerationStructure buildTopLevel(Context& ctx, const AccelerationStructure& bottom);
void destroyAccelerationStructure(Context& ctx, AccelerationStructure& as);

// One-shot command buffer: begin, record, then endOneShot submits, waits and frees it.
VkCommandBuffer beginOneShot(Context& ctx);
void endOneShot(Context& ctx, VkCommandBuffer cmd);

// A command buffer and fence kept for repeated record-submit-wait rounds (an integrator's passes):
// beginRecording resets and begins the buffer, submitAndWait ends it, submits it and waits.
struct Recorder {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
};
Recorder createRecorder(Context& ctx);
void destroyRecorder(Context& ctx, Recorder& recorder);
VkCommandBuffer beginRecording(Context& ctx, Recorder& recorder);
void submitAndWait(Context& ctx, Recorder& recorder);

// The SPIR-V of a stage embedded at build time, by name (e.g. "shade"). Throws if unknown.
std::vector<std::uint32_t> embeddedShader(const std::string& name);

struct ComputePipeline {
  std::string name;
  VkShaderModule module = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  bool kept = false;  // owned by the context's PipelineStore: destroyComputePipeline leaves it
};
// With ContextOptions::reusePipelines and a Globals layout (createGlobalsBinding), the pipeline is
// kept by the context and the same (layout, stage, specialization) returns it again.
ComputePipeline createComputePipeline(Context& ctx, VkPipelineLayout layout, const std::string& shaderName,
                                      const std::vector<std::uint32_t>& specialization = {});
void destroyComputePipeline(Context& ctx, ComputePipeline& pipeline);

// What every wavefront stage binds: one storage buffer (the Globals) at set 0, binding 0, and
// push constants of pushBytes. Shared by the renderer and the tools that run its stages.
struct GlobalsBinding {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  bool keptLayout = false;  // setLayout and layout belong to the context's PipelineStore
};
GlobalsBinding createGlobalsBinding(Context& ctx, VkBuffer globals, std::uint32_t pushBytes);
void destroyGlobalsBinding(Context& ctx, GlobalsBinding& binding);

// A global memory barrier between compute dispatches, also making queue counts visible to the
// indirect-dispatch stage that reads them.
void computeBarrier(VkCommandBuffer cmd);

}  // namespace nusselt::vk
