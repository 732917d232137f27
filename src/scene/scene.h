// scene.h: the renderer's view of a scene, independent of glTF: world-space triangles with
// shading normals and a material each, materials (model + parameters + emission), punctual
// lights and a camera. Built by the glTF loader (gltf_loader.h) or by tests directly.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "../brdf/registry.h"

namespace nusselt {

// One term w * f_k of a combined material.
struct MaterialComponent {
  std::uint32_t model = MODEL_LAMBERT;  // MODEL_* id (any catalogue model, delta ones included)
  float weight = 1.0f;                  // finite, >= 0
  BrdfParams params{};                  // packed by packParams()
};

struct Material {
  std::string name;
  std::uint32_t model = MODEL_LAMBERT;  // MODEL_* id
  BrdfParams params{};                  // packed by packParams()
  glm::vec3 emission{0.0f};             // emitted radiance [W/(m^2 sr)], front faces only
  // Not empty: a combined material f = sum_k weight_k f_k (at most MAX_COMPONENTS terms; the
  // random-walk source's estimator picks one per bounce, shaders/shared/combined.h). model and
  // params then repeat the first component and are not used for shading.
  std::vector<MaterialComponent> components;

  bool combined() const { return !components.empty(); }
  // Emits light (any channel of the emission above zero): the material's triangles are lights.
  bool emits() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
};

enum class LightType { Point, Spot, Directional };

// KHR_lights_punctual, radiometric reading: colour * intensity is the radiant intensity [W/sr]
// of point and spot lights, and the irradiance [W/m^2] a directional light gives to a surface
// facing it. (The extension specifies candela and lux; we do not convert photometric units.)
struct PunctualLight {
  LightType type = LightType::Point;
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // where the light points (spot, directional)
  glm::vec3 intensity{1.0f};
  float innerConeAngle = 0.0f;             // radians (spot)
  float outerConeAngle = 0.7853981634f;    // radians (spot), glTF default pi/4
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  bool orthographic = false;
  float yfov = 0.8f;                     // radians (perspective)
  float aspectRatio = 0.0f;              // 0: take the image's
  float xmag = 1.0f, ymag = 1.0f;        // half extents (orthographic)
};

struct Scene {
  std::string sourcePath;
  // Three entries per triangle, world space. Degenerate triangles never get here.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;       // unit shading normals; the geometric normal where absent
  std::vector<std::uint32_t> triangleMaterial;  // one per triangle
  std::vector<Material> materials;
  std::vector<PunctualLight> lights;
  Camera camera;
  bool hasCamera = false;  // false: the renderer frames the scene with a default view
  glm::vec3 background{0.0f};  // radiance of escaping rays
  std::uint64_t droppedTriangles = 0;  // skipped: zero area, non-finite vertex, or a coordinate beyond 1e15
  std::vector<std::string> warnings;   // one line each, printed once by the caller

  std::size_t triangleCount() const { return triangleMaterial.size(); }
};

// The default view when a scene has no camera: looks at the bounding box from the +z side,
// framing it with a 45-degree vertical field of view.
Camera frameScene(const Scene& scene);

}  // namespace nusselt
