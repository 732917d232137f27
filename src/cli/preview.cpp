// preview.cpp: `nusselt preview` (issue 7): a window that shows the render converging.
//
// It is driven by the same Renderer (wavefront integrator, film, seed) as `nusselt render`: each
// frame is one Renderer::renderPass() (one sample per pixel at the window's size), then the
// display stage (shaders/stages/display.comp) tone-maps the film into an RGBA8 buffer that is
// copied into the acquired swapchain image and presented. Nothing else renders: a preview with
// the same view, size, seed and N frames accumulates exactly the film that `nusselt render --spp N`
// does (tests/cli/preview.sh checks it).
//
// Window and surface: GLFW (X11 on Debian; lavapipe has no VK_EXT_headless_surface, so tests run
// under Xvfb). One frame in flight: renderPass() already waits for its pass, so the display
// submission is fenced too and every resource can be reused at the next frame.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "io/image.h"
#include "render/render_loop.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "vk/vk.h"  // volk (Vulkan types) before GLFW, so that GLFW declares its Vulkan functions

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace nusselt {

namespace {


const char* const kKeysHelp =
    "Keys and mouse (any camera change restarts accumulation):\n"
    "  left drag, arrow keys            orbit around the target\n"
    "  right/middle drag, Shift+arrows  pan\n"
    "  wheel, PageUp/PageDown, +/-      zoom (dolly; orthographic cameras: magnification)\n"
    "  R                                reset the camera to the scene's\n"
    "  [ and ]                          exposure down/up by half a stop; E resets it\n"
    "  T                                tone map: clamp (as `nusselt render --png`) / Reinhard\n"
    "  1 2 3 4 5                        sampling strategy: quadtree, cosine, analytic, tabulated,\n"
    "                                   uniform\n"
    "  Tab                              next available sampling strategy\n"
    "  L                                lighting estimator: mis -> nee -> bsdf\n"
    "  G                                path guiding on/off (trains on the first 127 spp; camera\n"
    "                                   and lighting changes keep the guide)\n"
    "  Space                            pause/resume accumulation\n"
    "  S                                save the accumulation: preview-<n>.exr and preview-<n>.png\n"
    "  H                                print these keys\n"
    "  Esc, Q, closing the window       quit\n"
    "The title bar shows spp, samples/s, sampler, lighting, exposure and the device.";

// Path guiding's training in the preview: 127 spp (iterations of 1, 2, ..., 64), as for renders
// limited by time (guideTrainingSpp).
constexpr std::uint32_t kPreviewGuideTrainSpp = 127;

// The sampling strategies the keys 1-5 name; a key switches RenderSettings::sampler (the shade
// stages are specialised per strategy, so the renderer is recreated).
struct SamplerKey {
  SamplerKind kind;
  int key;
};
const SamplerKey kSamplers[] = {{SamplerKind::Quadtree, GLFW_KEY_1},
                                {SamplerKind::Cosine, GLFW_KEY_2},
                                {SamplerKind::Analytic, GLFW_KEY_3},
                                {SamplerKind::Tabulated, GLFW_KEY_4},
                                {SamplerKind::Uniform, GLFW_KEY_5}};


struct PreviewArgs {
  std::string scene;
  std::string camera;
  std::uint32_t width = 0, height = 0;
  std::uint32_t seed = 0;
  std::uint32_t maxDepth = 8;
  std::string lighting = "mis";
  std::string sampler = "quadtree";
  std::string tonemap = "clamp";
  std::string traversal = "auto";
  std::string guiding = "off";
  int device = -1;
  float exposure = 0.0f;
  std::uint32_t frames = 0;   // 0: until closed
  std::uint32_t maxSpp = 0;   // 0: no limit
  std::string screenshot;
  std::string exr;
  std::vector<std::string> testResize;
  std::vector<std::string> testKeys;
  bool validation = false;
  bool quiet = false;
  EnvironmentArgs env;
};

// Test harness: a key as written in --test-keys ("S", "2", "Left", "Shift+Up", "]", ...).
bool parseKeyName(std::string name, int& key, int& mods) {
  mods = 0;
  if (name.rfind("Shift+", 0) == 0) {
    mods = GLFW_MOD_SHIFT;
    name = name.substr(6);
  }
  static const std::pair<const char*, int> named[] = {
      {"Left", GLFW_KEY_LEFT},       {"Right", GLFW_KEY_RIGHT},         {"Up", GLFW_KEY_UP},
      {"Down", GLFW_KEY_DOWN},       {"PageUp", GLFW_KEY_PAGE_UP},      {"PageDown", GLFW_KEY_PAGE_DOWN},
      {"Tab", GLFW_KEY_TAB},         {"Space", GLFW_KEY_SPACE},         {"Esc", GLFW_KEY_ESCAPE},
      {"[", GLFW_KEY_LEFT_BRACKET},  {"]", GLFW_KEY_RIGHT_BRACKET},     {"+", GLFW_KEY_EQUAL},
      {"-", GLFW_KEY_MINUS}};
  for (auto& [n, k] : named)
    if (name == n) {
      key = k;
      return true;
    }
  if (name.size() == 1 && std::isalnum(static_cast<unsigned char>(name[0]))) {
    key = std::toupper(static_cast<unsigned char>(name[0]));  // GLFW_KEY_A.. and GLFW_KEY_0.. are ASCII
    return true;
  }
  return false;
}


// ---- 8-bit sRGB back to linear, exactly invertible by toSrgb8 (checked) ---------------------------
const std::vector<float>& srgbDecodeTable() {
  static const std::vector<float> table = [] {
    std::vector<float> t(256);
    for (int c = 0; c < 256; ++c) {
      double v = c / 255.0;
      t[c] = float(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
      if (toSrgb8(t[c]) != c) throw Error("internal: sRGB code " + std::to_string(c) + " does not round-trip");
    }
    return t;
  }();
  return table;
}

// ---- Orbit camera ---------------------------------------------------------------------------------
struct Orbit {
  Camera initial;
  glm::vec3 initialTarget{0.0f};
  Camera cam;
  glm::vec3 target{0.0f};
  glm::vec3 worldUp{0.0f, 1.0f, 0.0f};
  float minDistance = 1e-4f;

  void init(const Camera& c, const Scene& scene) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec3& p : scene.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    glm::vec3 centre = scene.positions.empty() ? glm::vec3(0.0f) : 0.5f * (lo + hi);
    float radius = scene.positions.empty() ? 1.0f : std::max(0.5f * glm::length(hi - lo), 1e-6f);
    glm::vec3 f = glm::normalize(c.forward);
    float d = glm::dot(centre - c.position, f);
    if (!(d > 1e-3f * radius)) d = radius;
    initial = c;
    initialTarget = c.position + f * d;
    minDistance = 1e-4f * radius;
    // Orbit about the glTF up axis (+y) unless the camera looks (almost) along it.
    worldUp = std::abs(glm::dot(f, glm::vec3(0, 1, 0))) < 0.99f ? glm::vec3(0, 1, 0) : glm::normalize(c.up);
    reset();
  }
  void reset() {
    cam = initial;
    target = initialTarget;
  }
  float distance() const { return glm::length(cam.position - target); }
  void setForward(glm::vec3 f) {
    cam.forward = glm::normalize(f);
    glm::vec3 right = glm::normalize(glm::cross(cam.forward, worldUp));
    cam.up = glm::cross(right, cam.forward);
  }
  glm::vec3 right() const { return glm::normalize(glm::cross(cam.forward, cam.up)); }
  // Rotate the eye about the target: yaw about worldUp, pitch about the camera's right axis.
  void orbit(float yaw, float pitch) {
    glm::vec3 off = cam.position - target;
    off = glm::angleAxis(-yaw, worldUp) * off;
    glm::vec3 f = glm::normalize(-off);
    glm::vec3 r = glm::normalize(glm::cross(f, worldUp));
    glm::vec3 pitched = glm::angleAxis(-pitch, r) * off;
    if (std::abs(glm::dot(glm::normalize(-pitched), worldUp)) < 0.995f) off = pitched;  // not over the pole
    cam.position = target + off;
    setForward(-off);
  }
  // Move eye and target in the view plane by (dx, dy) world units (right, up).
  void pan(float dx, float dy) {
    glm::vec3 delta = right() * dx + glm::normalize(cam.up) * dy;
    cam.position += delta;
    target += delta;
  }
  // factor < 1 zooms in.
  void zoom(float factor) {
    if (cam.orthographic) {
      cam.xmag *= factor;
      cam.ymag *= factor;
      return;
    }
    float d = std::max(distance() * factor, minDistance);
    cam.position = target - glm::normalize(cam.forward) * d;
  }
  // World units per pixel in the view plane through the target, for a window h pixels high.
  float worldPerPixel(int h) const {
    float half = cam.orthographic ? cam.ymag : distance() * std::tan(0.5f * cam.yfov);
    return 2.0f * half / float(std::max(h, 1));
  }
};

// ---- The preview ----------------------------------------------------------------------------------
std::string glfwErrorText;
void onGlfwError(int, const char* description) { glfwErrorText = description ? description : "unknown GLFW error"; }

class Preview {
 public:
  Preview(const PreviewArgs& a) : m_args(a) {}
  ~Preview() { destroy(); }
  int run();

 private:
  void createRenderer(std::uint32_t width, std::uint32_t height);
  // A new render loop over the renderer's film (after any restart of accumulation).
  void restartLoop();
  bool createSwapchain();  // false: the surface has no area (minimised); try later
  void destroySwapchain();
  bool presentFrame();  // false: the swapchain must be recreated
  void updateTitle(bool force);
  void onKey(int key, int mods);
  void cameraChanged() { m_cameraDirty = true; }
  void save();
  void writeScreenshot(const std::string& path);
  void destroy();

  static void keyCallback(GLFWwindow* w, int key, int, int action, int mods) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT) static_cast<Preview*>(glfwGetWindowUserPointer(w))->onKey(key, mods);
  }
  static void cursorCallback(GLFWwindow* w, double x, double y);
  static void scrollCallback(GLFWwindow* w, double, double dy) {
    auto* p = static_cast<Preview*>(glfwGetWindowUserPointer(w));
    p->m_orbit.zoom(std::pow(0.9f, float(dy)));
    p->cameraChanged();
  }
  static void refreshCallback(GLFWwindow* w) { static_cast<Preview*>(glfwGetWindowUserPointer(w))->m_displayDirty = true; }

  PreviewArgs m_args;
  Scene m_scene;
  RenderSettings m_settings;
  bool m_glfw = false;
  GLFWwindow* m_window = nullptr;
  vk::Context m_ctx;
  bool m_contextCreated = false;
  VkSurfaceKHR m_surface = VK_NULL_HANDLE;

  std::unique_ptr<Renderer> m_renderer;
  std::unique_ptr<RenderLoop> m_loop;
  vk::ComputePipeline m_display;
  vk::Buffer m_displayBuffer;

  VkSwapchainKHR m_swapchain = VK_NULL_HANDLE;
  VkFormat m_format = VK_FORMAT_UNDEFINED;
  VkExtent2D m_extent{0, 0};
  std::vector<VkImage> m_images;
  std::vector<VkSemaphore> m_renderDone;  // one per swapchain image (presentation waits on it)
  VkSemaphore m_acquired = VK_NULL_HANDLE;
  VkFence m_fence = VK_NULL_HANDLE;
  VkCommandBuffer m_cmd = VK_NULL_HANDLE;
  int m_fbWidth = 0, m_fbHeight = 0;  // framebuffer size the swapchain was made for

  Orbit m_orbit;
  bool m_cameraDirty = false;
  bool m_displayDirty = true;
  bool m_lightingDirty = false;  // a new lighting estimator: setLighting (no pipeline is rebuilt)
  bool m_samplerDirty = false;   // a new sampling strategy: the shade stages are specialised, a new Renderer
  bool m_paused = false;
  bool m_reinhard = false;
  float m_exposure = 0.0f;
  double m_lastX = 0, m_lastY = 0;
  bool m_haveCursor = false;

  std::uint64_t m_framesPresented = 0;
  double m_samplesPerSecond = 0;
  std::chrono::steady_clock::time_point m_lastTitle{};
  std::chrono::steady_clock::time_point m_start{};
  std::vector<std::uint32_t> m_lastFrame;  // the last presented frame (only with --screenshot)
  std::uint32_t m_lastFrameWidth = 0, m_lastFrameHeight = 0;
};

void Preview::cursorCallback(GLFWwindow* w, double x, double y) {
  auto* p = static_cast<Preview*>(glfwGetWindowUserPointer(w));
  double dx = x - p->m_lastX, dy = y - p->m_lastY;
  bool had = p->m_haveCursor;
  p->m_lastX = x;
  p->m_lastY = y;
  p->m_haveCursor = true;
  if (!had || (dx == 0 && dy == 0)) return;
  if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
    p->m_orbit.orbit(float(dx) * 0.006f, float(dy) * 0.006f);
    p->cameraChanged();
  } else if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
             glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
    int ww = 0, wh = 0;
    glfwGetWindowSize(w, &ww, &wh);
    float s = p->m_orbit.worldPerPixel(wh);
    p->m_orbit.pan(-float(dx) * s, float(dy) * s);
    p->cameraChanged();
  }
}

void Preview::onKey(int key, int mods) {
  const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
  const float step = 5.0f * float(M_PI) / 180.0f;
  int wh = std::max(m_fbHeight, 1);
  float panStep = 0.05f * m_orbit.worldPerPixel(wh) * float(wh);
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(m_window, GLFW_TRUE); return;
    case GLFW_KEY_LEFT: shift ? m_orbit.pan(-panStep, 0) : m_orbit.orbit(-step, 0); cameraChanged(); return;
    case GLFW_KEY_RIGHT: shift ? m_orbit.pan(panStep, 0) : m_orbit.orbit(step, 0); cameraChanged(); return;
    case GLFW_KEY_UP: shift ? m_orbit.pan(0, panStep) : m_orbit.orbit(0, -step); cameraChanged(); return;
    case GLFW_KEY_DOWN: shift ? m_orbit.pan(0, -panStep) : m_orbit.orbit(0, step); cameraChanged(); return;
    case GLFW_KEY_PAGE_UP:
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: m_orbit.zoom(0.9f); cameraChanged(); return;
    case GLFW_KEY_PAGE_DOWN:
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: m_orbit.zoom(1.0f / 0.9f); cameraChanged(); return;
    case GLFW_KEY_R: m_orbit.reset(); cameraChanged(); return;
    case GLFW_KEY_LEFT_BRACKET: m_exposure -= 0.5f; m_displayDirty = true; updateTitle(true); return;
    case GLFW_KEY_RIGHT_BRACKET: m_exposure += 0.5f; m_displayDirty = true; updateTitle(true); return;
    case GLFW_KEY_E: m_exposure = m_args.exposure; m_displayDirty = true; updateTitle(true); return;
    case GLFW_KEY_T: m_reinhard = !m_reinhard; m_displayDirty = true; updateTitle(true); return;
    case GLFW_KEY_L: {
      LightingMode next = m_settings.lighting == LightingMode::Mis       ? LightingMode::NeeOnly
                          : m_settings.lighting == LightingMode::NeeOnly ? LightingMode::BsdfOnly
                                                                          : LightingMode::Mis;
      m_settings.lighting = next;
      m_lightingDirty = true;
      std::fprintf(stderr, "lighting: %s\n", lightingModeName(next));
      return;
    }
    case GLFW_KEY_TAB: {
      // The next strategy after the current one, in the keys' order.
      std::size_t n = sizeof kSamplers / sizeof kSamplers[0], cur = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (m_settings.sampler == kSamplers[i].kind) cur = i;
      m_settings.sampler = kSamplers[(cur + 1) % n].kind;
      m_samplerDirty = true;  // recreate the renderer with the new strategy
      std::fprintf(stderr, "sampler: %s\n", samplerName(m_settings.sampler));
      updateTitle(true);
      return;
    }
    case GLFW_KEY_G:
      m_settings.guiding = !m_settings.guiding;
      m_samplerDirty = true;  // the shade stages are specialised with GUIDING: a new Renderer
      std::fprintf(stderr, "guiding: %s\n", m_settings.guiding ? "on" : "off");
      updateTitle(true);
      return;
    case GLFW_KEY_SPACE: m_paused = !m_paused; updateTitle(true); return;
    case GLFW_KEY_S: save(); return;
    case GLFW_KEY_H: std::fprintf(stderr, "%s\n", kKeysHelp); return;
    default: break;
  }
  for (const SamplerKey& s : kSamplers) {
    if (key != s.key) continue;
    if (m_settings.sampler != s.kind) {
      m_settings.sampler = s.kind;
      m_samplerDirty = true;  // recreate the renderer with the new strategy
      std::fprintf(stderr, "sampler: %s\n", samplerName(s.kind));
    }
    updateTitle(true);
  }
}

void Preview::createRenderer(std::uint32_t width, std::uint32_t height) {
  Camera cam = m_renderer ? m_renderer->camera() : Camera{};
  bool keepCamera = m_renderer != nullptr;
  if (m_renderer) {
    vkDeviceWaitIdle(m_ctx.device);
    vk::destroyComputePipeline(m_ctx, m_display);
    m_loop.reset();
    m_renderer.reset();
  }
  vk::destroyBuffer(m_ctx, m_displayBuffer);
  m_settings.width = width;
  m_settings.height = height;
  m_settings.samplesPerPass = 1;  // a frame is one sample per pixel: the window stays responsive
  m_renderer = std::make_unique<Renderer>(m_ctx, m_scene, m_settings);
  if (keepCamera) m_renderer->setCamera(cam);  // the camera of the scene otherwise: same view as `render`
  m_display = vk::createComputePipeline(m_ctx, m_renderer->pipelineLayout(), "display");
  m_displayBuffer = vk::createBuffer(m_ctx, VkDeviceSize(width) * height * 4, 0, false, "display");
  m_renderer->setDisplayBuffer(m_displayBuffer.address);
  m_displayDirty = true;
  restartLoop();
}

void Preview::restartLoop() {
  RenderRecord base;
  base.scene = m_scene.sourcePath;
  base.device = m_ctx.deviceName;
  base.driver = m_ctx.driverInfo;
  for (const std::string& m : m_renderer->summary().models) base.models += (base.models.empty() ? "" : ",") + m;
  base.source = "preview";
  base.settings = m_settings;
  base.camera = m_renderer->camera();
  base.droppedTriangles = m_scene.droppedTriangles;
  recordEnvironment(base, m_scene);
  RenderLoopOptions lo;
  lo.spp = m_args.maxSpp ? m_args.maxSpp : (1u << 30);
  lo.progress = false;
  lo.quiet = true;
  m_loop.reset();
  m_loop = std::make_unique<RenderLoop>(*m_renderer, base, RenderRecord{}, lo);
}

bool Preview::createSwapchain() {
  VkSurfaceCapabilitiesKHR caps;
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(m_ctx.physical, m_surface, &caps));
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == 0xFFFFFFFFu) {
    extent.width = std::clamp<std::uint32_t>(std::uint32_t(m_fbWidth), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp<std::uint32_t>(std::uint32_t(m_fbHeight), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent.width == 0 || extent.height == 0) return false;  // minimised: try again later
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw Error("the window surface does not accept transfers into its images (VK_IMAGE_USAGE_TRANSFER_DST_BIT), "
                "which the preview needs");

  std::uint32_t n = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(m_ctx.physical, m_surface, &n, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(n);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(m_ctx.physical, m_surface, &n, formats.data()));
  // The display stage writes sRGB-encoded bytes; a copy does no conversion, so any 8-bit RGBA or
  // BGRA format shows them as they are. UNORM first (an _SRGB format would say the same).
  const VkFormat preferred[] = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB,
                                VK_FORMAT_R8G8B8A8_SRGB};
  VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  for (VkFormat want : preferred) {
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) {
        chosen = f;
        break;
      }
    if (chosen.format != VK_FORMAT_UNDEFINED) break;
  }
  if (chosen.format == VK_FORMAT_UNDEFINED) throw Error("the window surface offers no 8-bit RGBA/BGRA sRGB format");

  VkCompositeAlphaFlagBitsKHR alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & alpha))
    for (VkCompositeAlphaFlagBitsKHR a : {VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR, VK_COMPOSITE_ALPHA_PRE_MULTIPLIED_BIT_KHR,
                                          VK_COMPOSITE_ALPHA_POST_MULTIPLIED_BIT_KHR})
      if (caps.supportedCompositeAlpha & a) {
        alpha = a;
        break;
      }
  std::uint32_t imageCount = caps.minImageCount + 1;
  if (caps.maxImageCount && imageCount > caps.maxImageCount) imageCount = caps.maxImageCount;

  VkSwapchainKHR old = m_swapchain;
  VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  ci.surface = m_surface;
  ci.minImageCount = imageCount;
  ci.imageFormat = chosen.format;
  ci.imageColorSpace = chosen.colorSpace;
  ci.imageExtent = extent;
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = alpha;
  ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = old;
  VK_CHECK(vkCreateSwapchainKHR(m_ctx.device, &ci, nullptr, &m_swapchain));
  if (old) vkDestroySwapchainKHR(m_ctx.device, old, nullptr);
  m_format = chosen.format;
  m_extent = extent;

  VK_CHECK(vkGetSwapchainImagesKHR(m_ctx.device, m_swapchain, &n, nullptr));
  m_images.resize(n);
  VK_CHECK(vkGetSwapchainImagesKHR(m_ctx.device, m_swapchain, &n, m_images.data()));
  for (VkSemaphore s : m_renderDone) vkDestroySemaphore(m_ctx.device, s, nullptr);
  m_renderDone.assign(n, VK_NULL_HANDLE);
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  for (VkSemaphore& s : m_renderDone) VK_CHECK(vkCreateSemaphore(m_ctx.device, &sci, nullptr, &s));

  // The render follows the window: one film pixel per swapchain pixel.
  if (!m_renderer || m_settings.width != extent.width || m_settings.height != extent.height)
    createRenderer(extent.width, extent.height);
  m_displayDirty = true;
  return true;
}

void Preview::destroySwapchain() {
  if (!m_ctx.device) return;
  vkDeviceWaitIdle(m_ctx.device);
  for (VkSemaphore s : m_renderDone) vkDestroySemaphore(m_ctx.device, s, nullptr);
  m_renderDone.clear();
  if (m_swapchain) vkDestroySwapchainKHR(m_ctx.device, m_swapchain, nullptr);
  m_swapchain = VK_NULL_HANDLE;
  m_images.clear();
}

bool Preview::presentFrame() {
  VkDevice d = m_ctx.device;
  std::uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(d, m_swapchain, UINT64_MAX, m_acquired, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return false;
  if (r != VK_SUBOPTIMAL_KHR) VK_CHECK(r);
  bool suboptimal = r == VK_SUBOPTIMAL_KHR;
  const std::uint32_t w = m_settings.width, h = m_settings.height;

  VK_CHECK(vkResetCommandBuffer(m_cmd, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(m_cmd, &bi));
  // Orders the previous frame's copy out of the display buffer (and the last pass's film writes)
  // before the display stage.
  vk::computeBarrier(m_cmd);
  VkDescriptorSet set = m_renderer->descriptorSet();
  vkCmdBindDescriptorSets(m_cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_renderer->pipelineLayout(), 0, 1, &set, 0, nullptr);
  vkCmdBindPipeline(m_cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_display.pipeline);
  shared::DisplayConstants pc{};
  pc.exposureScale = std::exp2(m_exposure);
  pc.flags = (m_format == VK_FORMAT_B8G8R8A8_UNORM || m_format == VK_FORMAT_B8G8R8A8_SRGB ? DISPLAY_BGRA : 0u) |
             (m_reinhard ? DISPLAY_REINHARD : 0u);
  vkCmdPushConstants(m_cmd, m_renderer->pipelineLayout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(m_cmd, (w + 7) / 8, (h + 7) / 8, 1);
  vk::computeBarrier(m_cmd);  // display writes -> transfer read

  VkImageMemoryBarrier ib{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  ib.srcAccessMask = 0;
  ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  ib.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  ib.image = m_images[index];
  ib.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  // srcStage TRANSFER: the stage the acquire semaphore is waited at, so the transition follows it.
  vkCmdPipelineBarrier(m_cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                       1, &ib);
  VkBufferImageCopy copy{};
  copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  copy.imageExtent = {std::min(w, m_extent.width), std::min(h, m_extent.height), 1};
  copy.bufferRowLength = w;
  vkCmdCopyBufferToImage(m_cmd, m_displayBuffer.buffer, m_images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
  ib.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  ib.dstAccessMask = 0;
  ib.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  ib.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vkCmdPipelineBarrier(m_cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &ib);
  // The next pass may clear or accumulate into the film the display stage read.
  vk::computeBarrier(m_cmd);
  VK_CHECK(vkEndCommandBuffer(m_cmd));

  VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &m_acquired;
  si.pWaitDstStageMask = &waitStage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &m_cmd;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &m_renderDone[index];
  VK_CHECK(vkResetFences(d, 1, &m_fence));
  VK_CHECK(vkQueueSubmit(m_ctx.queue, 1, &si, m_fence));

  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &m_renderDone[index];
  pi.swapchainCount = 1;
  pi.pSwapchains = &m_swapchain;
  pi.pImageIndices = &index;
  r = vkQueuePresentKHR(m_ctx.queue, &pi);
  VK_CHECK(vkWaitForFences(d, 1, &m_fence, VK_TRUE, UINT64_MAX));
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) suboptimal = true;
  else VK_CHECK(r);

  ++m_framesPresented;
  m_displayDirty = false;
  if (!m_args.screenshot.empty()) {
    m_lastFrame.resize(std::size_t(w) * h);
    vk::downloadBuffer(m_ctx, m_displayBuffer, m_lastFrame.data(), VkDeviceSize(w) * h * 4);
    m_lastFrameWidth = w;
    m_lastFrameHeight = h;
  }
  return !suboptimal;
}

void Preview::updateTitle(bool force) {
  auto now = std::chrono::steady_clock::now();
  if (!force && now - m_lastTitle < std::chrono::milliseconds(250)) return;
  m_lastTitle = now;
  char guide[64] = "";
  if (m_settings.guiding)
    std::snprintf(guide, sizeof guide, " | guiding (trained %u/%u spp)", m_renderer ? m_renderer->guideTrainedSpp() : 0u,
                  kPreviewGuideTrainSpp);
  char title[512];
  std::snprintf(title, sizeof title,
                "nusselt preview | %u spp | %.3g Msamples/s | sampler %s | lighting %s%s | exposure %+.1f (%s)%s | %ux%u | %s",
                m_renderer ? m_renderer->samplesDone() : 0u, m_samplesPerSecond / 1e6, samplerName(m_settings.sampler),
                lightingModeName(m_settings.lighting), guide, m_exposure, m_reinhard ? "Reinhard" : "clamp",
                m_paused ? " | paused" : (m_args.maxSpp && m_renderer && m_renderer->samplesDone() >= m_args.maxSpp ? " | done" : ""),
                m_settings.width, m_settings.height, m_ctx.deviceName.c_str());
  glfwSetWindowTitle(m_window, title);
}

void Preview::save() {
  if (!m_renderer || m_renderer->samplesDone() == 0) {
    std::fprintf(stderr, "nothing to save yet (0 spp)\n");
    return;
  }
  namespace fs = std::filesystem;
  std::string base;
  for (int n = 1;; ++n) {
    base = "preview-" + std::to_string(n);
    std::error_code ec;
    if (!fs::exists(base + ".exr", ec) && !fs::exists(base + ".png", ec)) break;
  }
  try {
    // The full record of a render: `nusselt render --resume` continues it, `nusselt merge` adds it.
    m_loop->setDisplayExposure(m_exposure);
    m_loop->write(base + ".exr", false, base + ".png", m_exposure);  // clamp tone map, as `render --png`
    std::fprintf(stderr, "wrote %s.exr and %s.png (%u spp)\n", base.c_str(), base.c_str(), m_renderer->samplesDone());
  } catch (const Error& e) {
    std::fprintf(stderr, "error: saving failed: %s\n", e.what());  // the preview goes on
  }
}

void Preview::writeScreenshot(const std::string& path) {
  if (m_lastFrame.empty()) throw Error("--screenshot " + path + ": no frame was presented");
  const std::vector<float>& lin = srgbDecodeTable();
  const bool bgra = m_format == VK_FORMAT_B8G8R8A8_UNORM || m_format == VK_FORMAT_B8G8R8A8_SRGB;
  Image img;
  img.width = int(m_lastFrameWidth);
  img.height = int(m_lastFrameHeight);
  img.rgb.resize(m_lastFrame.size() * 3);
  for (std::size_t i = 0; i < m_lastFrame.size(); ++i) {
    std::uint32_t v = m_lastFrame[i];
    std::uint32_t c0 = v & 0xffu, c1 = (v >> 8) & 0xffu, c2 = (v >> 16) & 0xffu;
    img.rgb[3 * i + 0] = lin[bgra ? c2 : c0];
    img.rgb[3 * i + 1] = lin[c1];
    img.rgb[3 * i + 2] = lin[bgra ? c0 : c2];
  }
  writePng(path, img, 0.0f);  // re-encodes exactly the displayed code values
}

int Preview::run() {
  const PreviewArgs& a = m_args;
  m_start = std::chrono::steady_clock::now();
  if (!a.screenshot.empty()) checkOutputPath(a.screenshot, "--screenshot");
  if (!a.exr.empty()) checkOutputPath(a.exr, "--exr");
  std::vector<std::pair<int, int>> resizes;
  for (const std::string& s : a.testResize) {
    int w = 0, h = 0;
    char x = 0;
    std::istringstream in(s);
    if (!(in >> w >> x >> h) || x != 'x' || w < 1 || h < 1) throw Error("--test-resize " + s + ": expected WxH");
    resizes.push_back({w, h});
  }
  std::vector<std::pair<int, int>> keys;
  for (const std::string& k : a.testKeys) {
    int key = 0, mods = 0;
    if (!parseKeyName(k, key, mods)) throw Error("--test-keys " + k + ": unknown key");
    keys.push_back({key, mods});
  }
  srgbDecodeTable();

  // A display first: without one there is nothing to do, whatever the scene.
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit())
    throw Error("nusselt preview needs a display and could not open one (" + glfwErrorText +
                "); on a machine without a display, render to a file with `nusselt render` (same scene and "
                "options, e.g. `nusselt render --spp 64 --png out.png`), or run the preview under Xvfb (xvfb-run)");
  m_glfw = true;
  if (!glfwVulkanSupported())
    throw Error("GLFW found no Vulkan loader with window-system support (" + glfwErrorText +
                "); install libvulkan1 and mesa-vulkan-drivers, or use `nusselt render`");
  std::uint32_t extCount = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&extCount);
  if (!exts) throw Error("no Vulkan surface extension for this display (" + glfwErrorText + "); use `nusselt render`");

  m_scene = loadCommandScene(a.scene, a.camera, a.env, a.quiet);
  m_settings.seed = a.seed;
  m_settings.maxDepth = a.maxDepth;
  parseLighting(a.lighting, m_settings.lighting);
  parseSampler(a.sampler, m_settings.sampler);
  parseTraversal(a.traversal, m_settings.traversal);
  m_settings.spp = 1;
  // A quadtree build (at start, or on switching to the quadtree with S) is announced before the
  // window stalls on it.
  if (!a.quiet) m_settings.notice = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  // Path guiding (G switches): the open-ended render's training, as `render --time` has it.
  m_settings.guiding = a.guiding == "on";
  m_settings.guideTrainSpp = kPreviewGuideTrainSpp;
  m_exposure = a.exposure;
  m_reinhard = a.tonemap == "reinhard";
  std::uint32_t imageWidth = 0, imageHeight = 0;
  imageSize(m_scene, a.width, a.height, 512u, imageWidth, imageHeight);
  int width = int(imageWidth), height = int(imageHeight);

  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  m_window = glfwCreateWindow(width, height, "nusselt preview", nullptr, nullptr);
  if (!m_window) throw Error("cannot create the preview window (" + glfwErrorText + "); use `nusselt render`");
  glfwSetWindowUserPointer(m_window, this);
  glfwSetKeyCallback(m_window, keyCallback);
  glfwSetCursorPosCallback(m_window, cursorCallback);
  glfwSetScrollCallback(m_window, scrollCallback);
  glfwSetWindowRefreshCallback(m_window, refreshCallback);

  vk::ContextOptions co;
  co.deviceIndex = a.device;
  co.validation = a.validation || validationFromEnvironment();
  for (std::uint32_t i = 0; i < extCount; ++i) co.instanceExtensions.push_back(exts[i]);
  co.swapchain = true;
  co.rayQuery = m_settings.traversal != Traversal::Bvh;
  m_contextCreated = true;
  vk::createContext(m_ctx, co);
  VkResult sr = glfwCreateWindowSurface(m_ctx.instance, m_window, nullptr, &m_surface);
  if (sr != VK_SUCCESS)
    throw Error(std::string("cannot create a Vulkan surface for the window (") + vk::resultName(sr) + ", " + glfwErrorText +
                "); use `nusselt render`");
  VkBool32 supported = VK_FALSE;
  VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(m_ctx.physical, m_ctx.queueFamily, m_surface, &supported));
  if (!supported)
    throw Error(m_ctx.deviceName + " cannot present to this window (choose another with --device, or use `nusselt render`)");

  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VK_CHECK(vkCreateSemaphore(m_ctx.device, &sci, nullptr, &m_acquired));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(m_ctx.device, &fci, nullptr, &m_fence));
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = m_ctx.commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(m_ctx.device, &ai, &m_cmd));

  glfwGetFramebufferSize(m_window, &m_fbWidth, &m_fbHeight);
  createSwapchain();
  if (!m_renderer) createRenderer(std::uint32_t(std::max(m_fbWidth, 1)), std::uint32_t(std::max(m_fbHeight, 1)));
  m_orbit.init(m_renderer->camera(), m_scene);
  if (!a.quiet) {
    const SceneSummary& sum = m_renderer->summary();
    std::string models;
    for (auto& m : sum.models) models += (models.empty() ? "" : ",") + m;
    std::fprintf(stderr, "scene: %s: %zu triangles, %zu materials (models: %s), %zu lights\n", m_scene.sourcePath.c_str(),
                 sum.triangles, sum.materials, models.c_str(), sum.lights);
    std::fprintf(stderr, "device: %s; window %ux%u, max depth %u, seed %u, lighting %s, sampler %s, traversal %s; press H "
                         "for the keys\n",
                 m_ctx.deviceName.c_str(), m_settings.width, m_settings.height, m_settings.maxDepth, m_settings.seed,
                 lightingModeName(m_settings.lighting), samplerName(m_settings.sampler), traversalName(sum.traversal));
  }

  std::unique_ptr<ScopedStopSignals> signals = std::make_unique<ScopedStopSignals>();
  std::size_t nextResize = 0, nextKey = 0;
  bool swapchainStale = false;
  while (!glfwWindowShouldClose(m_window) && g_stopSignal == 0) {
    const bool dirty = m_cameraDirty || m_lightingDirty || m_samplerDirty;
    bool idle = m_paused || (a.maxSpp && m_renderer->samplesDone() >= a.maxSpp && !dirty);
    // Test harness: one key per frame from the second frame on, as if typed (also while idle).
    if (nextKey < keys.size() && (idle || m_framesPresented >= 1 + nextKey)) {
      onKey(keys[nextKey].first, keys[nextKey].second);
      ++nextKey;
      continue;
    }
    const bool minimised = glfwGetWindowAttrib(m_window, GLFW_ICONIFIED) != 0;
    // Scripts: once --max-spp is reached nothing changes any more, so --frames ends the run.
    if (a.frames && a.maxSpp && m_renderer->samplesDone() >= a.maxSpp && !dirty && !m_displayDirty &&
        nextKey >= keys.size())
      break;
    if (minimised || (idle && !m_displayDirty && !swapchainStale)) {
      glfwWaitEventsTimeout(0.25);  // nothing to draw: sleep until something happens
      updateTitle(false);
      continue;
    }
    glfwPollEvents();

    // Test harness: resize the window after a share of the frames (as a user's drag would).
    if (nextResize < resizes.size()) {
      std::uint64_t every = a.frames ? std::max<std::uint64_t>(1, a.frames / (resizes.size() + 1)) : 10;
      if (m_framesPresented >= every * (nextResize + 1)) {
        glfwSetWindowSize(m_window, resizes[nextResize].first, resizes[nextResize].second);
        ++nextResize;
      }
    }

    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(m_window, &fbw, &fbh);
    if (fbw == 0 || fbh == 0) {
      glfwWaitEventsTimeout(0.25);
      continue;
    }
    if (swapchainStale || !m_swapchain || fbw != m_fbWidth || fbh != m_fbHeight) {
      m_fbWidth = fbw;
      m_fbHeight = fbh;
      vkDeviceWaitIdle(m_ctx.device);
      if (!createSwapchain()) {
        swapchainStale = true;
        glfwWaitEventsTimeout(0.25);
        continue;
      }
      swapchainStale = false;
    }
    if (m_samplerDirty) {
      createRenderer(m_settings.width, m_settings.height);  // keeps the camera; restarts accumulation
      m_samplerDirty = m_lightingDirty = false;
    }
    if (m_lightingDirty) {
      m_renderer->setLighting(m_settings.lighting);  // a run-time value of the shaders; restarts accumulation
      m_lightingDirty = false;
      restartLoop();
    }
    if (m_cameraDirty) {
      m_renderer->setCamera(m_orbit.cam);
      m_cameraDirty = false;
      restartLoop();
    }
    if (!m_paused) {
      auto t0 = std::chrono::steady_clock::now();
      if (m_loop->step()) {
        double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        double rate = double(m_settings.width) * m_settings.height / std::max(sec, 1e-9);
        m_samplesPerSecond = m_samplesPerSecond > 0 ? 0.8 * m_samplesPerSecond + 0.2 * rate : rate;
      }
    }
    if (!presentFrame()) {
      swapchainStale = true;
      continue;
    }
    updateTitle(false);
    if (a.frames && m_framesPresented >= a.frames) break;
  }
  const int sig = g_stopSignal.load();
  signals.reset();
  vkDeviceWaitIdle(m_ctx.device);

  if (!a.screenshot.empty()) {
    writeScreenshot(a.screenshot);
    if (!a.quiet) std::fprintf(stderr, "wrote %s (%ux%u, the last presented frame)\n", a.screenshot.c_str(), m_lastFrameWidth, m_lastFrameHeight);
  }
  if (!a.exr.empty()) {
    if (m_renderer->samplesDone() == 0) throw Error("--exr " + a.exr + ": no sample was accumulated");
    m_loop->setDisplayExposure(m_exposure);
    m_loop->write(a.exr);
    if (!a.quiet) std::fprintf(stderr, "wrote %s (%u spp)\n", a.exr.c_str(), m_renderer->samplesDone());
  }
  if (!a.quiet)
    std::fprintf(stderr, "preview: %llu frames, %u spp accumulated at the end\n",
                 static_cast<unsigned long long>(m_framesPresented), m_renderer->samplesDone());
  RenderStats st = m_renderer->stats();
  if (st.bvhStackOverflows)
    std::fprintf(stderr, "warning: %llu BVH traversals overflowed their stack\n", static_cast<unsigned long long>(st.bvhStackOverflows));

  destroy();
  std::uint64_t messages = m_ctx.validationMessages.load();
  if (messages) {
    std::fprintf(stderr, "error: %llu Vulkan validation messages\n", static_cast<unsigned long long>(messages));
    return kExitFailure;
  }
  return sig ? kExitInterrupted : kExitOk;
}

void Preview::destroy() {
  if (m_ctx.device) {
    vkDeviceWaitIdle(m_ctx.device);
    destroySwapchain();
    if (m_renderer) vk::destroyComputePipeline(m_ctx, m_display);
    m_loop.reset();
    m_renderer.reset();
    vk::destroyBuffer(m_ctx, m_displayBuffer);
    if (m_cmd) vkFreeCommandBuffers(m_ctx.device, m_ctx.commandPool, 1, &m_cmd);
    if (m_fence) vkDestroyFence(m_ctx.device, m_fence, nullptr);
    if (m_acquired) vkDestroySemaphore(m_ctx.device, m_acquired, nullptr);
    m_cmd = VK_NULL_HANDLE;
    m_fence = VK_NULL_HANDLE;
    m_acquired = VK_NULL_HANDLE;
  }
  if (m_surface && m_ctx.instance) vkDestroySurfaceKHR(m_ctx.instance, m_surface, nullptr);
  m_surface = VK_NULL_HANDLE;
  if (m_contextCreated) vk::destroyContext(m_ctx);  // keeps validationMessages
  m_contextCreated = false;
  if (m_window) glfwDestroyWindow(m_window);
  m_window = nullptr;
  if (m_glfw) glfwTerminate();
  m_glfw = false;
}

}  // namespace

void registerPreviewCommand(CLI::App& app, CommandRunner& run) {
  auto a = std::make_shared<PreviewArgs>();
  CLI::App* p = app.add_subcommand(
      "preview", "Open a window that shows the render converging (progressive, same integrator as `render`)");
  p->footer(kKeysHelp);
  p->add_option("scene", a->scene, "glTF 2.0 scene (.gltf or .glb); omitted: the built-in Cornell box");
  addEnvironmentOptions(*p, a->env);
  p->add_option("--width", a->width, "Window (and render) width in pixels (default 512, or from --height and the camera)")
      ->check(CLI::Range(1u, 16384u));
  p->add_option("--height", a->height, "Window (and render) height in pixels (default from the width and the camera)")
      ->check(CLI::Range(1u, 16384u));
  p->add_option("--camera", a->camera, "Use the glTF camera with this name (default: the first camera)");
  p->add_option("--seed", a->seed, "Random seed (same as `render --seed`: same view and spp give the same film)")
      ->capture_default_str();
  p->add_option("--max-depth", a->maxDepth, "Maximum path depth")->capture_default_str()->check(CLI::Range(0u, 1024u));
  p->add_option("--sampler", a->sampler, "BSDF sampling at start (keys 1-5 and Tab switch): quadtree, cosine, uniform")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kSamplerNames)));
  p->add_option("--lighting", a->lighting, "Light transport estimator at start (L switches): mis, nee, bsdf")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kLightingNames)));
  p->add_option("--guiding", a->guiding, "Path guiding at start (G switches): off, on (trains on the first 127 spp; docs/guiding.md)")
      ->capture_default_str()->check(CLI::IsMember({"off", "on"}));
  p->add_option("--exposure", a->exposure, "Display exposure in stops ([ and ] change it)")->capture_default_str();
  p->add_option("--tonemap", a->tonemap, "Display tone map at start (T switches): clamp (as `render --png`), reinhard")
      ->capture_default_str()->check(CLI::IsMember({"clamp", "reinhard"}));
  p->add_option("--device", a->device, "Vulkan device index (see `nusselt devices`)");
  p->add_option("--traversal", a->traversal, "Ray traversal: rayquery, bvh or auto (as `render --traversal`)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kTraversalNames)));
  p->add_option("--frames", a->frames, "Exit after presenting this many frames, or earlier when --max-spp is reached (scripts and tests; 0: run until closed)")
      ->capture_default_str();
  p->add_option("--max-spp", a->maxSpp, "Stop accumulating at this many samples per pixel and idle (0: no limit)")
      ->capture_default_str();
  p->add_option("--screenshot", a->screenshot, "At exit, write the last presented frame (8-bit sRGB) as PNG");
  p->add_option("--exr", a->exr, "At exit, write the accumulated film (32-bit float, as `render -o`) as OpenEXR");
  p->add_option("--test-resize", a->testResize, "Test harness: resize the window to WxH during the run (repeatable)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->delimiter(',')->group("");  // hidden
  p->add_option("--test-keys", a->testKeys, "Test harness: keys to press, one per frame (e.g. S,L,2,Shift+Left)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->delimiter(',')->group("");  // hidden
  p->add_flag("--validation", a->validation, "Enable the Vulkan validation layer (also NUSSELT_VALIDATION=1); any message fails the preview");
  p->add_flag("-q,--quiet", a->quiet, "No summary output");
  p->callback([a, &run] {
    run = [a] {
      Preview preview(*a);
      return preview.run();
    };
  });
}

}  // namespace nusselt
