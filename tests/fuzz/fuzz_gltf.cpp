// fuzz_gltf.cpp: libFuzzer target for the glTF / GLB loader (issue 8).
//
// The bytes are a scene file loaded from memory (no directory: every external URI must be
// refused). nusselt::Error is the loader's one documented failure; any other exception, a crash,
// a leak, an ASan or UBSan report, or a Scene that breaks its invariants is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "scene/gltf_loader.h"
#include "util/error.h"

namespace {

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_gltf: %s\n", what);
  std::abort();
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What the renderer relies on (scene.h): three corners and normals per triangle, finite
// positions, unit shading normals, valid material indices, finite non-negative emission and
// light intensities, a usable camera.
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
  for (const nusselt::Material& m : s.materials)
    if (!finite(m.emission) || m.emission.x < 0 || m.emission.y < 0 || m.emission.z < 0)
      finding("bad material emission");
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
    nusselt::Scene scene = nusselt::loadSceneFromMemory(data, size, "fuzz.gltf");
    checkInvariants(scene);
  } catch (const nusselt::Error&) {
    // The documented failure: a message naming the file and the field.
  }
  return 0;
}
