// renderer.cpp: scene upload, pipelines and the wavefront pass.
#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "brdf/albedo.h"
#include "quadtree/sampler_tables.h"
#include "sampling/tabulated.h"
#include "scene/bvh.h"
#include "util/error.h"

namespace nusselt {

using shared::BvhNode;
using shared::DispatchArgs;
using shared::Globals;
using shared::GpuLight;
using shared::GpuComponent;
using shared::GpuMaterial;
using shared::GpuTriangle;
using shared::GpuTriShading;
using shared::StageConstants;

const char* lightingModeName(LightingMode mode) {
  switch (mode) {
    case LightingMode::Mis: return "mis";
    case LightingMode::NeeOnly: return "nee";
    case LightingMode::BsdfOnly: return "bsdf";
  }
  return "?";
}

const char* samplerName(SamplerKind kind) {
  switch (kind) {
    case SamplerKind::Quadtree: return "quadtree";
    case SamplerKind::Cosine: return "cosine";
    case SamplerKind::Uniform: return "uniform";
    case SamplerKind::Analytic: return "analytic";
    case SamplerKind::Tabulated: return "tabulated";
  }
  return "?";
}

const char* componentSelectionName(ComponentSelection mode) {
  return mode == ComponentSelection::Uniform ? "uniform" : "albedo";
}

bool parseComponentSelection(const std::string& name, ComponentSelection& mode) {
  for (ComponentSelection m : {ComponentSelection::Albedo, ComponentSelection::Uniform})
    if (name == componentSelectionName(m)) {
      mode = m;
      return true;
    }
  return false;
}

bool parseSampler(const std::string& name, SamplerKind& kind) {
  for (SamplerKind k : {SamplerKind::Quadtree, SamplerKind::Cosine, SamplerKind::Uniform, SamplerKind::Analytic,
                        SamplerKind::Tabulated})
    if (name == samplerName(k)) {
      kind = k;
      return true;
    }
  return false;
}

const char* rouletteModeName(RouletteMode mode) { return mode == RouletteMode::Albedo ? "albedo" : "throughput"; }

bool parseRouletteMode(const std::string& name, RouletteMode& mode) {
  for (RouletteMode m : {RouletteMode::Throughput, RouletteMode::Albedo})
    if (name == rouletteModeName(m)) {
      mode = m;
      return true;
    }
  return false;
}

const char* rngModeName(RngMode mode) { return mode == RngMode::Qmc ? "qmc" : "pcg"; }

namespace {

double seconds(std::chrono::steady_clock::time_point a) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
}

glm::vec4 v4(glm::vec3 v, float w = 0.0f) { return glm::vec4(v, w); }

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

Renderer::Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings)
    : m_ctx(ctx), m_settings(settings) {
  if (settings.width == 0 || settings.height == 0) throw Error("image size must be at least 1x1");
  std::uint64_t pixels = std::uint64_t(settings.width) * settings.height;
  if (pixels > (1ull << 28)) throw Error("image too large: at most 2^28 pixels");
  // One indirect dispatch covers a whole queue: its group count must stay <= 65535.
  std::uint32_t maxChunk = std::min<std::uint32_t>(settings.maxPathsPerChunk, 65535u * WORKGROUP_SIZE);
  m_capacity = static_cast<std::uint32_t>(std::min<std::uint64_t>(pixels, maxChunk));
  uploadScene(scene);
  auto t0 = std::chrono::steady_clock::now();
  createPipelines();
  m_summary.pipelineSeconds = seconds(t0);

  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = m_ctx.commandPool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(m_ctx.device, &ai, &m_cmd));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(m_ctx.device, &fci, nullptr, &m_fence));
  if (settings.timeStages && m_ctx.properties.limits.timestampComputeAndGraphics) {
    m_queryCapacity = 8 + (settings.maxDepth + 1) * 8;
    VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    q.queryType = VK_QUERY_TYPE_TIMESTAMP;
    q.queryCount = m_queryCapacity;
    VK_CHECK(vkCreateQueryPool(m_ctx.device, &q, nullptr, &m_queryPool));
  }
}

void Renderer::mark(VkCommandBuffer cmd, const char* stage) {
  if (!m_queryPool) return;
  std::uint32_t index = static_cast<std::uint32_t>(m_marks.size()) + 1;
  if (stage == nullptr) index = 0;  // the start
  else m_marks.push_back(stage);
  if (index < m_queryCapacity) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, m_queryPool, index);
}

Renderer::~Renderer() {
  VkDevice d = m_ctx.device;
  vkDeviceWaitIdle(d);
  if (m_fence) vkDestroyFence(d, m_fence, nullptr);
  if (m_queryPool) vkDestroyQueryPool(d, m_queryPool, nullptr);
  if (m_cmd) vkFreeCommandBuffers(d, m_ctx.commandPool, 1, &m_cmd);
  for (auto* p : {&m_camera, &m_submit, &m_intersect, &m_shadow, &m_accumulate}) vk::destroyComputePipeline(m_ctx, *p);
  for (auto& p : m_shade) vk::destroyComputePipeline(m_ctx, p);
  vk::destroyGlobalsBinding(m_ctx, m_binding);
  for (auto& b : m_buffers) vk::destroyBuffer(m_ctx, b);
  vk::destroyBuffer(m_ctx, m_globalsBuffer);
}

void Renderer::uploadScene(const Scene& scene) {
  const std::size_t triCount = scene.triangleCount();
  m_summary.triangles = triCount;
  m_summary.materials = scene.materials.size();

  // ---- BVH (binned SAH) and triangles in BVH order ----
  auto t0 = std::chrono::steady_clock::now();
  Bvh bvh = buildBvh(scene.positions);
  m_summary.bvhSeconds = seconds(t0);
  m_summary.bvhNodes = static_cast<std::uint32_t>(bvh.nodes.size());

  // ---- Materials and the shade slots this render needs ----
  // A slot is a shade pipeline and its queue. Key: {0, model} for a single-model material,
  // {n, model_0, ..., model_{n-1}} for a combined one (one pipeline per tuple of component models,
  // in the material's order). Sorted, so single-model slots keep the order of their model ids.
  std::vector<GpuMaterial> materials(std::max<std::size_t>(scene.materials.size(), 1));
  std::vector<GpuComponent> components;
  std::vector<bool> materialUsed(materials.size(), false);
  for (std::uint32_t m : scene.triangleMaterial) materialUsed.at(m) = true;
  auto slotKey = [](const Material& m) {
    std::vector<std::uint32_t> key;
    if (!m.combined()) return std::vector<std::uint32_t>{0u, m.model};
    key.push_back(static_cast<std::uint32_t>(m.components.size()));
    for (const MaterialComponent& c : m.components) key.push_back(c.model);
    return key;
  };
  std::vector<std::vector<std::uint32_t>> slots;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    if (!materialUsed[i]) continue;
    const Material& m = scene.materials[i];
    if (m.components.size() > MAX_COMPONENTS)
      throw Error("material " + m.name + ": " + std::to_string(m.components.size()) + " components, at most " +
                  std::to_string(MAX_COMPONENTS));
    std::vector<std::uint32_t> key = slotKey(m);
    if (std::find(slots.begin(), slots.end(), key) == slots.end()) slots.push_back(key);
  }
  std::sort(slots.begin(), slots.end());
  if (slots.size() > MAX_MODEL_SLOTS)
    throw Error("the scene uses " + std::to_string(slots.size()) + " distinct models and combinations of models, at most " +
                std::to_string(MAX_MODEL_SLOTS));
  m_slotKeys = slots;
  for (const auto& key : slots) {
    std::string name;
    for (std::size_t k = 1; k < key.size(); ++k) name += (k > 1 ? "+" : "") + modelById(key[k]).name;
    m_summary.models.push_back(name);
  }
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& src = scene.materials[i];
    GpuMaterial& dst = materials[i];
    std::uint32_t slot = 0;
    std::vector<std::uint32_t> key = slotKey(src);
    for (std::uint32_t s = 0; s < slots.size(); ++s)
      if (slots[s] == key) slot = s;
    std::uint32_t flags = 0;
    if (luminance(src.emission) > 0.0f || src.emission.x > 0 || src.emission.y > 0 || src.emission.z > 0)
      flags |= MATERIAL_EMISSIVE;
    bool allDelta = true;
    for (const MaterialComponent& c : src.components) allDelta = allDelta && modelById(c.model).delta;
    if (src.combined() ? allDelta : modelById(src.model).delta) flags |= MATERIAL_DELTA;
    if (src.combined()) flags |= MATERIAL_COMBINED;
    dst.info = glm::uvec4(src.combined() ? src.components[0].model : src.model, flags, INVALID_INDEX, slot);
    dst.emission = v4(src.emission);
    dst.params = src.params;
    dst.components = glm::uvec4(0u);
    if (src.combined() && materialUsed[i]) {
      dst.components = glm::uvec4(static_cast<std::uint32_t>(components.size()),
                                  static_cast<std::uint32_t>(src.components.size()), 0u, 0u);
      for (const MaterialComponent& c : src.components) {
        GpuComponent g{};
        g.info = glm::uvec4(c.model, INVALID_INDEX, 0u, 0u);
        g.data = glm::vec4(c.weight, 0.0f, 0.0f, 0.0f);
        g.params = c.params;
        components.push_back(g);
      }
    }
  }

  // ---- Triangles, shading data and lights ----
  std::vector<GpuTriangle> tris(std::max<std::size_t>(triCount, 1));
  std::vector<GpuTriShading> shading(std::max<std::size_t>(triCount, 1));
  std::vector<GpuLight> lights;
  std::vector<double> weights;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (std::size_t k = 0; k < triCount; ++k) {
    std::uint32_t src = bvh.triangleOrder.empty() ? static_cast<std::uint32_t>(k) : bvh.triangleOrder[k];
    glm::vec3 p0 = scene.positions[3 * src], p1 = scene.positions[3 * src + 1], p2 = scene.positions[3 * src + 2];
    for (glm::vec3 p : {p0, p1, p2}) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    tris[k].v0 = v4(p0);
    tris[k].e1 = v4(p1 - p0);
    tris[k].e2 = v4(p2 - p0);
    shading[k].n0 = v4(scene.normals[3 * src]);
    shading[k].n1 = v4(scene.normals[3 * src + 1]);
    shading[k].n2 = v4(scene.normals[3 * src + 2]);
    std::uint32_t mat = scene.triangleMaterial[src];
    std::uint32_t lightIndex = INVALID_INDEX;
    if (materials[mat].info.y & MATERIAL_EMISSIVE) {
      float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
      double power = double(luminance(scene.materials[mat].emission)) * area * M_PI;
      if (power > 0) {
        lightIndex = static_cast<std::uint32_t>(lights.size());
        GpuLight l{};
        l.info = glm::uvec4(LIGHT_TRIANGLE, static_cast<std::uint32_t>(k), 0u, 0u);
        lights.push_back(l);
        weights.push_back(power);
      }
    }
    shading[k].info = glm::uvec4(mat, lightIndex, 0u, 0u);
  }
  glm::vec3 centre = triCount ? 0.5f * (lo + hi) : glm::vec3(0.0f);
  float radius = triCount ? 0.5f * glm::length(hi - lo) : 1.0f;
  for (const PunctualLight& pl : scene.lights) {
    GpuLight l{};
    double power = 0;
    float lum = luminance(pl.intensity);
    switch (pl.type) {
      case LightType::Point:
        l.info.x = LIGHT_POINT;
        power = 4.0 * M_PI * lum;
        break;
      case LightType::Spot:
        l.info.x = LIGHT_SPOT;
        power = 2.0 * M_PI * (1.0 - std::cos(0.5 * (pl.innerConeAngle + pl.outerConeAngle))) * lum;
        break;
      case LightType::Directional:
        l.info.x = LIGHT_DIRECTIONAL;
        power = M_PI * double(radius) * radius * lum;
        break;
    }
    if (!(power > 0)) continue;
    l.position = v4(pl.position);
    l.direction = v4(glm::normalize(pl.direction));
    l.intensity = v4(pl.intensity);
    l.cone = glm::vec4(std::cos(pl.innerConeAngle), std::cos(pl.outerConeAngle), 0.0f, 0.0f);
    lights.push_back(l);
    weights.push_back(power);
  }
  m_summary.lights = lights.size();
  // Light selection proportional to estimated power.
  std::vector<float> cdf(lights.size() + 1, 0.0f);
  double total = 0;
  for (double w : weights) total += w;
  double acc = 0;
  for (std::size_t i = 0; i < weights.size(); ++i) {
    acc += weights[i];
    cdf[i + 1] = static_cast<float>(acc / total);
  }
  if (!weights.empty()) cdf.back() = 1.0f;
  if (lights.empty()) lights.resize(1);

  // ---- Device buffers ----
  std::uint64_t pixels = std::uint64_t(m_settings.width) * m_settings.height;
  // Refuse before allocating when the render cannot fit the device: a clear message instead of
  // an allocation failure halfway (or the driver swapping).
  {
    const std::uint64_t cap = m_capacity;
    std::uint64_t need = std::max<std::size_t>(bvh.nodes.size(), 1) * sizeof(BvhNode) + tris.size() * sizeof(GpuTriangle) +
                         shading.size() * sizeof(GpuTriShading) + materials.size() * sizeof(GpuMaterial) +
                         lights.size() * sizeof(GpuLight) + cdf.size() * 4 + pixels * 32 + cap * 9 * 16 +
                         components.size() * sizeof(GpuComponent) +
                         (QUEUE_HEADER_UINTS + (QUEUE_SHADE_BASE + slots.size()) * cap) * 4;
    std::uint64_t have = vk::deviceLocalHeapSize(m_ctx);
    auto mib = [](std::uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
    if (have && need > have)
      throw Error("the render needs about " + mib(need) + " of device memory (" + std::to_string(triCount) +
                  " triangles, " + std::to_string(m_settings.width) + "x" + std::to_string(m_settings.height) +
                  " pixels) but " + m_ctx.deviceName + " has " + mib(have) +
                  ": use a smaller image or a simpler scene");
  }
  auto make = [&](VkDeviceSize bytes, const std::string& what, const void* data = nullptr,
                  VkBufferUsageFlags usage = 0, bool host = false) -> vk::Buffer* {
    m_buffers.push_back(vk::createBuffer(m_ctx, bytes, usage, host, what));
    m_summary.deviceBytes += m_buffers.back().size;
    if (data) vk::uploadBuffer(m_ctx, m_buffers.back(), data, bytes);
    return &m_buffers.back();
  };
  m_buffers.reserve(32);  // pointers into m_buffers stay valid
  std::vector<BvhNode> nodes = bvh.nodes;
  if (nodes.empty()) {  // no triangles: a root whose two children are empty boxes
    BvhNode n{};
    n.min0 = n.min1 = glm::vec4(INFINITY);
    n.max0 = n.max1 = glm::vec4(-INFINITY);
    n.link = glm::uvec4(INVALID_INDEX, INVALID_INDEX, 0u, 0u);
    nodes.push_back(n);
  }
  const std::uint64_t cap = m_capacity;
  Globals g{};
  g.bvh = make(nodes.size() * sizeof(BvhNode), "BVH", nodes.data())->address;
  g.triangles = make(tris.size() * sizeof(GpuTriangle), "triangle", tris.data())->address;
  g.shading = make(shading.size() * sizeof(GpuTriShading), "triangle shading", shading.data())->address;
  vk::Buffer* materialBuffer = make(materials.size() * sizeof(GpuMaterial), "material", materials.data());
  g.materials = materialBuffer->address;
  g.lights = make(lights.size() * sizeof(GpuLight), "light", lights.data())->address;
  g.lightCdf = make(cdf.size() * sizeof(float), "light CDF", cdf.data())->address;
  m_film = make(pixels * 16, "film");
  m_filmSq = make(pixels * 16, "film variance");
  g.film = m_film->address;
  g.filmSq = m_filmSq->address;
  g.pathOrigin = make(cap * 16, "path origin")->address;
  g.pathDirection = make(cap * 16, "path direction")->address;
  g.pathThroughput = make(cap * 16, "path throughput")->address;
  g.pathRadiance = make(cap * 16, "path radiance")->address;
  g.pathInfo = make(cap * 16, "path info")->address;
  g.pathHit = make(cap * 16, "path hit")->address;
  g.shadowOrigin = make(cap * 16, "shadow ray origin")->address;
  g.shadowDirection = make(cap * 16, "shadow ray direction")->address;
  g.shadowRadiance = make(cap * 16, "shadow ray radiance")->address;
  std::uint64_t queueUints = QUEUE_HEADER_UINTS + (QUEUE_SHADE_BASE + slots.size()) * cap;
  m_queues = make(queueUints * 4, "queue");
  g.queues = m_queues->address;
  m_args = make(QUEUE_COUNT * sizeof(DispatchArgs), "dispatch arguments", nullptr, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  g.dispatchArgs = m_args->address;
  m_stats = make(STAT_COUNT * 4, "statistics", nullptr, 0, true);
  std::memset(m_stats->mapped, 0, STAT_COUNT * 4);
  g.stats = m_stats->address;
  // ---- The generic sampler's quadtrees: only for the non-delta materials (and non-delta
  // components of combined materials) the scene uses; identical (model, params) share a set ----
  std::vector<std::pair<std::uint32_t, shared::BrdfParams>> toBuild;
  std::vector<std::uint32_t*> builtSet;  // where each built set's index goes
  // The tabulated strategy's tables go to the very same places (GpuMaterial.info.z, GpuComponent.info.y):
  // the shade stage passes that index to bsdfSample as the set of the strategy it is specialised for.
  if (m_settings.sampler == SamplerKind::Quadtree || m_settings.sampler == SamplerKind::Tabulated)
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
      if (!materialUsed[i]) continue;
      const Material& m = scene.materials[i];
      if (!m.combined() && !modelById(m.model).delta) {
        toBuild.push_back({m.model, m.params});
        builtSet.push_back(&materials[i].info.z);
      }
      for (std::size_t k = 0; k < m.components.size(); ++k)
        if (!modelById(m.components[k].model).delta) {
          toBuild.push_back({m.components[k].model, m.components[k].params});
          builtSet.push_back(&components[materials[i].components.x + k].info.y);
        }
    }
  quadtree::SamplerTables qt;
  sampling::TabulatedTables tab;
  if (!toBuild.empty() && m_settings.sampler == SamplerKind::Tabulated) {
    // Memory budget: the default 64 KiB per table (90 x 180 cells; docs/strategies.md). Sizing each
    // material's tables like its quadtree (bytesPerTableLike) would need the quadtree built first
    // (seconds to minutes per material when the cache is cold), so renders use the default.
    std::vector<std::uint32_t> setOf;
    tab = sampling::buildTabulatedTables(toBuild, sampling::TabulatedSettings{}, setOf);
    for (std::size_t k = 0; k < builtSet.size(); ++k) *builtSet[k] = setOf[k];
    m_summary.samplerSeconds = tab.seconds;
    m_summary.samplerTrees = static_cast<std::uint32_t>(tab.tables.size());
    m_summary.samplerBytes = tab.bytes();
    vk::uploadBuffer(m_ctx, *materialBuffer, materials.data(), materials.size() * sizeof(GpuMaterial));
  } else if (!toBuild.empty()) {
    std::vector<std::uint32_t> setOf;
    quadtree::QuadtreeSettings qs;
    qs.thetaTables = std::max(1u, m_settings.samplerThetaTables);
    qs.phiTables = std::max(2u, m_settings.samplerPhiTables);
    qt = quadtree::buildSamplerTables(toBuild, qs, setOf);
    for (std::size_t k = 0; k < builtSet.size(); ++k) *builtSet[k] = setOf[k];
    m_summary.samplerSeconds = qt.seconds;
    m_summary.samplerTrees = static_cast<std::uint32_t>(qt.tables.size());
    m_summary.samplerBytes = qt.bytes();
    m_summary.samplerCacheHits = qt.cacheHits;
    m_summary.samplerCacheMisses = qt.cacheMisses;
    m_summary.samplerCacheRejected = qt.cacheRejected;
    vk::uploadBuffer(m_ctx, *materialBuffer, materials.data(), materials.size() * sizeof(GpuMaterial));
  }
  // Components choose by a CPU-tabulated albedo over cos theta_o (the choice probability must be
  // known before sampling; any positive function of wo keeps the estimator unbiased, the albedo
  // keeps the weights near 1): its largest RGB channel for every non-delta component under the
  // throughput roulette (combined.h: no channel is amplified), its luminance under the albedo
  // roulette for the components without a QuadSet (quadtree components read their set's table).
  // Floored at 1e-4 so that no component whose BRDF is not zero is ever left unsampled.
  const bool maxChannel = m_settings.roulette == RouletteMode::Throughput;
  for (GpuComponent& c : components) {
    // (Only quadtree components read their albedo from their set: tabulated ones use this table too.)
    if (modelById(c.info.x).delta) continue;
    if (!maxChannel && m_settings.sampler == SamplerKind::Quadtree && c.info.y != INVALID_INDEX) continue;
    float table[COMPONENT_ALBEDO_NODES];
    for (std::uint32_t n = 0; n < COMPONENT_ALBEDO_NODES; ++n) {
      double cosTheta = std::max(double(n) / (COMPONENT_ALBEDO_NODES - 1), 0.02);
      double thetaDeg = std::acos(cosTheta) * 180.0 / M_PI;
      double a;
      if (maxChannel) {
        double rgb[3];
        directionalAlbedoRgb(c.info.x, c.params, thetaDeg, 0.0, rgb);
        a = std::max(rgb[0], std::max(rgb[1], rgb[2]));
      } else {
        a = directionalAlbedo(c.info.x, c.params, thetaDeg);
      }
      table[n] = std::isfinite(a) ? std::max(float(a), 1e-4f) : 1e-4f;
    }
    c.albedoLo = glm::vec4(table[0], table[1], table[2], table[3]);
    c.albedoHi = glm::vec4(table[4], table[5], table[6], table[7]);
  }
  g.components = make(std::max<std::size_t>(components.size(), 1) * sizeof(GpuComponent), "material components",
                      components.empty() ? nullptr : components.data())->address;
  auto orOne = [](auto& v) {
    if (v.empty()) v.resize(1);
    return v.size();
  };
  g.quadSets = make(orOne(qt.sets) * sizeof(shared::QuadSet), "quadtree sets", qt.sets.data())->address;
  g.quadTables = make(orOne(qt.tables) * sizeof(shared::QuadTable), "quadtree tables", qt.tables.data())->address;
  g.quadNodes = make(orOne(qt.nodes) * sizeof(shared::QuadNode), "quadtree nodes", qt.nodes.data())->address;
  g.quadLeaves = make(orOne(qt.leaves) * sizeof(shared::QuadLeaf), "quadtree leaves", qt.leaves.data())->address;
  g.tabSets = make(orOne(tab.sets) * sizeof(shared::TabSet), "tabulated sets", tab.sets.data())->address;
  g.tabTables = make(orOne(tab.tables) * sizeof(shared::TabTable), "tabulated tables", tab.tables.data())->address;
  g.tabData = make(orOne(tab.data) * sizeof(float), "tabulated cdfs", tab.data.data())->address;
  g.display = 0;

  // Film starts at zero.
  VkCommandBuffer cmd = vk::beginOneShot(m_ctx);
  vkCmdFillBuffer(cmd, m_film->buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(cmd, m_filmSq->buffer, 0, VK_WHOLE_SIZE, 0);
  vk::endOneShot(m_ctx, cmd);

  m_cameraState = scene.hasCamera ? scene.camera : frameScene(scene);
  g.sceneSphere = glm::vec4(centre, radius);
  g.lightTotal = glm::vec4(float(total), 0, 0, 0);
  g.background = v4(scene.background);
  g.image = glm::uvec4(m_settings.width, m_settings.height, 0u, 0u);
  g.frame = glm::uvec4(0u, m_settings.seed, m_settings.maxDepth, m_capacity);
  g.counts = glm::uvec4(static_cast<std::uint32_t>(materials.size()), static_cast<std::uint32_t>(weights.size()),
                        static_cast<std::uint32_t>(triCount), static_cast<std::uint32_t>(m_settings.lighting));
  g.options = glm::uvec4(static_cast<std::uint32_t>(m_settings.rng), static_cast<std::uint32_t>(m_settings.components),
                         static_cast<std::uint32_t>(m_settings.roulette), 0u);
  m_globals.resize(sizeof(Globals));
  std::memcpy(m_globals.data(), &g, sizeof g);
  writeCamera(m_cameraState);
  m_globalsBuffer = vk::createBuffer(m_ctx, sizeof(Globals), 0, true, "globals");
}

void Renderer::writeCamera(const Camera& cam) {
  Globals* g = reinterpret_cast<Globals*>(m_globals.data());
  glm::vec3 f = glm::normalize(cam.forward);
  glm::vec3 right = glm::normalize(glm::cross(f, cam.up));
  glm::vec3 up = glm::cross(right, f);
  float aspect = float(m_settings.width) / float(m_settings.height);
  g->camPosition = v4(cam.position, cam.orthographic ? 1.0f : 0.0f);
  g->camForward = v4(f);
  if (cam.orthographic) {
    g->camRight = v4(right * cam.xmag);
    g->camUp = v4(up * cam.ymag);
  } else {
    float th = std::tan(0.5f * cam.yfov);
    g->camRight = v4(right * (th * aspect));
    g->camUp = v4(up * th);
  }
}

void Renderer::reset() {
  VkCommandBuffer cmd = vk::beginOneShot(m_ctx);
  vkCmdFillBuffer(cmd, m_film->buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(cmd, m_filmSq->buffer, 0, VK_WHOLE_SIZE, 0);
  vk::endOneShot(m_ctx, cmd);
  m_samples = 0;
}

void Renderer::setCamera(const Camera& camera) {
  m_cameraState = camera;
  writeCamera(camera);
  reset();
}

void Renderer::setLighting(LightingMode mode) {
  m_settings.lighting = mode;
  reinterpret_cast<Globals*>(m_globals.data())->counts.w = static_cast<std::uint32_t>(mode);
  std::memcpy(m_globalsBuffer.mapped, m_globals.data(), sizeof(Globals));
  reset();
}

void Renderer::setDisplayBuffer(VkDeviceAddress address) {
  reinterpret_cast<Globals*>(m_globals.data())->display = address;
  std::memcpy(m_globalsBuffer.mapped, m_globals.data(), sizeof(Globals));
}

void Renderer::createPipelines() {
  m_binding = vk::createGlobalsBinding(m_ctx, m_globalsBuffer.buffer, sizeof(StageConstants));
  m_pipelineLayout = m_binding.layout;
  m_set = m_binding.set;
  m_camera = vk::createComputePipeline(m_ctx, m_pipelineLayout, "camera");
  m_submit = vk::createComputePipeline(m_ctx, m_pipelineLayout, "submit");
  m_intersect = vk::createComputePipeline(m_ctx, m_pipelineLayout, "intersect");
  m_shadow = vk::createComputePipeline(m_ctx, m_pipelineLayout, "shadow");
  m_accumulate = vk::createComputePipeline(m_ctx, m_pipelineLayout, "accumulate");
  // Only the models (and combinations) this scene uses: one specialised shade pipeline each,
  // created on all cores (drivers compile at creation; lavapipe takes ~0.3 s per shade pipeline,
  // single-threaded). Single-model pipelines get exactly (MODEL_ID, SAMPLER) as before;
  // combined ones (MODEL_ID unused, SAMPLER, COMPONENT_COUNT, MODEL_0..MODEL_3).
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
          // One module per strategy (CMakeLists.txt): shade_sN / shade_combined_sN.
          const std::string module = std::string(key[0] > 0 ? "shade_combined" : "shade") + "_s" + std::to_string(sampler);
          m_shade[s] = vk::createComputePipeline(m_ctx, m_pipelineLayout, module, spec);
        } catch (const std::exception& e) {
          errors[s] = e.what();
        }
      }
    });
  for (auto& w : workers) w.join();
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

void Renderer::dispatchSubmit(VkCommandBuffer cmd, std::uint32_t queueA, std::uint32_t zeroFirst,
                              std::uint32_t zeroCount, std::uint32_t argsFirst, std::uint32_t argsCount) {
  StageConstants pc{};
  pc.queueA = queueA;
  pc.queueB = zeroFirst;
  pc.queueBCount = zeroCount;
  pc.queueC = argsFirst;
  pc.queueCCount = argsCount;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_submit.pipeline);
  vkCmdPushConstants(cmd, m_pipelineLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(cmd, 1, 1, 1);
  vk::computeBarrier(cmd);
}

void Renderer::recordPass(VkCommandBuffer cmd, std::uint32_t chunkStart, std::uint32_t chunkCount) {
  (void)chunkStart;
  const std::uint32_t slots = static_cast<std::uint32_t>(m_slotKeys.size());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_pipelineLayout, 0, 1, &m_set, 0, nullptr);
  m_marks.clear();
  if (m_queryPool) vkCmdResetQueryPool(cmd, m_queryPool, 0, m_queryCapacity);
  mark(cmd, nullptr);
  // All queues start empty.
  vkCmdFillBuffer(cmd, m_queues->buffer, 0, QUEUE_HEADER_UINTS * 4, 0);
  vk::computeBarrier(cmd);

  StageConstants pc{};
  auto bindAndPush = [&](const vk::ComputePipeline& p) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdPushConstants(cmd, m_pipelineLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  };
  const std::uint32_t groups = (chunkCount + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE;
  bindAndPush(m_camera);
  vkCmdDispatch(cmd, groups, 1, 1);
  vk::computeBarrier(cmd);
  mark(cmd, "camera");

  for (std::uint32_t bounce = 0; bounce <= m_settings.maxDepth; ++bounce) {
    const std::uint32_t rayQueue = bounce & 1u;
    pc.bounce = bounce;
    // intersect <- ray queue; empties the shadow queue of the previous bounce.
    dispatchSubmit(cmd, rayQueue, QUEUE_SHADOW, 1, 0, 0);
    mark(cmd, "submit");
    bindAndPush(m_intersect);
    vkCmdDispatchIndirect(cmd, m_args->buffer, rayQueue * sizeof(DispatchArgs));
    vk::computeBarrier(cmd);
    mark(cmd, "intersect");
    // shade(model) <- shade queues; empties the consumed ray queue.
    dispatchSubmit(cmd, INVALID_INDEX, rayQueue, 1, QUEUE_SHADE_BASE, slots);
    mark(cmd, "submit");
    for (std::uint32_t s = 0; s < slots; ++s) {
      pc.modelSlot = s;
      bindAndPush(m_shade[s]);
      vkCmdDispatchIndirect(cmd, m_args->buffer, (QUEUE_SHADE_BASE + s) * sizeof(DispatchArgs));
    }
    vk::computeBarrier(cmd);
    mark(cmd, "shade");
    // shadow <- shadow queue; empties the shade queues.
    dispatchSubmit(cmd, QUEUE_SHADOW, QUEUE_SHADE_BASE, slots, 0, 0);
    mark(cmd, "submit");
    bindAndPush(m_shadow);
    vkCmdDispatchIndirect(cmd, m_args->buffer, QUEUE_SHADOW * sizeof(DispatchArgs));
    vk::computeBarrier(cmd);
    mark(cmd, "shadow");
  }
  bindAndPush(m_accumulate);
  vkCmdDispatch(cmd, groups, 1, 1);
  vk::computeBarrier(cmd);
  mark(cmd, "accumulate");
}

void Renderer::renderPass() {
  // Fault injection for the tests of device loss (no GPU can be lost on purpose):
  // NUSSELT_FAULT_DEVICE_LOST_AFTER=N makes the pass after N samples fail as a lost device would.
  static const char* fault = std::getenv("NUSSELT_FAULT_DEVICE_LOST_AFTER");
  if (fault && m_samples >= std::strtoul(fault, nullptr, 10)) VK_CHECK(VK_ERROR_DEVICE_LOST);
  const std::uint64_t pixels = std::uint64_t(m_settings.width) * m_settings.height;
  for (std::uint64_t start = 0; start < pixels; start += m_capacity) {
    std::uint32_t count = static_cast<std::uint32_t>(std::min<std::uint64_t>(m_capacity, pixels - start));
    Globals* g = reinterpret_cast<Globals*>(m_globals.data());
    g->image.z = static_cast<std::uint32_t>(start);
    g->image.w = count;
    g->frame.x = m_settings.sampleOffset + m_samples;
    std::memcpy(m_globalsBuffer.mapped, m_globals.data(), sizeof(Globals));

    VK_CHECK(vkResetCommandBuffer(m_cmd, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(m_cmd, &bi));
    recordPass(m_cmd, g->image.z, count);
    VK_CHECK(vkEndCommandBuffer(m_cmd));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &m_cmd;
    VK_CHECK(vkResetFences(m_ctx.device, 1, &m_fence));
    VK_CHECK(vkQueueSubmit(m_ctx.queue, 1, &si, m_fence));
    VK_CHECK(vkWaitForFences(m_ctx.device, 1, &m_fence, VK_TRUE, UINT64_MAX));
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
    // Fold the 32-bit device counters into 64-bit totals and restart them.
    std::uint32_t* s = static_cast<std::uint32_t*>(m_stats->mapped);
    m_totals.rays += s[STAT_RAYS];
    m_totals.shadowRays += s[STAT_SHADOW_RAYS];
    m_totals.nonFiniteSamples += s[STAT_NONFINITE_SAMPLES];
    m_totals.bvhStackOverflows += s[STAT_BVH_STACK_OVERFLOW];
    m_totals.samplerBoundViolations += s[STAT_SAMPLER_BOUND_VIOLATIONS];
    m_totals.samplerTrialFailures += s[STAT_SAMPLER_TRIAL_FAILURES];
    std::memset(s, 0, STAT_COUNT * 4);
  }
  ++m_samples;
}

Image Renderer::image(bool withVariance) {
  const std::uint64_t pixels = std::uint64_t(m_settings.width) * m_settings.height;
  std::vector<glm::vec4> sum(pixels), sumSq(pixels);
  vk::downloadBuffer(m_ctx, *m_film, sum.data(), pixels * 16);
  vk::downloadBuffer(m_ctx, *m_filmSq, sumSq.data(), pixels * 16);
  Image img;
  img.width = static_cast<int>(m_settings.width);
  img.height = static_cast<int>(m_settings.height);
  img.rgb.resize(pixels * 3);
  if (withVariance) img.variance.resize(pixels * 3);
  img.sum.resize(pixels * 3);
  img.sumSq.resize(pixels * 3);
  for (std::uint64_t i = 0; i < pixels; ++i) {
    float n = sum[i].w;
    for (int c = 0; c < 3; ++c) {
      img.sum[3 * i + c] = sum[i][c];
      img.sumSq[3 * i + c] = sumSq[i][c];
      float mean = n > 0 ? sum[i][c] / n : 0.0f;
      img.rgb[3 * i + c] = mean;
      if (withVariance) {
        // Unbiased sample variance of one sample, divided by n: the variance of the mean.
        double var = n > 1 ? (double(sumSq[i][c]) - double(n) * mean * mean) / (double(n) - 1.0) : 0.0;
        img.variance[3 * i + c] = n > 0 ? static_cast<float>(std::max(var, 0.0) / n) : 0.0f;
      }
    }
  }
  return img;
}

RenderStats Renderer::stats() const { return m_totals; }

void Renderer::addStats(const RenderStats& c) {
  m_totals.rays += c.rays;
  m_totals.shadowRays += c.shadowRays;
  m_totals.nonFiniteSamples += c.nonFiniteSamples;
  m_totals.bvhStackOverflows += c.bvhStackOverflows;
  m_totals.samplerBoundViolations += c.samplerBoundViolations;
  m_totals.samplerTrialFailures += c.samplerTrialFailures;
}

void Renderer::restoreAccumulation(const Image& saved, std::uint32_t spp) {
  const std::uint64_t pixels = std::uint64_t(m_settings.width) * m_settings.height;
  if (saved.width != int(m_settings.width) || saved.height != int(m_settings.height))
    throw Error("the saved image is " + std::to_string(saved.width) + "x" + std::to_string(saved.height) +
                " but this render is " + std::to_string(m_settings.width) + "x" + std::to_string(m_settings.height));
  if (saved.sum.size() != pixels * 3 || saved.sumSq.size() != pixels * 3)
    throw Error("the saved image has no accumulation channels (sum.R/G/B, sumSq.R/G/B)");
  std::vector<glm::vec4> sum(pixels), sumSq(pixels);
  for (std::uint64_t i = 0; i < pixels; ++i) {
    sum[i] = glm::vec4(saved.sum[3 * i], saved.sum[3 * i + 1], saved.sum[3 * i + 2], float(spp));
    sumSq[i] = glm::vec4(saved.sumSq[3 * i], saved.sumSq[3 * i + 1], saved.sumSq[3 * i + 2], 0.0f);
  }
  vk::uploadBuffer(m_ctx, *m_film, sum.data(), pixels * 16);
  vk::uploadBuffer(m_ctx, *m_filmSq, sumSq.data(), pixels * 16);
  m_samples = spp;
}

}  // namespace nusselt
