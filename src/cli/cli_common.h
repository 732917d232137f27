// cli_common.h: what the commands share: the validation switch, output-path checks and the scene
// (a file or the built-in Cornell box). The stop signal is in util/stop_signal.h.
#pragma once
#include <atomic>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "util/stop_signal.h"

namespace nusselt {

// NUSSELT_VALIDATION set to anything but "" or "0".
bool validationFromEnvironment();

// Throws nusselt::Error naming the option unless `path` can be written: its directory exists
// and is writable, and it is not a directory. Checked before any work starts.
void checkOutputPath(const std::string& path, const std::string& option);

// The scene at `path`, or the built-in Cornell box when `path` is empty.
Scene loadSceneOrDefault(const std::string& path, const std::string& camera);

// The parameter block of a measured model (merl) from --file: throws nusselt::Error when the file
// is missing or bad (naming it), or when --param options were given (a table has no parameters).
// Prints the count of unmeasured nodes on stderr.
BrdfParams measuredParams(const ModelSpec& model, const std::string& file, const std::vector<std::string>& params);

// The loader's warnings on stderr (unless quiet), with the count of dropped triangles.
void printSceneWarnings(const Scene& scene, bool quiet);

}  // namespace nusselt
