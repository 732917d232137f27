#include "cli/cli_common.h"

#include <cstdio>

#include "brdf/merl.h"

#include <cstdio>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include "scene/gltf_loader.h"
#include "util/error.h"

namespace nusselt {
extern const unsigned char kDefaultSceneBytes[];
extern const std::size_t kDefaultSceneSize;

bool validationFromEnvironment() {
  const char* v = std::getenv("NUSSELT_VALIDATION");
  return v && *v && std::string(v) != "0";
}

void checkOutputPath(const std::string& path, const std::string& option) {
  namespace fs = std::filesystem;
  fs::path p(path);
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(option + " " + path + ": directory " + dir.string() + " does not exist");
  if (fs::is_directory(p, ec)) throw Error(option + " " + path + ": is a directory");
  if (access(dir.c_str(), W_OK) != 0) throw Error(option + " " + path + ": directory " + dir.string() + " is not writable");
}

Scene loadSceneOrDefault(const std::string& path, const std::string& camera) {
  LoadOptions opts;
  opts.cameraName = camera;
  if (path.empty()) return loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene (cornell-box.glb)", opts);
  return loadScene(path, opts);
}

void printSceneWarnings(const Scene& scene, bool quiet) {
  if (quiet) return;
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (scene.droppedTriangles)
    std::fprintf(stderr,
                 "warning: %s: dropped %llu degenerate triangles (zero area, non-finite vertices or coordinates "
                 "beyond 1e15)\n",
                 scene.sourcePath.c_str(), static_cast<unsigned long long>(scene.droppedTriangles));
}

BrdfParams measuredParams(const ModelSpec& model, const std::string& file, const std::vector<std::string>& params) {
  if (file.empty()) throw Error("--model " + model.name + " needs --file, a MERL binary file (docs/measured.md)");
  if (!params.empty()) throw Error("--param: model " + model.name + " has no parameters (it reads --file)");
  BrdfParams p = loadMerl(file, "--file " + file);
  const MerlTable& t = merlTable(p);
  if (t.unmeasured)
    std::fprintf(stderr, "%s: %u of %u table nodes not measured (negative), filled from the nearest measured node\n",
                 file.c_str(), t.unmeasured, unsigned(MERL_NODES));
  return p;
}

}  // namespace nusselt
