// render_record.h: what a render records in its EXR header, and reads back to resume or merge.
// One writer (makeMetadata) and one reader (readRecord) serve `render`, `preview` (its saves are
// ordinary, resumable renders) and `merge`.
#pragma once
#include <cstdint>
#include <string>

#include "io/image.h"
#include "render/settings.h"
#include "scene/scene.h"

namespace nusselt {

struct RenderRecord {
  std::string scene;   // the scene's source path (or the default scene's name)
  std::string device;
  std::string driver;  // the device's driver and version (not checked on resume: same device name suffices)
  std::string models;  // the shade slots' names, comma-separated
  std::string source = "render";  // render, preview or merge
  RenderSettings settings;        // size, seed, depth, modes, spp offset (settings.spp is unused)
  Camera camera;                  // the view rendered (a preview's may differ from the scene's)
  bool cameraRecorded = true;     // readRecord: false for files written before the camera was recorded
  std::uint32_t spp = 0;          // samples per pixel in the image
  bool interrupted = false;
  bool checkpoint = false;        // written during the render (periodic checkpoint), not at its end
  RenderStats stats;
  std::uint64_t droppedTriangles = 0;
  double renderSeconds = 0;
  double totalSeconds = 0;
  double timeBudget = 0;          // --time, 0: none
  double displayExposure = 0;     // the preview's display exposure in stops (recorded for previews only)
  // The environment (docs/environment.md): "none", "uniform R,G,B" or "map FILE" (describeEnvironment).
  std::string environment = "none";
  double envScale = 1, envRotate = 0;
  std::string envSelect = "half";  // --env-select
  // Path guiding: the hash of the guide the render sampled from when it was written
  // (DeviceGuide::hash, 16 hex digits); empty for unguided renders and older files.
  std::string guideHash;
  // Binned sampling (settings.roughnessBins, roughnessBinSpacing): the bins the render built, 0 when
  // its scene has no material that needs them (then the header has no bin attributes).
  std::uint32_t roughnessBins = 0;
};

// The record's description of an environment ("none", "uniform R,G,B", "map FILE"); a scene's
// background alone counts as a uniform environment (effectiveEnvironment).
std::string describeEnvironment(const Scene& scene);
// Sets record.environment, envScale and envRotate from the scene.
void recordEnvironment(RenderRecord& record, const Scene& scene);

// The header attributes of a render.
ImageMetadata makeMetadata(const RenderRecord& record);
// Reads back what makeMetadata wrote; throws nusselt::Error naming the file and the attribute when
// one is missing or malformed. Attributes added after a file was written take the value that
// reproduces what the writing version did (documented per attribute in the .cpp). The image size
// is the image's: the caller sets settings.width and settings.height.
RenderRecord readRecord(const std::string& path, const ImageMetadata& meta);

// The first setting in which two records of renders differ, as "what: a vs b" (scene, image size,
// seed, depth, lighting, random numbers, sampler, component choice, roulette, camera); empty when
// their samples can be added up (resume, merge). The spp offset is the caller's to check.
std::string firstDifference(const RenderRecord& a, const RenderRecord& b);

}  // namespace nusselt
