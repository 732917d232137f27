// default_scene.cpp: see default_scene.h.
#include "scene/default_scene.h"

#include <cstddef>

namespace nusselt {

// Written by cmake/embed_file.cmake into the build directory (default_scene.cpp there).
extern const unsigned char kDefaultSceneBytes[];
extern const std::size_t kDefaultSceneSize;

Scene loadDefaultScene(const LoadOptions& options) {
  return loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, kDefaultSceneName, options);
}

}  // namespace nusselt
