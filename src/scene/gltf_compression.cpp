// gltf_compression.cpp: see gltf_compression.h.
#include "scene/gltf_compression.h"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include <cstring>

#include "util/error.h"

namespace nusselt {
namespace {

std::string str(std::uint64_t v) { return std::to_string(v); }

const char* dracoTypeName(draco::DataType t) {
  switch (t) {
    case draco::DT_INT8: return "int8";
    case draco::DT_UINT8: return "uint8";
    case draco::DT_INT16: return "int16";
    case draco::DT_UINT16: return "uint16";
    case draco::DT_INT32: return "int32";
    case draco::DT_UINT32: return "uint32";
    case draco::DT_INT64: return "int64";
    case draco::DT_UINT64: return "uint64";
    case draco::DT_FLOAT32: return "float32";
    case draco::DT_FLOAT64: return "float64";
    case draco::DT_BOOL: return "bool";
    default: return "invalid";
  }
}

template <typename T>
void convertAll(const draco::PointAttribute& att, std::uint32_t points, const draco::Mesh& mesh, int components,
                std::vector<std::uint8_t>* out) {
  (void)mesh;
  out->resize(std::size_t(points) * std::size_t(components) * sizeof(T));
  T value[4];
  for (std::uint32_t i = 0; i < points; ++i) {
    const draco::AttributeValueIndex avi = att.mapped_index(draco::PointIndex(i));
    if (avi.value() >= att.size())
      throw Error("Draco: point " + str(i) + " maps to value " + str(avi.value()) + " of an attribute with " +
                  str(att.size()) + " values");
    if (!att.ConvertValue<T>(avi, std::uint8_t(components), value))
      throw Error("Draco: value " + str(avi.value()) + " of attribute id " + str(att.unique_id()) +
                  " does not convert to the accessor's component type");
    std::memcpy(out->data() + std::size_t(i) * components * sizeof(T), value, components * sizeof(T));
  }
}

}  // namespace

DracoMesh DracoMesh::decode(const std::uint8_t* data, std::size_t size) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data), size);
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) throw Error("Draco: " + type.status().error_msg_string());
  if (type.value() != draco::TRIANGULAR_MESH)
    throw Error("Draco: the data is a point cloud, not a triangle mesh");
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) throw Error("Draco: " + decoded.status().error_msg_string());
  std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) throw Error("Draco: the decoder returned no mesh");
  DracoMesh out;
  out.m_points = mesh->num_points();
  out.m_indices.resize(std::size_t(mesh->num_faces()) * 3);
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
    const draco::Mesh::Face& face = mesh->face(f);
    for (int k = 0; k < 3; ++k) {
      std::uint32_t v = face[k].value();
      if (v >= out.m_points)
        throw Error("Draco: face " + str(f.value()) + " refers to point " + str(v) + " of " + str(out.m_points));
      out.m_indices[3 * std::size_t(f.value()) + k] = v;
    }
  }
  out.m_mesh = std::shared_ptr<const draco::Mesh>(mesh.release());
  return out;
}

std::vector<std::uint8_t> DracoMesh::attribute(std::uint32_t id, int componentType, int components) const {
  const draco::Mesh& mesh = *static_cast<const draco::Mesh*>(m_mesh.get());
  const draco::PointAttribute* att = mesh.GetAttributeByUniqueId(id);
  if (!att) throw Error("Draco: the data has no attribute with unique id " + str(id));
  if (att->num_components() != components)
    throw Error("Draco: attribute id " + str(id) + " has " + str(att->num_components()) + " components, the accessor " +
                str(std::uint64_t(components)));
  draco::DataType expected = draco::DT_INVALID;
  switch (componentType) {
    case 5120: expected = draco::DT_INT8; break;
    case 5121: expected = draco::DT_UINT8; break;
    case 5122: expected = draco::DT_INT16; break;
    case 5123: expected = draco::DT_UINT16; break;
    case 5125: expected = draco::DT_UINT32; break;
    case 5126: expected = draco::DT_FLOAT32; break;
    default: throw Error("Draco: component type " + std::to_string(componentType) + " is not supported");
  }
  if (componentType != 5126 && att->data_type() != expected)
    throw Error(std::string("Draco: attribute id ") + str(id) + " holds " + dracoTypeName(att->data_type()) +
                ", the accessor's componentType needs " + dracoTypeName(expected));
  std::vector<std::uint8_t> out;
  switch (componentType) {
    case 5120: convertAll<std::int8_t>(*att, m_points, mesh, components, &out); break;
    case 5121: convertAll<std::uint8_t>(*att, m_points, mesh, components, &out); break;
    case 5122: convertAll<std::int16_t>(*att, m_points, mesh, components, &out); break;
    case 5123: convertAll<std::uint16_t>(*att, m_points, mesh, components, &out); break;
    case 5125: convertAll<std::uint32_t>(*att, m_points, mesh, components, &out); break;
    default: convertAll<float>(*att, m_points, mesh, components, &out); break;
  }
  return out;
}

std::vector<std::uint8_t> decodeMeshopt(const std::uint8_t* data, std::size_t size, std::uint64_t count,
                                        std::uint64_t stride, MeshoptMode mode, MeshoptFilter filter,
                                        std::uint64_t maxBytes) {
  if (count == 0) throw Error("count must be at least 1");
  if (mode == MeshoptMode::Attributes) {
    if (stride == 0 || stride % 4 != 0 || stride > 256)
      throw Error("byteStride " + str(stride) + ": ATTRIBUTES needs a multiple of 4 up to 256");
  } else {
    if (stride != 2 && stride != 4) throw Error("byteStride " + str(stride) + ": TRIANGLES and INDICES need 2 or 4");
    if (filter != MeshoptFilter::None) throw Error("filter: TRIANGLES and INDICES take no filter");
    if (mode == MeshoptMode::Triangles && count % 3 != 0)
      throw Error("count " + str(count) + ": TRIANGLES needs a multiple of 3");
  }
  if (filter == MeshoptFilter::Octahedral && stride != 4 && stride != 8)
    throw Error("byteStride " + str(stride) + ": the OCTAHEDRAL filter needs 4 or 8");
  if (filter == MeshoptFilter::Quaternion && stride != 8)
    throw Error("byteStride " + str(stride) + ": the QUATERNION filter needs 8");
  if (filter == MeshoptFilter::Exponential && stride % 4 != 0)
    throw Error("byteStride " + str(stride) + ": the EXPONENTIAL filter needs a multiple of 4");
  if (count > maxBytes / stride)
    throw Error("count " + str(count) + " x byteStride " + str(stride) + " exceeds the limit of " + str(maxBytes) +
                " bytes");
  std::vector<std::uint8_t> out(std::size_t(count * stride));
  int rc = 0;
  switch (mode) {
    case MeshoptMode::Attributes: rc = meshopt_decodeVertexBuffer(out.data(), count, stride, data, size); break;
    case MeshoptMode::Triangles: rc = meshopt_decodeIndexBuffer(out.data(), count, stride, data, size); break;
    case MeshoptMode::Indices: rc = meshopt_decodeIndexSequence(out.data(), count, stride, data, size); break;
  }
  if (rc != 0) throw Error("meshopt: the compressed data is invalid (decoder error " + std::to_string(rc) + ")");
  switch (filter) {
    case MeshoptFilter::None: break;
    case MeshoptFilter::Octahedral: meshopt_decodeFilterOct(out.data(), count, stride); break;
    case MeshoptFilter::Quaternion: meshopt_decodeFilterQuat(out.data(), count, stride); break;
    case MeshoptFilter::Exponential: meshopt_decodeFilterExp(out.data(), count, stride); break;
  }
  return out;
}

}  // namespace nusselt
