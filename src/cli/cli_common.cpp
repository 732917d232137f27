#include "cli/cli_common.h"
#include "scene/default_scene.h"

#include <algorithm>
#include <cstdio>

#include "brdf/merl.h"

#include <cstdio>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include <CLI/CLI.hpp>

#include <cmath>
#include <sstream>

#include "io/environment_map.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace nusselt {
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
  if (path.empty()) return loadDefaultScene(opts);
  return loadScene(path, opts);
}

void imageSize(const Scene& scene, std::uint32_t width, std::uint32_t height, std::uint32_t defaultWidth,
               std::uint32_t& outWidth, std::uint32_t& outHeight) {
  const float aspect = scene.hasCamera && scene.camera.aspectRatio > 0 ? scene.camera.aspectRatio : 1.0f;
  outWidth = width ? width : (height ? std::max(1u, unsigned(height * aspect + 0.5f)) : defaultWidth);
  outHeight = height ? height : std::max(1u, unsigned(outWidth / aspect + 0.5f));
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

void addEnvironmentOptions(CLI::App& app, EnvironmentArgs& a) {
  app.add_option("--env", a.env, "Environment light: an equirectangular (lat-long) map, OpenEXR or Radiance .hdr "
                                 "(+Y up, the map's centre along -Z), or none (no environment, even for a scene "
                                 "without lights)");
  app.add_option("--env-color", a.color, "A uniform environment of this radiance, R,G,B (linear Rec. 709)");
  app.add_option("--env-scale", a.scale, "Multiplies the environment's radiance")->capture_default_str();
  app.add_option("--env-rotate", a.rotate, "Rotates the environment about +Y by this many degrees (counter-clockwise "
                                           "seen from above)")->capture_default_str();
  app.add_option("--env-select", a.select, "How light sampling picks the environment in a scene with other lights: "
                                           "half (half of the samples) or power (by estimated power)")
      ->capture_default_str()->check(CLI::IsMember({"half", "power"}));
}

void applyEnvironmentOptions(Scene& scene, const EnvironmentArgs& a, bool quiet) {
  if (!std::isfinite(a.scale) || a.scale < 0.0f) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", double(a.scale));
    throw Error(std::string("--env-scale ") + buf + ": must be a finite number >= 0");
  }
  if (!std::isfinite(a.rotate)) throw Error("--env-rotate: must be a finite number of degrees");
  if (!a.env.empty() && !a.color.empty())
    throw Error("--env " + a.env + " and --env-color " + a.color + ": give one environment, not both");
  Environment e;
  if (a.env == "none") {
    scene.environment = e;
    scene.background = glm::vec3(0.0f);
    return;
  }
  if (!a.env.empty()) {
    EnvironmentImage img = readEnvironmentMap(a.env);
    if (!quiet)
      for (const std::string& w : img.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    e.kind = EnvironmentKind::Map;
    e.path = a.env;
    e.width = img.width;
    e.height = img.height;
    e.rgb = std::move(img.rgb);
  } else if (!a.color.empty()) {
    std::istringstream in(a.color);
    float c[3];
    char comma1 = 0, comma2 = 0;
    in >> c[0] >> comma1 >> c[1] >> comma2 >> c[2];
    std::string rest;
    in >> rest;
    if (!in.eof() && in.fail()) rest = "?";
    if (comma1 != ',' || comma2 != ',' || !rest.empty() || !std::isfinite(c[0]) || !std::isfinite(c[1]) ||
        !std::isfinite(c[2]) || c[0] < 0 || c[1] < 0 || c[2] < 0)
      throw Error("--env-color " + a.color + ": expected R,G,B with three finite numbers >= 0 (e.g. 1,1,1)");
    e.kind = EnvironmentKind::Uniform;
    e.color = glm::vec3(c[0], c[1], c[2]);
  } else {
    bool lit = !scene.lights.empty() || scene.background != glm::vec3(0.0f) || scene.environment.present();
    for (std::uint32_t m : scene.triangleMaterial) lit = lit || scene.materials[m].emits();
    if (lit) {
      if (!quiet && (a.scale != 1.0f || a.rotate != 0.0f || a.select != "half"))
        std::fprintf(stderr, "warning: --env-scale, --env-rotate and --env-select apply to an environment "
                             "(--env or --env-color); this render has none\n");
      return;
    }
    if (!quiet)
      std::fprintf(stderr, "warning: %s has no light (no emissive material, no punctual light, no environment): "
                           "rendering it in a uniform white environment of radiance 1. Give --env FILE, --env-color "
                           "R,G,B, or --env none to keep it black\n",
                   scene.sourcePath.c_str());
    e.kind = EnvironmentKind::Uniform;
    e.color = glm::vec3(1.0f);
  }
  e.scale = a.scale;
  e.rotateDegrees = a.rotate;
  e.selectByPower = a.select == "power";
  scene.environment = std::move(e);
}

Scene loadCommandScene(const std::string& path, const std::string& camera, const EnvironmentArgs& env, bool quiet) {
  Scene scene = loadSceneOrDefault(path, camera);
  printSceneWarnings(scene, quiet);
  applyEnvironmentOptions(scene, env, quiet);
  return scene;
}

}  // namespace nusselt
