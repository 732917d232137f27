// cli_common.h: what the commands share: the validation switch, output-path checks and the scene
// (a file or the built-in Cornell box). The stop signal is in util/stop_signal.h.
#pragma once
#include <atomic>
#include <string>

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

// The loader's warnings on stderr (unless quiet), with the count of dropped triangles.
void printSceneWarnings(const Scene& scene, bool quiet);

}  // namespace nusselt
