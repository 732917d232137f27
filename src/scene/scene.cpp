// scene.cpp: the default view for scenes without a camera; materials built in code.
#include "scene/scene.h"

#include <cmath>

#include "util/error.h"

namespace nusselt {

Camera frameScene(const Scene& scene) {
  Camera camera;
  camera.name = "default";
  camera.yfov = 0.7853981634f;  // 45 degrees
  camera.forward = glm::vec3(0.0f, 0.0f, -1.0f);
  camera.up = glm::vec3(0.0f, 1.0f, 0.0f);

  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : scene.positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  if (scene.positions.empty()) {
    lo = glm::dvec3(-1.0);
    hi = glm::dvec3(1.0);
  }
  glm::dvec3 centre = 0.5 * (lo + hi);
  double radius = 0.5 * glm::length(hi - lo);
  if (!(radius > 0.0) || !std::isfinite(radius)) radius = 1.0;
  // The bounding sphere fits the vertical field of view at this distance. Using the vertical
  // angle also frames it horizontally for any aspect ratio >= 1; narrower images may crop the
  // sides, which is acceptable for a preview view.
  double distance = radius / std::sin(0.5 * static_cast<double>(camera.yfov));
  camera.position = glm::vec3(centre + glm::dvec3(0.0, 0.0, distance));
  // Loaded scenes keep their coordinates within 1e15; a scene built in code might not.
  if (!std::isfinite(camera.position.x) || !std::isfinite(camera.position.y) || !std::isfinite(camera.position.z))
    camera.position = glm::vec3(0.0f, 0.0f, float(1.0 / std::sin(0.5 * static_cast<double>(camera.yfov))));
  return camera;
}

namespace {
const ModelSpec& catalogueModel(const std::string& model, const std::string& name) {
  const ModelSpec* spec = findModel(model);
  if (!spec) throw Error(name + ": unknown model \"" + model + "\"");
  return *spec;
}
}  // namespace

Material catalogueMaterial(const std::string& model, const NamedParams& params, const std::string& name,
                           glm::vec3 emission) {
  const ModelSpec& spec = catalogueModel(model, name);
  Material m;
  m.name = name;
  m.model = spec.id;
  m.params = packParams(spec, params, name);
  m.emission = emission;
  return m;
}

MaterialComponent catalogueComponent(const std::string& model, const NamedParams& params, float weight) {
  const ModelSpec& spec = catalogueModel(model, model);
  MaterialComponent c;
  c.model = spec.id;
  c.weight = weight;
  c.params = packParams(spec, params, model);
  return c;
}

namespace {
template <class F>
bool anyModel(const Material& m, F f) {
  if (!m.combined()) return f(m.model);
  for (const MaterialComponent& c : m.components)
    if (f(c.model)) return true;
  return false;
}
}  // namespace

bool Material::hasGltfPbr() const {
  return anyModel(*this, [](std::uint32_t id) { return id == MODEL_GLTF_PBR; });
}

bool Material::hasTintedTransmission() const {
  return anyModel(*this, [](std::uint32_t id) { return shared::modelTintParam(id) != INVALID_INDEX; });
}

void setComponents(Material& m, const std::vector<MaterialComponent>& components) {
  if (components.empty()) throw Error(m.name + ": a combined material needs at least one component");
  m.components = components;
  m.model = components[0].model;
  m.params = components[0].params;
}

}  // namespace nusselt
