// fuzz_gltf.cpp: libFuzzer target for the glTF / GLB loader (issue 8).
//
// The bytes are a scene file loaded from memory (no directory: every external URI must be
// refused). nusselt::Error is the loader's one documented failure; any other exception, a crash,
// a leak, an ASan or UBSan report, or a Scene that breaks its invariants is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include <vector>

#include "scene/gltf_loader.h"
#include "util/error.h"

namespace {

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_gltf: %s\n", what);
  std::abort();
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What the renderer relies on (scene.h): three corners and normals per triangle, finite
// positions, unit shading normals, texture coordinates and tangents per corner or none, valid
// material and image indices, finite material factors, finite non-negative emission and light
// intensities, a usable camera.
void checkInvariants(const nusselt::Scene& s) {
  const std::size_t t = s.triangleCount();
  if (s.positions.size() != 3 * t || s.normals.size() != 3 * t) finding("positions/normals/materials sizes disagree");
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    if (!finite(s.positions[i])) finding("non-finite position");
    if (!finite(s.normals[i])) finding("non-finite normal");
    float len = glm::length(s.normals[i]);
    if (!(std::fabs(len - 1.0f) < 1e-3f)) finding("shading normal is not unit length");
  }
  for (std::uint32_t m : s.triangleMaterial)
    if (m >= s.materials.size()) finding("triangle material index out of range");
  // Texture coordinates and tangents: empty or one per corner; finite; unit tangents orthogonal
  // to the shading normal with w = +-1.
  for (const std::vector<glm::vec2>* uv : {&s.texcoords0, &s.texcoords1}) {
    if (!uv->empty() && uv->size() != 3 * t) finding("texcoords size disagrees with the triangle count");
    for (const glm::vec2& w : *uv)
      if (!std::isfinite(w.x) || !std::isfinite(w.y)) finding("non-finite texture coordinate");
  }
  if (!s.tangents.empty() && s.tangents.size() != 3 * t) finding("tangents size disagrees with the triangle count");
  for (std::size_t i = 0; i < s.tangents.size(); ++i) {
    const glm::vec3 d(s.tangents[i]);
    if (!finite(d) || !(std::fabs(glm::length(d) - 1.0f) < 1e-3f)) finding("tangent is not unit length");
    if (!(std::fabs(glm::dot(d, s.normals[i])) < 1e-3f)) finding("tangent is not orthogonal to the normal");
    if (s.tangents[i].w != 1.0f && s.tangents[i].w != -1.0f) finding("tangent w is not +-1");
  }
  for (const nusselt::TextureImage& im : s.images)
    if (im.width == 0 || im.height == 0 || im.rgba.size() != std::size_t(4) * im.width * im.height)
      finding("image size disagrees with its dimensions");
  auto checkRef = [&](const nusselt::TextureRef& r) {
    if (r.image < -1 || (r.image >= 0 && std::size_t(r.image) >= s.images.size())) finding("texture image out of range");
    if (r.texCoord > 1) finding("texture coordinate set beyond 1");
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(r.transform[c][0]) || !std::isfinite(r.transform[c][1])) finding("non-finite texture transform");
  };
  for (const nusselt::Material& m : s.materials) {
    if (!finite(m.emission) || m.emission.x < 0 || m.emission.y < 0 || m.emission.z < 0)
      finding("bad material emission");
    for (const nusselt::TextureRef* r : {&m.baseColorTexture, &m.metallicRoughnessTexture, &m.normalTexture,
                                         &m.emissiveTexture, &m.transmissionTexture})
      checkRef(*r);
    if (!std::isfinite(m.normalScale) || !std::isfinite(m.alphaCutoff) || !(m.ior >= 1.0f) || !std::isfinite(m.ior) ||
        !(m.transmissionFactor >= 0.0f && m.transmissionFactor <= 1.0f) || !std::isfinite(m.thicknessFactor) ||
        !(m.attenuationDistance > 0.0f) || !finite(m.attenuationColor) || !finite(m.absorption) ||
        m.absorption.x < 0 || m.absorption.y < 0 || m.absorption.z < 0)
      finding("bad material factor");
  }
  for (const nusselt::PunctualLight& l : s.lights) {
    if (!finite(l.position) || !finite(l.direction) || !finite(l.intensity)) finding("non-finite light");
    if (l.intensity.x < 0 || l.intensity.y < 0 || l.intensity.z < 0) finding("negative light intensity");
  }
  const nusselt::Camera& c = s.camera;
  if (!finite(c.position) || !finite(c.forward) || !finite(c.up)) finding("non-finite camera");
  if (!std::isfinite(c.yfov) || !std::isfinite(c.aspectRatio) || !std::isfinite(c.xmag) || !std::isfinite(c.ymag))
    finding("non-finite camera projection");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    // Smaller image caps than the defaults: a hostile header asking for the full 2^26 pixels
    // would take seconds to fill under ASan; the caps' logic is the same.
    nusselt::LoadOptions options;
    options.maxImagePixels = std::uint64_t(1) << 20;
    options.maxTotalImagePixels = std::uint64_t(1) << 22;
    nusselt::Scene scene = nusselt::loadSceneFromMemory(data, size, "fuzz.gltf", options);
    checkInvariants(scene);
  } catch (const nusselt::Error&) {
    // The documented failure: a message naming the file and the field.
  }
  return 0;
}
