// cli_common.h: what the commands share: the stop signal, the validation switch, output-path
// checks and the scene (a file or the built-in Cornell box).
#pragma once
#include <atomic>
#include <string>

#include "scene/scene.h"

namespace nusselt {

// The signal (SIGINT, SIGTERM) that asked a long-running command to stop, or 0. Install
// onStopSignal for both; a second signal ends the program at once.
extern std::atomic<int> g_stopSignal;
void onStopSignal(int sig);

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
