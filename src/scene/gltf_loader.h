// gltf_loader.h: reads a glTF 2.0 scene (.gltf with embedded or side-by-side buffers, or .glb)
// into a Scene. Input is treated as untrusted: every accessor is bounds-checked, external files
// must stay inside the scene's directory, and every problem is a nusselt::Error naming the file
// and the offending field. Unsupported features (textures, skins, ...) become Scene::warnings.
#pragma once
#include <cstddef>
#include <string>

#include "scene/scene.h"

namespace nusselt {

struct LoadOptions {
  std::string cameraName;  // --camera NAME; empty = the first camera instanced by a node
};

// .gltf (JSON) or .glb, recognised by content (GLB magic) rather than by extension.
Scene loadScene(const std::string& path, const LoadOptions& options = {});

// GLB or JSON bytes. There is no directory to resolve against, so every external URI is refused;
// `displayName` is used in messages in place of a file name.
Scene loadSceneFromMemory(const unsigned char* bytes, std::size_t size, const std::string& displayName,
                          const LoadOptions& options = {});

}  // namespace nusselt
