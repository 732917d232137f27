// device_scene.h: the scene as the GPU sees it: triangles (in BVH order when there is a BVH) with
// their shading data, the BVH and/or the acceleration structures of ray queries, and the lights with their selection distribution (proportional to estimated power).
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

// Which traversal structures to build: the BVH for the GLSL traversal, the acceleration
// structures for ray queries (the device must have them: vk::Context::rayQuery), or both (the
// tests that hold one against the other: then both index the same triangle order).
struct TraversalStructures {
  bool bvh = true;
  bool accelerationStructures = false;
};

class DeviceScene {
 public:
  // Without a BVH the triangles keep the scene's order; with one they are in BVH order.
  DeviceScene(vk::Context& ctx, const Scene& scene, TraversalStructures structures = {});
  ~DeviceScene();
  DeviceScene(const DeviceScene&) = delete;
  DeviceScene& operator=(const DeviceScene&) = delete;

  // Device bytes the scene's buffers take for this many triangles and lights (before anything is
  // allocated: the render refuses early when it cannot fit), with the BVH or, when
  // accelerationStructures, an estimate of the acceleration structures and their build input.
  static std::uint64_t bytesFor(std::size_t triangles, std::size_t lights, bool accelerationStructures = false);

  // Buffer addresses, light count and distribution, scene bounds and background in the globals.
  void fillGlobals(shared::Globals& g) const;

  std::size_t triangles() const { return m_triangles; }
  std::size_t lights() const { return m_lights; }
  std::uint32_t bvhNodes() const { return m_bvhNodes; }
  double bvhSeconds() const { return m_bvhSeconds; }
  // The acceleration structures: build time (the Morton order when there is no BVH, the vertex
  // upload and both levels) and device bytes; 0 when not built.
  double accelerationSeconds() const { return m_accelSeconds; }
  std::uint64_t accelerationBytes() const { return m_blas.buffer.size + m_tlas.buffer.size; }
  std::uint64_t deviceBytes() const;
  // The triangles as the stages see them (g.triangles: v0, e1, e2 in BVH or Morton order).
  const vk::Buffer& triangleBuffer() const { return m_tris; }
  // Bounding sphere of the triangles (centre, radius; radius 1 without triangles).
  glm::vec4 boundingSphere() const { return m_sphere; }
  // The scene has an environment that emits (a light, and an escape stage for missed rays).
  bool hasEnvironment() const { return m_environmentLight != 0xffffffffu; }

 private:
  void release();  // destroys every buffer and structure (idempotent)

  vk::Context& m_ctx;
  std::size_t m_triangles = 0;
  std::size_t m_lights = 0;
  std::uint32_t m_bvhNodes = 0;
  double m_bvhSeconds = 0;
  glm::vec4 m_sphere{0.0f, 0.0f, 0.0f, 1.0f};
  glm::vec3 m_background{0.0f};
  double m_accelSeconds = 0;
  std::uint32_t m_environmentLight = 0xffffffffu;  // index in the light list, INVALID_INDEX: none
  vk::Buffer m_bvh, m_tris, m_shading, m_lightBuffer, m_lightCdf;
  vk::Buffer m_envTexels, m_envDistribution, m_envStruct;  // empty without an environment
  vk::Buffer m_texcoords;  // GpuTriTexcoords per triangle; one entry when the scene has no textures
  vk::Buffer m_tangents;   // 3 tangents (vec4) per triangle; one entry without normal maps
  vk::AccelerationStructure m_blas, m_tlas;
};

}  // namespace nusselt
