// default_scene.h: the built-in scene (scenes/cornell-box.glb, embedded in the binary at build
// time by CMakeLists.txt), so that `nusselt render` works from any directory.
#pragma once
#include "scene/gltf_loader.h"

namespace nusselt {

// The source name the default scene carries in messages and EXR headers.
inline constexpr const char* kDefaultSceneName = "default scene (cornell-box.glb)";

Scene loadDefaultScene(const LoadOptions& options);

}  // namespace nusselt
