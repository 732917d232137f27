// gltf_loader.h: reads a glTF 2.0 scene (.gltf with embedded or side-by-side buffers and
// images, or .glb) into a Scene: geometry (also Draco-, meshopt- and quantization-compressed),
// texture coordinates and tangents, materials with their textures, decoded images, lights and a
// camera. Input is treated as untrusted: every accessor is bounds-checked, external files must
// stay inside the scene's directory, images are decoded by libpng / libjpeg-turbo under size
// caps, and every problem is a nusselt::Error naming the file and the offending field, with no
// raw byte of the input in it. Unsupported features (skins, ...) become Scene::warnings.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

#include "scene/scene.h"

namespace nusselt {

struct LoadOptions {
  std::string cameraName;  // --camera NAME; empty = the first camera instanced by a node
  // Caps on the images a scene's materials use (a larger image is an error naming it):
  // width x height of one image (2^26: 8192 x 8192, 256 MiB as RGBA), the sum over the scene's
  // images (2^28: 1 GiB as RGBA), and the encoded bytes of one image.
  std::uint64_t maxImagePixels = std::uint64_t(1) << 26;
  std::uint64_t maxTotalImagePixels = std::uint64_t(1) << 28;
  std::uint64_t maxImageBytes = std::uint64_t(1) << 28;
};

// .gltf (JSON) or .glb, recognised by content (GLB magic) rather than by extension.
Scene loadScene(const std::string& path, const LoadOptions& options = {});

// GLB or JSON bytes. There is no directory to resolve against, so every external URI is refused;
// `displayName` is used in messages in place of a file name.
Scene loadSceneFromMemory(const unsigned char* bytes, std::size_t size, const std::string& displayName,
                          const LoadOptions& options = {});

}  // namespace nusselt
