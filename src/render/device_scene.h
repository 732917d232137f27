// device_scene.h: the scene as the GPU sees it: triangles in BVH order with their shading data,
// the BVH, and the lights with their selection distribution (proportional to estimated power).
// Built once per scene; the material table and the integrators only read it.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "vk/vk.h"

namespace nusselt {

namespace shared {
struct Globals;
}

class DeviceScene {
 public:
  DeviceScene(vk::Context& ctx, const Scene& scene);
  ~DeviceScene();
  DeviceScene(const DeviceScene&) = delete;
  DeviceScene& operator=(const DeviceScene&) = delete;

  // Device bytes the scene's buffers take for this many triangles and lights (before anything is
  // allocated: the render refuses early when it cannot fit).
  static std::uint64_t bytesFor(std::size_t triangles, std::size_t lights);

  // Buffer addresses, light count and distribution, scene bounds and background in the globals.
  void fillGlobals(shared::Globals& g) const;

  std::size_t triangles() const { return m_triangles; }
  std::size_t lights() const { return m_lights; }
  std::uint32_t bvhNodes() const { return m_bvhNodes; }
  double bvhSeconds() const { return m_bvhSeconds; }
  std::uint64_t deviceBytes() const;
  // Bounding sphere of the triangles (centre, radius; radius 1 without triangles).
  glm::vec4 boundingSphere() const { return m_sphere; }
  // The scene has an environment that emits (a light, and an escape stage for missed rays).
  bool hasEnvironment() const { return m_environmentLight != 0xffffffffu; }

 private:
  vk::Context& m_ctx;
  std::size_t m_triangles = 0;
  std::size_t m_lights = 0;
  std::uint32_t m_bvhNodes = 0;
  double m_bvhSeconds = 0;
  glm::vec4 m_sphere{0.0f, 0.0f, 0.0f, 1.0f};
  glm::vec3 m_background{0.0f};
  std::uint32_t m_environmentLight = 0xffffffffu;  // index in the light list, INVALID_INDEX: none
  vk::Buffer m_bvh, m_tris, m_shading, m_lightBuffer, m_lightCdf;
  vk::Buffer m_envTexels, m_envDistribution, m_envStruct;  // empty without an environment
};

}  // namespace nusselt
