// cli_common.h: what the commands share: the validation switch, output-path checks and the scene
// (a file or the built-in Cornell box). The stop signal is in util/stop_signal.h.
#pragma once
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace CLI {
class App;
}
#include "util/stop_signal.h"

namespace nusselt {

// NUSSELT_VALIDATION set to anything but "" or "0".
bool validationFromEnvironment();

// Throws nusselt::Error naming the option unless `path` can be written: its directory exists
// and is writable, and it is not a directory. Checked before any work starts.
void checkOutputPath(const std::string& path, const std::string& option);

// The scene at `path`, or the built-in Cornell box when `path` is empty.
Scene loadSceneOrDefault(const std::string& path, const std::string& camera);
// The image size of a command's --width and --height (0: not given): a side not given follows the
// camera's aspect ratio from the other, and with neither the width is defaultWidth.
void imageSize(const Scene& scene, std::uint32_t width, std::uint32_t height, std::uint32_t defaultWidth,
               std::uint32_t& outWidth, std::uint32_t& outHeight);

// The parameter block of a measured model (merl) from --file: throws nusselt::Error when the file
// is missing or bad (naming it), or when --param options were given (a table has no parameters).
// Prints the count of unmeasured nodes on stderr.
BrdfParams measuredParams(const ModelSpec& model, const std::string& file, const std::vector<std::string>& params);

// The loader's warnings on stderr (unless quiet), with the count of dropped triangles.
void printSceneWarnings(const Scene& scene, bool quiet);

// The environment options of `render` and `preview` (docs/environment.md).
struct EnvironmentArgs {
  std::string env;       // --env FILE (.exr or .hdr) or "none"; empty: not given
  std::string color;     // --env-color R,G,B; empty: not given
  float scale = 1.0f;    // --env-scale
  float rotate = 0.0f;   // --env-rotate, degrees about +Y
  std::string select = "half";  // --env-select: half or power
};
// Registers --env, --env-color, --env-scale and --env-rotate on a subcommand.
void addEnvironmentOptions(CLI::App& app, EnvironmentArgs& args);
// Sets scene.environment from the options: reads the map (its warnings on stderr unless quiet),
// or takes the colour; with neither, a scene without any light (no emissive triangle, no punctual
// light, black background) gets the default, a uniform white environment of radiance 1, and a
// warning naming the options. Throws nusselt::Error naming the option or the file on bad input.
void applyEnvironmentOptions(Scene& scene, const EnvironmentArgs& args, bool quiet);
// The scene of a rendering command (render, preview, guide-view): loadSceneOrDefault, its
// warnings (printSceneWarnings) and the environment options (applyEnvironmentOptions).
Scene loadCommandScene(const std::string& path, const std::string& camera, const EnvironmentArgs& env, bool quiet);

}  // namespace nusselt
