// device_scene.cpp: BVH or acceleration structures, triangles, shading data and lights on the device.
#include "render/device_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "../../shaders/shared/layout.h"
#include "render/environment.h"
#include "render/texture_table.h"
#include "scene/bvh.h"
#include "util/error.h"

namespace nusselt {

using shared::BvhNode;
using shared::GpuLight;
using shared::GpuTriangle;
using shared::GpuTriShading;

namespace {

glm::vec4 v4(glm::vec3 v, float w = 0.0f) { return glm::vec4(v, w); }

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

std::uint64_t DeviceScene::bytesFor(std::size_t triangles, std::size_t lights, bool accelerationStructures) {
  // Nodes store both children and leaves are not nodes: fewer nodes than triangles. The
  // acceleration structures are the driver's: lavapipe 25 took 104 bytes per triangle (the
  // dragon's 9.9 MiB), plus 36 bytes of vertices during the build; 160 leaves a margin. One
  // light per emitting triangle or punctual light at most.
  const std::uint64_t n = std::max<std::size_t>(triangles, 1);
  const std::uint64_t traversal = accelerationStructures ? 160 : sizeof(BvhNode);
  return n * traversal + n * (sizeof(GpuTriangle) + sizeof(GpuTriShading)) +
         (std::max<std::size_t>(lights, 1)) * (sizeof(GpuLight) + 4) + 4;
}

DeviceScene::DeviceScene(vk::Context& ctx, const Scene& scene, TraversalStructures structures)
    : m_ctx(ctx), m_background(scene.background) {
  const std::size_t triCount = scene.triangleCount();
  m_triangles = triCount;
  if (structures.accelerationStructures && !ctx.rayQuery)
    throw Error("internal: acceleration structures requested on a device without ray queries");
  if (triCount > UINT32_MAX / 3) throw Error("the scene has more than 2^32 / 3 triangles");

  // ---- BVH (binned SAH) and triangles in BVH order; ray queries alone need no BVH ----
  Bvh bvh;
  if (structures.bvh) {
    auto t0 = std::chrono::steady_clock::now();
    bvh = buildBvh(scene.positions);
    m_bvhSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    m_bvhNodes = static_cast<std::uint32_t>(bvh.nodes.size());
  }
  // Triangle order: the BVH's; without one, along a Morton curve, so that builders that split the
  // primitives in the order given (Mesa 25.0's lavapipe) get a spatially coherent tree: in the
  // scene's order lavapipe traced the dragon ~200x slower. GPU drivers sort for themselves.
  auto tOrder = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> order = structures.bvh ? bvh.triangleOrder : mortonOrder(scene.positions);
  const double orderSeconds =
      structures.bvh ? 0.0 : std::chrono::duration<double>(std::chrono::steady_clock::now() - tOrder).count();

  // ---- Triangles, shading data and area lights (emitting triangles, by power) ----
  std::vector<GpuTriangle> tris(std::max<std::size_t>(triCount, 1));
  std::vector<GpuTriShading> shading(std::max<std::size_t>(triCount, 1));
  std::vector<GpuLight> lights;
  std::vector<double> weights;
  // Texture coordinates in the same order, only for a scene with textures (absent sets read (0, 0)).
  const bool textured = sceneUsesTextures(scene);
  std::vector<shared::GpuTriTexcoords> texcoords(textured ? std::max<std::size_t>(triCount, 1) : 1);
  // Tangents (3 vec4 per triangle) only for a scene with a normal map.
  const bool normalMapped = sceneUsesNormalMaps(scene);
  std::vector<glm::vec4> tangents(normalMapped ? 3 * std::max<std::size_t>(triCount, 1) : 1, glm::vec4(0.0f));
  std::vector<float> vertices;  // the bottom level's input: 3 vertices per triangle, in g.triangles order
  if (structures.accelerationStructures) vertices.reserve(9 * triCount);
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (std::size_t k = 0; k < triCount; ++k) {
    std::uint32_t src = order.empty() ? static_cast<std::uint32_t>(k) : order[k];
    glm::vec3 p0 = scene.positions[3 * src], p1 = scene.positions[3 * src + 1], p2 = scene.positions[3 * src + 2];
    for (glm::vec3 p : {p0, p1, p2}) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    if (structures.accelerationStructures)
      for (glm::vec3 p : {p0, p1, p2}) vertices.insert(vertices.end(), {p.x, p.y, p.z});
    tris[k].v0 = v4(p0);
    tris[k].e1 = v4(p1 - p0);
    tris[k].e2 = v4(p2 - p0);
    shading[k].n0 = v4(scene.normals[3 * src]);
    shading[k].n1 = v4(scene.normals[3 * src + 1]);
    shading[k].n2 = v4(scene.normals[3 * src + 2]);
    if (textured) texcoords[k] = packTriTexcoords(scene, src);
    if (normalMapped)
      for (int c = 0; c < 3; ++c) tangents[3 * k + c] = scene.tangents[3 * src + c];
    std::uint32_t mat = scene.triangleMaterial[src];
    std::uint32_t lightIndex = INVALID_INDEX;
    if (scene.materials[mat].emits()) {
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
  m_sphere = glm::vec4(centre, radius);

  // ---- Punctual lights (KHR_lights_punctual), by power ----
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

  // ---- The environment: one light among the others, always chosen when alone. With others, by
  // default with probability 1/2 (a fixed split: the power of an environment, which reaches only
  // the parts of the scene that see the sky, compares badly with a lamp's); --env-select power:
  // in proportion to its power through the scene's bounding disc, pi R^2 x integral of luminance
  // over the sphere (pbrt-v4's ImageInfiniteLight::Phi). docs/environment.md measures both. ----
  const Environment envDesc = effectiveEnvironment(scene);
  const EnvironmentData env = buildEnvironment(envDesc);
  if (env.emits()) {
    double others = 0;
    for (double w : weights) others += w;
    GpuLight l{};
    l.info = glm::uvec4(LIGHT_ENVIRONMENT, 0u, 0u, 0u);
    m_environmentLight = static_cast<std::uint32_t>(lights.size());
    lights.push_back(l);
    const double power = M_PI * double(radius) * radius * env.luminanceIntegral;
    weights.push_back(others <= 0 ? 1.0 : envDesc.selectByPower ? power : others);
  }
  m_lights = weights.size();

  // ---- Light selection proportional to estimated power ----
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
  std::vector<BvhNode> nodes = bvh.nodes;
  if (nodes.empty()) {  // no triangles: a root whose two children are empty boxes
    shared::BvhNodeBoxes n{};
    n.min0 = n.min1 = glm::vec4(INFINITY);
    n.max0 = n.max1 = glm::vec4(-INFINITY);
    n.link = glm::uvec4(INVALID_INDEX, INVALID_INDEX, 0u, 0u);
    nodes.push_back(encodeBvhNode(n));
  }
  auto make = [&](vk::Buffer& b, VkDeviceSize bytes, const char* what, const void* data) {
    b = vk::createBuffer(m_ctx, bytes, 0, false, what);
    vk::uploadBuffer(m_ctx, b, data, bytes);
  };
  if (structures.bvh) make(m_bvh, nodes.size() * sizeof(BvhNode), "BVH", nodes.data());
  make(m_tris, tris.size() * sizeof(GpuTriangle), "triangle", tris.data());
  make(m_shading, shading.size() * sizeof(GpuTriShading), "triangle shading", shading.data());
  make(m_lightBuffer, lights.size() * sizeof(GpuLight), "light", lights.data());
  make(m_lightCdf, cdf.size() * sizeof(float), "light CDF", cdf.data());
  make(m_texcoords, texcoords.size() * sizeof(shared::GpuTriTexcoords), "triangle texture coordinates", texcoords.data());
  make(m_tangents, tangents.size() * sizeof(glm::vec4), "triangle tangents", tangents.data());

  if (env.emits()) {
    make(m_envTexels, env.texels.size() * sizeof(glm::vec4), "environment texels", env.texels.data());
    make(m_envDistribution, env.distribution.size() * sizeof(float), "environment distribution", env.distribution.data());
    shared::GpuEnvironment e = env.gpu;
    e.texels = m_envTexels.address;
    e.distribution = m_envDistribution.address;
    make(m_envStruct, sizeof e, "environment", &e);
  }

  // ---- Acceleration structures: one bottom level over all triangles (the scene is flattened to
  // world space), one top-level instance of it. Primitive i is triangle i of g.triangles. ----
  if (structures.accelerationStructures && triCount > 0) {
    auto t0 = std::chrono::steady_clock::now();
    vk::Buffer input = vk::createBuffer(m_ctx, vertices.size() * sizeof(float),
                                        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, false,
                                        "acceleration structure vertex");
    try {
      vk::uploadBuffer(m_ctx, input, vertices.data(), vertices.size() * sizeof(float));
      m_blas = vk::buildBottomLevel(m_ctx, input, static_cast<std::uint32_t>(triCount));
      m_tlas = vk::buildTopLevel(m_ctx, m_blas);
    } catch (...) {
      vk::destroyBuffer(m_ctx, input);
      release();  // the constructor does not complete: the destructor will not run
      throw;
    }
    // The structures hold their own copy of the geometry.
    vk::destroyBuffer(m_ctx, input);
    m_accelSeconds = orderSeconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
}

DeviceScene::~DeviceScene() { release(); }

void DeviceScene::release() {
  vk::destroyAccelerationStructure(m_ctx, m_tlas);
  vk::destroyAccelerationStructure(m_ctx, m_blas);
  for (vk::Buffer* b : {&m_bvh, &m_tris, &m_shading, &m_lightBuffer, &m_lightCdf, &m_envTexels, &m_envDistribution,
                        &m_envStruct, &m_texcoords, &m_tangents})
    vk::destroyBuffer(m_ctx, *b);
}

std::uint64_t DeviceScene::deviceBytes() const {
  return m_bvh.size + m_tris.size + m_shading.size + m_lightBuffer.size + m_lightCdf.size + m_envTexels.size +
         m_envDistribution.size + m_envStruct.size + m_texcoords.size + m_tangents.size + accelerationBytes();
}

void DeviceScene::fillGlobals(shared::Globals& g) const {
  g.bvh = m_bvh.address;
  g.triangles = m_tris.address;
  g.shading = m_shading.address;
  g.lights = m_lightBuffer.address;
  g.lightCdf = m_lightCdf.address;
  g.sceneSphere = m_sphere;
  g.background = v4(m_background);
  g.lightCount = static_cast<std::uint32_t>(m_lights);
  g.environmentLight = m_environmentLight;
  g.environment = m_envStruct.buffer ? m_envStruct.address : 0;
  g.triangleCount = static_cast<std::uint32_t>(m_triangles);
  g.texcoords = m_texcoords.address;
  g.tangents = m_tangents.address;
  g.tlasLow = static_cast<std::uint32_t>(m_tlas.address);
  g.tlasHigh = static_cast<std::uint32_t>(m_tlas.address >> 32);
}

}  // namespace nusselt
