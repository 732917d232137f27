// vk.cpp: instance, device, buffers and compute pipelines.
#include "vk/vk.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "util/error.h"

namespace nusselt {
struct EmbeddedShader {
  const char* name;
  const std::uint32_t* code;
  std::size_t bytes;
};
extern const EmbeddedShader kEmbeddedShaders[];
extern const std::size_t kEmbeddedShaderCount;
}  // namespace nusselt

namespace nusselt::vk {
namespace {

const char* kInstallHint =
    "install a Vulkan loader and driver: apt-get install libvulkan1 mesa-vulkan-drivers "
    "(mesa-vulkan-drivers provides lavapipe, a CPU device that is enough to render)";

// volk keeps one global table of instance and device functions, loaded for the context created
// last. A process may hold several contexts (the tests: a shared one plus one without ray
// queries); when the newest is destroyed, the table goes back to the newest that is still alive,
// so its extension functions (acceleration structures) are not left pointing at a dead device.
std::vector<Context*> g_liveContexts;

void initLoader() {
  static bool done = false;
  if (done) return;
  if (volkInitialize() != VK_SUCCESS)
    throw Error("no Vulkan loader (libvulkan.so.1) found: " + std::string(kInstallHint));
  done = true;
}

const char* deviceTypeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) return VK_FALSE;
  auto* ctx = static_cast<Context*>(user);
  ctx->validationMessages.fetch_add(1);
  std::fprintf(stderr, "validation %s: %s\n",
               severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;
}

bool hasLayer(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

VkInstance createInstance(Context* ctx, bool validation, const std::vector<std::string>& extraExtensions,
                          VkDebugUtilsMessengerEXT* messenger) {
  initLoader();
  std::uint32_t version = 0;
  if (vkEnumerateInstanceVersion) vkEnumerateInstanceVersion(&version);
  if (version < VK_API_VERSION_1_2)
    throw Error("the Vulkan loader supports only Vulkan " + std::to_string(VK_API_VERSION_MAJOR(version)) +
                "." + std::to_string(VK_API_VERSION_MINOR(version)) + "; nusselt needs 1.2: " + kInstallHint);

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "nusselt";
  app.applicationVersion = VK_MAKE_VERSION(0, 1, 0);
  app.pEngineName = "nusselt";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  for (auto& e : extraExtensions) extensions.push_back(e.c_str());
  VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  VkDebugUtilsMessengerCreateInfoEXT dbg{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  dbg.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = debugCallback;
  dbg.pUserData = ctx;

  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  if (validation) {
    if (!hasLayer("VK_LAYER_KHRONOS_validation"))
      throw Error("validation requested but VK_LAYER_KHRONOS_validation is not installed: apt-get install "
                  "vulkan-validationlayers");
    layers.push_back("VK_LAYER_KHRONOS_validation");
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    features.pNext = &dbg;
    ci.pNext = &features;
  }
  ci.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw Error("no Vulkan driver found (vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER): " + std::string(kInstallHint));
  VK_CHECK(r);
  volkLoadInstanceOnly(instance);
  if (validation && messenger) VK_CHECK(vkCreateDebugUtilsMessengerEXT(instance, &dbg, nullptr, messenger));
  return instance;
}

DeviceInfo describe(VkPhysicalDevice pd, std::uint32_t index, std::uint32_t* queueFamily) {
  DeviceInfo info;
  info.index = index;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(pd, &props);
  info.name = props.deviceName;
  info.type = deviceTypeName(props.deviceType);
  info.apiVersion = props.apiVersion;
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(pd, &mem);
  for (std::uint32_t h = 0; h < mem.memoryHeapCount; ++h)
    if (mem.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) info.deviceLocalBytes += mem.memoryHeaps[h].size;
  if (props.apiVersion < VK_API_VERSION_1_2) {
    info.whyNot = "supports only Vulkan " + std::to_string(VK_API_VERSION_MAJOR(props.apiVersion)) + "." +
                  std::to_string(VK_API_VERSION_MINOR(props.apiVersion)) + " (1.2 needed)";
    return info;
  }
  std::uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> qs(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &nq, qs.data());
  bool found = false;
  for (std::uint32_t q = 0; q < nq && !found; ++q)
    if (qs[q].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      if (queueFamily) *queueFamily = q;
      found = true;
    }
  if (!found) {
    info.whyNot = "has no compute queue";
    return info;
  }
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(pd, &f2);
  if (!f12.bufferDeviceAddress) {
    info.whyNot = "lacks bufferDeviceAddress";
    return info;
  }
  if (!f12.scalarBlockLayout) {
    info.whyNot = "lacks scalarBlockLayout";
    return info;
  }
  if (!f2.features.shaderInt64) {
    info.whyNot = "lacks shaderInt64";
    return info;
  }
  VkPhysicalDeviceSubgroupProperties sub{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  sub.pNext = &driver;
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &sub;
  vkGetPhysicalDeviceProperties2(pd, &p2);
  info.driverInfo = std::string(driver.driverName) + (driver.driverInfo[0] ? std::string(" ") + driver.driverInfo : "");
  // Ballot, vote and shuffle: the queues' allocation, the quadtree sampler, the BVH's shared leaves.
  VkSubgroupFeatureFlags need = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT |
                                VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
  if (!(sub.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) || (sub.supportedOperations & need) != need) {
    info.whyNot = "lacks subgroup ballot, vote or shuffle in compute shaders";
    return info;
  }
  info.suitable = true;
  info.rayQuery = rayQueryUsable(pd);
  return info;
}

std::uint32_t findMemoryType(const Context& ctx, std::uint32_t bits, VkMemoryPropertyFlags flags) {
  for (std::uint32_t i = 0; i < ctx.memory.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (ctx.memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
  return UINT32_MAX;
}

std::string formatBytes(VkDeviceSize bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f MiB", bytes / (1024.0 * 1024.0));
  return buf;
}

bool hasDeviceExtension(const std::vector<VkExtensionProperties>& all, const char* name) {
  for (const VkExtensionProperties& e : all)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

}  // namespace

bool rayQueryUsable(VkPhysicalDevice pd) {
  const char* fault = std::getenv("NUSSELT_FAULT_NO_RAY_QUERY");
  if (fault && *fault && std::strcmp(fault, "0") != 0) return false;
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> all(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, all.data());
  for (const char* e : {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                        VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME})
    if (!hasDeviceExtension(all, e)) return false;
  VkPhysicalDeviceRayQueryFeaturesKHR rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  as.pNext = &rq;
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &as;
  vkGetPhysicalDeviceFeatures2(pd, &f2);
  return as.accelerationStructure && rq.rayQuery;
}

const char* resultName(VkResult r) {
  switch (r) {
#define NAME(x) case x: return #x;
    NAME(VK_SUCCESS) NAME(VK_NOT_READY) NAME(VK_TIMEOUT) NAME(VK_EVENT_SET) NAME(VK_EVENT_RESET)
    NAME(VK_INCOMPLETE) NAME(VK_ERROR_OUT_OF_HOST_MEMORY) NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    NAME(VK_ERROR_INITIALIZATION_FAILED) NAME(VK_ERROR_DEVICE_LOST) NAME(VK_ERROR_MEMORY_MAP_FAILED)
    NAME(VK_ERROR_LAYER_NOT_PRESENT) NAME(VK_ERROR_EXTENSION_NOT_PRESENT) NAME(VK_ERROR_FEATURE_NOT_PRESENT)
    NAME(VK_ERROR_INCOMPATIBLE_DRIVER) NAME(VK_ERROR_TOO_MANY_OBJECTS) NAME(VK_ERROR_FORMAT_NOT_SUPPORTED)
    NAME(VK_ERROR_FRAGMENTED_POOL) NAME(VK_ERROR_OUT_OF_POOL_MEMORY) NAME(VK_ERROR_SURFACE_LOST_KHR)
    NAME(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR) NAME(VK_SUBOPTIMAL_KHR) NAME(VK_ERROR_OUT_OF_DATE_KHR)
    NAME(VK_ERROR_INVALID_SHADER_NV) NAME(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
#undef NAME
    default: return "VK_RESULT_UNKNOWN";
  }
}

void check(VkResult result, const char* expr, const char* file, int line) {
  if (result == VK_SUCCESS) return;
  std::string msg = std::string("Vulkan call failed: ") + resultName(result) + " from " + expr + " (" + file + ":" +
                    std::to_string(line) + ")";
  if (result == VK_ERROR_DEVICE_LOST) msg += "; the device was lost (driver reset or crash)";
  throw Error(msg);
}

std::vector<DeviceInfo> listDevices() {
  VkInstance instance = createInstance(nullptr, false, {}, nullptr);
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(instance, &n, pds.data());
  std::vector<DeviceInfo> out;
  for (std::uint32_t i = 0; i < n; ++i) out.push_back(describe(pds[i], i, nullptr));
  vkDestroyInstance(instance, nullptr);
  return out;
}

void createContext(Context& ctx, const ContextOptions& options) {
  ctx.validation = options.validation;
  ctx.instance = createInstance(&ctx, options.validation, options.instanceExtensions, &ctx.messenger);

  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(ctx.instance, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(ctx.instance, &n, pds.data());
  if (n == 0) throw Error("no Vulkan device found: " + std::string(kInstallHint));

  int chosen = -1;
  std::uint32_t family = 0;
  if (options.deviceIndex >= 0) {
    if (options.deviceIndex >= static_cast<int>(n))
      throw Error("--device " + std::to_string(options.deviceIndex) + ": there are only " + std::to_string(n) +
                  " devices (see `nusselt devices`)");
    DeviceInfo info = describe(pds[options.deviceIndex], options.deviceIndex, &family);
    if (!info.suitable)
      throw Error("--device " + std::to_string(options.deviceIndex) + " (" + info.name + ") cannot be used: " +
                  info.whyNot);
    chosen = options.deviceIndex;
  } else {
    int bestRank = 99;
    std::string reasons;
    for (std::uint32_t i = 0; i < n; ++i) {
      std::uint32_t q = 0;
      DeviceInfo info = describe(pds[i], i, &q);
      if (!info.suitable) {
        reasons += "\n  " + std::to_string(i) + ": " + info.name + ": " + info.whyNot;
        continue;
      }
      VkPhysicalDeviceProperties props;
      vkGetPhysicalDeviceProperties(pds[i], &props);
      int rank = typeRank(props.deviceType);
      if (rank < bestRank) {
        bestRank = rank;
        chosen = static_cast<int>(i);
        family = q;
      }
    }
    if (chosen < 0) throw Error("no suitable Vulkan device:" + reasons);
  }
  ctx.physical = pds[chosen];
  ctx.queueFamily = family;
  vkGetPhysicalDeviceProperties(ctx.physical, &ctx.properties);
  vkGetPhysicalDeviceMemoryProperties(ctx.physical, &ctx.memory);
  ctx.deviceName = ctx.properties.deviceName;
  {
    // The driver (lavapipe's Mesa version matters: 25 is 3-4x faster than 22.3) and the largest
    // single allocation (2 GiB on lavapipe, which crashes instead of failing when asked for more).
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceMaintenance3Properties m3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
    m3.pNext = &driver;
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &m3;
    vkGetPhysicalDeviceProperties2(ctx.physical, &p2);
    ctx.driverInfo = std::string(driver.driverName) + (driver.driverInfo[0] ? std::string(" ") + driver.driverInfo : "");
    ctx.maxAllocation = m3.maxMemoryAllocationSize;
  }

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.bufferDeviceAddress = VK_TRUE;
  f12.scalarBlockLayout = VK_TRUE;
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.features.shaderInt64 = VK_TRUE;
  f2.pNext = &f12;
  std::vector<const char*> extensions;
  if (options.swapchain) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  // Ray queries only where offered (Mesa 25's lavapipe and current GPU drivers; not Mesa 22.3):
  // otherwise the device is created as before and the GLSL BVH traces every ray. Acceleration
  // structure builds take scratch and instance buffers by device address (bufferDeviceAddress,
  // enabled above for every device).
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asFeatures{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceRayQueryFeaturesKHR rqFeatures{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  ctx.rayQuery = options.rayQuery && rayQueryUsable(ctx.physical);
  if (ctx.rayQuery) {
    extensions.push_back(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
    extensions.push_back(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
    extensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    asFeatures.accelerationStructure = VK_TRUE;
    rqFeatures.rayQuery = VK_TRUE;
    asFeatures.pNext = &rqFeatures;
    f12.pNext = &asFeatures;
    VkPhysicalDeviceAccelerationStructurePropertiesKHR asProps{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    p2.pNext = &asProps;
    vkGetPhysicalDeviceProperties2(ctx.physical, &p2);
    ctx.asScratchAlignment = std::max<VkDeviceSize>(asProps.minAccelerationStructureScratchOffsetAlignment, 1);
  }
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &f2;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  dci.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(vkCreateDevice(ctx.physical, &dci, nullptr, &ctx.device));
  volkLoadDevice(ctx.device);
  g_liveContexts.push_back(&ctx);
  vkGetDeviceQueue(ctx.device, family, 0, &ctx.queue);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = family;
  VK_CHECK(vkCreateCommandPool(ctx.device, &pci, nullptr, &ctx.commandPool));
  ctx.pipelineStore.enabled = options.reusePipelines;
}

void destroyContext(Context& ctx) {
  if (ctx.device) {
    vkDeviceWaitIdle(ctx.device);
    if (ctx.commandPool) vkDestroyCommandPool(ctx.device, ctx.commandPool, nullptr);
    {
      PipelineStore& st = ctx.pipelineStore;
      std::lock_guard<std::mutex> lock(st.mutex);
      for (auto& [key, mp] : st.pipelines) {
        vkDestroyPipeline(ctx.device, mp.second, nullptr);
        vkDestroyShaderModule(ctx.device, mp.first, nullptr);
      }
      for (auto& [bytes, l] : st.layouts) {
        vkDestroyPipelineLayout(ctx.device, l.second, nullptr);
        vkDestroyDescriptorSetLayout(ctx.device, l.first, nullptr);
      }
      st.pipelines.clear();
      st.layouts.clear();
    }
    vkDestroyDevice(ctx.device, nullptr);
  }
  if (ctx.messenger) vkDestroyDebugUtilsMessengerEXT(ctx.instance, ctx.messenger, nullptr);
  if (ctx.instance) vkDestroyInstance(ctx.instance, nullptr);
  ctx.device = VK_NULL_HANDLE;
  ctx.instance = VK_NULL_HANDLE;
  ctx.messenger = VK_NULL_HANDLE;
  ctx.commandPool = VK_NULL_HANDLE;
  const bool wasCurrent = !g_liveContexts.empty() && g_liveContexts.back() == &ctx;
  g_liveContexts.erase(std::remove(g_liveContexts.begin(), g_liveContexts.end(), &ctx), g_liveContexts.end());
  if (wasCurrent && !g_liveContexts.empty()) {
    volkLoadInstanceOnly(g_liveContexts.back()->instance);
    volkLoadDevice(g_liveContexts.back()->device);
  }
}

Buffer createBuffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags extraUsage, bool hostVisible,
                    const std::string& what) {
  Buffer b;
  b.size = size < 16 ? 16 : size;
  // Refuse what the device cannot allocate in one piece, before asking: lavapipe (Mesa 25) crashes
  // later instead of failing the allocation.
  if (ctx.maxAllocation && b.size > ctx.maxAllocation)
    throw Error("the " + what + " buffer needs " + formatBytes(b.size) + " of device memory in one allocation, more "
                "than " + ctx.deviceName + " allows (" + formatBytes(ctx.maxAllocation) + ")");
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = b.size;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
              VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | extraUsage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult r = vkCreateBuffer(ctx.device, &bci, nullptr, &b.buffer);
  if (r != VK_SUCCESS)
    throw Error("cannot create the " + what + " buffer (" + formatBytes(b.size) + "): " + resultName(r));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device, b.buffer, &req);
  VkMemoryPropertyFlags flags = hostVisible ? (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)
                                            : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  std::uint32_t type = findMemoryType(ctx, req.memoryTypeBits, flags);
  if (type == UINT32_MAX) {
    vkDestroyBuffer(ctx.device, b.buffer, nullptr);
    throw Error("no suitable memory type for the " + what + " buffer");
  }
  VkMemoryAllocateFlagsInfo flagsInfo{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flagsInfo.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.pNext = &flagsInfo;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  r = vkAllocateMemory(ctx.device, &ai, nullptr, &b.memory);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(ctx.device, b.buffer, nullptr);
    throw Error("out of device memory allocating the " + what + " buffer (" + formatBytes(req.size) +
                "): " + resultName(r));
  }
  VK_CHECK(vkBindBufferMemory(ctx.device, b.buffer, b.memory, 0));
  if (hostVisible) VK_CHECK(vkMapMemory(ctx.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  VkBufferDeviceAddressInfo addr{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  addr.buffer = b.buffer;
  b.address = vkGetBufferDeviceAddress(ctx.device, &addr);
  return b;
}

VkDeviceSize deviceLocalHeapSize(const Context& ctx) {
  VkDeviceSize best = 0;
  for (std::uint32_t h = 0; h < ctx.memory.memoryHeapCount; ++h)
    if (ctx.memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      best = std::max(best, ctx.memory.memoryHeaps[h].size);
  return best;
}

bool sharesHostMemory(const Context& ctx) {
  return ctx.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ||
         ctx.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
}

void destroyBuffer(Context& ctx, Buffer& b) {
  if (b.buffer) vkDestroyBuffer(ctx.device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(ctx.device, b.memory, nullptr);
  b = Buffer{};
}

namespace {

// Creates the structure's buffer (device-local, with a device address) and handle for `size`
// bytes. `what` names it in out-of-memory errors.
AccelerationStructure createAccelerationStructure(Context& ctx, VkAccelerationStructureTypeKHR type, VkDeviceSize size,
                                                  const std::string& what) {
  AccelerationStructure as;
  as.buffer = createBuffer(ctx, size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, false, what);
  VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  ci.buffer = as.buffer.buffer;
  ci.size = size;
  ci.type = type;
  VkResult r = vkCreateAccelerationStructureKHR(ctx.device, &ci, nullptr, &as.handle);
  if (r != VK_SUCCESS) {
    destroyBuffer(ctx, as.buffer);
    throw Error("cannot create the " + what + " (" + formatBytes(size) + "): " + resultName(r));
  }
  VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  ai.accelerationStructure = as.handle;
  as.address = vkGetAccelerationStructureDeviceAddressKHR(ctx.device, &ai);
  return as;
}

// Sizes, allocation and the build of one structure from one geometry; waits for it. The scratch
// buffer is padded by the device's scratch alignment so that an aligned address lies inside it.
AccelerationStructure buildOne(Context& ctx, VkAccelerationStructureTypeKHR type,
                               const VkAccelerationStructureGeometryKHR& geometry, std::uint32_t primitives,
                               const std::string& what) {
  VkAccelerationStructureBuildGeometryInfoKHR build{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  build.type = type;
  // Built once per scene and traced billions of times: trace speed over build speed.
  build.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  build.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  build.geometryCount = 1;
  build.pGeometries = &geometry;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  vkGetAccelerationStructureBuildSizesKHR(ctx.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &build,
                                          &primitives, &sizes);
  AccelerationStructure as = createAccelerationStructure(ctx, type, sizes.accelerationStructureSize, what);
  Buffer scratch;
  try {
    scratch = createBuffer(ctx, sizes.buildScratchSize + ctx.asScratchAlignment, 0, false, what + " build scratch");
  } catch (...) {
    destroyAccelerationStructure(ctx, as);
    throw;
  }
  const VkDeviceSize align = ctx.asScratchAlignment ? ctx.asScratchAlignment : 1;
  build.dstAccelerationStructure = as.handle;
  build.scratchData.deviceAddress = (scratch.address + align - 1) / align * align;
  VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  VkCommandBuffer cmd = beginOneShot(ctx);
  // The inputs were uploaded by earlier copies (vertices, instances) or built by an earlier build
  // (the bottom level under a top level): make them visible to this build.
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  before.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &before, 0, nullptr, 0, nullptr);
  vkCmdBuildAccelerationStructuresKHR(cmd, 1, &build, &ranges);
  // The structure is read by later builds and by the compute stages' ray queries (later
  // submissions: a barrier's second scope extends to them in submission order).
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  after.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                       1, &after, 0, nullptr, 0, nullptr);
  try {
    endOneShot(ctx, cmd);
  } catch (...) {
    destroyBuffer(ctx, scratch);
    destroyAccelerationStructure(ctx, as);
    throw;
  }
  destroyBuffer(ctx, scratch);
  return as;
}

}  // namespace

AccelerationStructure buildBottomLevel(Context& ctx, const Buffer& vertices, std::uint32_t triangles) {
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  // Opaque: no candidate is handed to the shader, the traversal commits the closest hit itself.
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkAccelerationStructureGeometryTrianglesDataKHR& tri = geometry.geometry.triangles;
  tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  tri.vertexData.deviceAddress = vertices.address;
  tri.vertexStride = 3 * sizeof(float);
  tri.maxVertex = triangles * 3 - 1;
  tri.indexType = VK_INDEX_TYPE_NONE_KHR;
  return buildOne(ctx, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, geometry, triangles,
                  "bottom-level acceleration structure");
}

AccelerationStructure buildTopLevel(Context& ctx, const AccelerationStructure& bottom) {
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.instanceCustomIndex = 0;
  instance.mask = 0xff;
  instance.instanceShaderBindingTableRecordOffset = 0;
  instance.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
  instance.accelerationStructureReference = bottom.address;
  Buffer instances = createBuffer(ctx, sizeof instance,
                                  VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, false,
                                  "acceleration structure instance");
  AccelerationStructure as;
  try {
    uploadBuffer(ctx, instances, &instance, sizeof instance);
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    geometry.geometry.instances.arrayOfPointers = VK_FALSE;
    geometry.geometry.instances.data.deviceAddress = instances.address;
    as = buildOne(ctx, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, geometry, 1, "top-level acceleration structure");
  } catch (...) {
    destroyBuffer(ctx, instances);
    throw;
  }
  destroyBuffer(ctx, instances);
  return as;
}

void destroyAccelerationStructure(Context& ctx, AccelerationStructure& as) {
  if (as.handle) vkDestroyAccelerationStructureKHR(ctx.device, as.handle, nullptr);
  destroyBuffer(ctx, as.buffer);
  as = AccelerationStructure{};
}

namespace {

VkCommandBuffer allocateCommandBuffer(Context& ctx) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = ctx.commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  VK_CHECK(vkAllocateCommandBuffers(ctx.device, &ai, &cmd));
  return cmd;
}

void beginCommandBuffer(VkCommandBuffer cmd) {
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
}

VkFence createFence(Context& ctx) {
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  VK_CHECK(vkCreateFence(ctx.device, &fci, nullptr, &fence));
  return fence;
}

// Ends cmd, submits it with the (unsignalled) fence and waits for it.
VkResult endSubmitWait(Context& ctx, VkCommandBuffer cmd, VkFence fence) {
  VkResult r = vkEndCommandBuffer(cmd);
  if (r != VK_SUCCESS) return r;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  r = vkQueueSubmit(ctx.queue, 1, &si, fence);
  if (r == VK_SUCCESS) r = vkWaitForFences(ctx.device, 1, &fence, VK_TRUE, UINT64_MAX);
  return r;
}

}  // namespace

VkCommandBuffer beginOneShot(Context& ctx) {
  VkCommandBuffer cmd = allocateCommandBuffer(ctx);
  beginCommandBuffer(cmd);
  return cmd;
}

void endOneShot(Context& ctx, VkCommandBuffer cmd) {
  VkFence fence = createFence(ctx);
  VkResult r = endSubmitWait(ctx, cmd, fence);
  vkDestroyFence(ctx.device, fence, nullptr);
  vkFreeCommandBuffers(ctx.device, ctx.commandPool, 1, &cmd);
  VK_CHECK(r);
}

Recorder createRecorder(Context& ctx) {
  Recorder r;
  r.cmd = allocateCommandBuffer(ctx);
  r.fence = createFence(ctx);
  return r;
}

void destroyRecorder(Context& ctx, Recorder& recorder) {
  if (recorder.fence) vkDestroyFence(ctx.device, recorder.fence, nullptr);
  if (recorder.cmd) vkFreeCommandBuffers(ctx.device, ctx.commandPool, 1, &recorder.cmd);
  recorder = Recorder();
}

VkCommandBuffer beginRecording(Context& ctx, Recorder& recorder) {
  (void)ctx;
  VK_CHECK(vkResetCommandBuffer(recorder.cmd, 0));
  beginCommandBuffer(recorder.cmd);
  return recorder.cmd;
}

void submitAndWait(Context& ctx, Recorder& recorder) {
  VK_CHECK(vkResetFences(ctx.device, 1, &recorder.fence));
  VK_CHECK(endSubmitWait(ctx, recorder.cmd, recorder.fence));
}

void uploadBuffer(Context& ctx, Buffer& buffer, const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (bytes == 0) return;
  if (buffer.mapped) {
    std::memcpy(static_cast<char*>(buffer.mapped) + offset, data, bytes);
    return;
  }
  Buffer staging = createBuffer(ctx, bytes, 0, true, "staging");
  std::memcpy(staging.mapped, data, bytes);
  VkCommandBuffer cmd = beginOneShot(ctx);
  VkBufferCopy copy{0, offset, bytes};
  vkCmdCopyBuffer(cmd, staging.buffer, buffer.buffer, 1, &copy);
  endOneShot(ctx, cmd);
  destroyBuffer(ctx, staging);
}

void downloadBuffer(Context& ctx, const Buffer& buffer, void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  if (bytes == 0) return;
  if (buffer.mapped) {
    std::memcpy(data, static_cast<const char*>(buffer.mapped) + offset, bytes);
    return;
  }
  Buffer staging = createBuffer(ctx, bytes, 0, true, "readback");
  VkCommandBuffer cmd = beginOneShot(ctx);
  VkBufferCopy copy{offset, 0, bytes};
  vkCmdCopyBuffer(cmd, buffer.buffer, staging.buffer, 1, &copy);
  endOneShot(ctx, cmd);
  std::memcpy(data, staging.mapped, bytes);
  destroyBuffer(ctx, staging);
}

std::vector<std::uint32_t> embeddedShader(const std::string& name) {
  for (std::size_t i = 0; i < kEmbeddedShaderCount; ++i)
    if (name == kEmbeddedShaders[i].name)
      return std::vector<std::uint32_t>(kEmbeddedShaders[i].code, kEmbeddedShaders[i].code + kEmbeddedShaders[i].bytes / 4);
  throw Error("internal: no embedded shader named \"" + name + "\"");
}

namespace {
ComputePipeline buildComputePipeline(Context& ctx, VkPipelineLayout layout, const std::string& shaderName,
                                     const std::vector<std::uint32_t>& specialization) {
  ComputePipeline p;
  p.name = shaderName;
  std::vector<std::uint32_t> code = embeddedShader(shaderName);
  VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smci.codeSize = code.size() * 4;
  smci.pCode = code.data();
  VK_CHECK(vkCreateShaderModule(ctx.device, &smci, nullptr, &p.module));
  std::vector<VkSpecializationMapEntry> entries;
  for (std::uint32_t i = 0; i < specialization.size(); ++i) entries.push_back({i, i * 4u, 4u});
  VkSpecializationInfo spec{};
  spec.mapEntryCount = static_cast<std::uint32_t>(entries.size());
  spec.pMapEntries = entries.data();
  spec.dataSize = specialization.size() * 4;
  spec.pData = specialization.data();
  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = p.module;
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = specialization.empty() ? nullptr : &spec;
  ci.layout = layout;
  VkResult r = vkCreateComputePipelines(ctx.device, VK_NULL_HANDLE, 1, &ci, nullptr, &p.pipeline);
  if (r != VK_SUCCESS) vkDestroyShaderModule(ctx.device, p.module, nullptr);
  VK_CHECK(r);
  return p;
}
}  // namespace

ComputePipeline createComputePipeline(Context& ctx, VkPipelineLayout layout, const std::string& shaderName,
                                      const std::vector<std::uint32_t>& specialization) {
  PipelineStore& st = ctx.pipelineStore;
  bool keep = false;
  if (st.enabled) {
    std::lock_guard<std::mutex> lock(st.mutex);
    for (const auto& [bytes, l] : st.layouts) keep = keep || l.second == layout;
    if (keep) {
      auto it = st.pipelines.find({layout, shaderName, specialization});
      if (it != st.pipelines.end()) {
        ++st.reused;
        return ComputePipeline{shaderName, it->second.first, it->second.second, true};
      }
    }
  }
  // Created outside the lock (seconds for a large stage); a second thread asking for the same
  // pipeline meanwhile builds its own and the first one stored wins.
  ComputePipeline p = buildComputePipeline(ctx, layout, shaderName, specialization);
  if (!keep) return p;
  std::lock_guard<std::mutex> lock(st.mutex);
  ++st.created;
  auto [it, inserted] = st.pipelines.emplace(std::make_tuple(layout, shaderName, specialization), std::make_pair(p.module, p.pipeline));
  if (!inserted) {
    vkDestroyPipeline(ctx.device, p.pipeline, nullptr);
    vkDestroyShaderModule(ctx.device, p.module, nullptr);
  }
  return ComputePipeline{shaderName, it->second.first, it->second.second, true};
}

void destroyComputePipeline(Context& ctx, ComputePipeline& p) {
  if (!p.kept) {
    if (p.pipeline) vkDestroyPipeline(ctx.device, p.pipeline, nullptr);
    if (p.module) vkDestroyShaderModule(ctx.device, p.module, nullptr);
  }
  p.pipeline = VK_NULL_HANDLE;
  p.module = VK_NULL_HANDLE;
  p.kept = false;
}

GlobalsBinding createGlobalsBinding(Context& ctx, VkBuffer globals, std::uint32_t pushBytes) {
  VkDevice d = ctx.device;
  GlobalsBinding b;
  PipelineStore& st = ctx.pipelineStore;
  std::unique_lock<std::mutex> lock(st.mutex);
  auto kept = st.enabled ? st.layouts.find(pushBytes) : st.layouts.end();
  if (kept != st.layouts.end()) {
    b.setLayout = kept->second.first;
    b.layout = kept->second.second;
    b.keptLayout = true;
  } else {
    VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sl.bindingCount = 1;
    sl.pBindings = &binding;
    VK_CHECK(vkCreateDescriptorSetLayout(d, &sl, nullptr, &b.setLayout));
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &b.setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    VkResult r = vkCreatePipelineLayout(d, &pl, nullptr, &b.layout);
    if (r != VK_SUCCESS) vkDestroyDescriptorSetLayout(d, b.setLayout, nullptr);
    VK_CHECK(r);
    if (st.enabled) {
      st.layouts[pushBytes] = {b.setLayout, b.layout};
      b.keptLayout = true;
    }
  }
  lock.unlock();
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  VK_CHECK(vkCreateDescriptorPool(d, &dp, nullptr, &b.pool));
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = b.pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &b.setLayout;
  VK_CHECK(vkAllocateDescriptorSets(d, &da, &b.set));
  VkDescriptorBufferInfo bi{globals, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = b.set;
  w.dstBinding = 0;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(d, 1, &w, 0, nullptr);
  return b;
}

void destroyGlobalsBinding(Context& ctx, GlobalsBinding& b) {
  if (b.pool) vkDestroyDescriptorPool(ctx.device, b.pool, nullptr);
  if (!b.keptLayout) {
    if (b.layout) vkDestroyPipelineLayout(ctx.device, b.layout, nullptr);
    if (b.setLayout) vkDestroyDescriptorSetLayout(ctx.device, b.setLayout, nullptr);
  }
  b = GlobalsBinding{};
}

void computeBarrier(VkCommandBuffer cmd) {
  // Writes of one stage (path state, queue counts, dispatch args) become visible to the next
  // stage's shader reads/writes and to the indirect-dispatch read of its argument buffer.
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT |
                     VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT |
                           VK_PIPELINE_STAGE_TRANSFER_BIT,
                       0, 1, &mb, 0, nullptr, 0, nullptr);
}

}  // namespace nusselt::vk
