// gltf_compression.h: decoders for compressed glTF geometry, behind plain types so that the
// loader does not see the libraries' headers.
//   KHR_draco_mesh_compression: Google's Draco (Debian libdraco-dev),
//   EXT_meshopt_compression: meshoptimizer's decoders (Debian libmeshoptimizer-dev), which its
//   header documents as safe for untrusted input (the output may be garbage, never out of
//   bounds); every parameter the decoders assert on is checked here first.
// Every failure is a nusselt::Error whose message has no context (the loader prefixes the file
// and the glTF field).
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace nusselt {

// A decoded Draco triangle mesh.
class DracoMesh {
 public:
  // Decodes a Draco bitstream holding a triangle mesh (a point cloud is refused).
  static DracoMesh decode(const std::uint8_t* data, std::size_t size);

  std::uint32_t pointCount() const { return m_points; }
  // Three point indices per face, each < pointCount().
  const std::vector<std::uint32_t>& indices() const { return m_indices; }

  // The attribute with Draco unique id `id`, one element per point (pointCount() elements of
  // `components` values), tightly packed as glTF `componentType` (5120..5126). A float type
  // takes any Draco data type (converted, normalised integers mapped to [0, 1] / [-1, 1]); an
  // integer type needs the Draco attribute to have that very type. Throws on a missing
  // attribute, a different component count, or a type that does not fit.
  std::vector<std::uint8_t> attribute(std::uint32_t id, int componentType, int components) const;

 private:
  std::shared_ptr<const void> m_mesh;  // draco::Mesh
  std::uint32_t m_points = 0;
  std::vector<std::uint32_t> m_indices;
};

enum class MeshoptMode { Attributes, Triangles, Indices };
enum class MeshoptFilter { None, Octahedral, Quaternion, Exponential };

// Decodes one EXT_meshopt_compression bufferView: `count` elements of `stride` bytes from the
// compressed bytes, then applies the filter in place. Checks the extension's constraints
// (ATTRIBUTES: stride a multiple of 4, at most 256; TRIANGLES: count a multiple of 3;
// TRIANGLES/INDICES: stride 2 or 4, no filter; OCTAHEDRAL: stride 4 or 8; QUATERNION: 8;
// EXPONENTIAL: a multiple of 4) and that count x stride does not exceed `maxBytes`.
std::vector<std::uint8_t> decodeMeshopt(const std::uint8_t* data, std::size_t size, std::uint64_t count,
                                        std::uint64_t stride, MeshoptMode mode, MeshoptFilter filter,
                                        std::uint64_t maxBytes);

}  // namespace nusselt
