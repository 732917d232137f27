// gltf_loader.cpp: glTF 2.0 -> Scene.
//
// The file is untrusted input. tinygltf 2.7.0 does the JSON-to-struct work, but it follows `../`
// and absolute URIs, misreads a directory named by a URI as a huge file, leaves accessor bounds
// to the caller and hands image callbacks a bufferView pointer it never checked against its
// buffer. So before tinygltf sees anything we:
//   - read the file ourselves (regular file, size cap) and split GLB chunks with checked sizes,
//   - parse the JSON once with nlohmann (after a cheap nesting-depth scan, because tinygltf
//     converts extension values recursively) and vet every buffer URI against the scene folder,
//   - refuse integers tinygltf would truncate to int, a BIN-chunk buffer other than buffers[0] or
//     of byteLength 0, and buffers adding up to more than 1 GiB (tinygltf copies per buffer),
//   - take `images` out of the JSON (kept here, see ImageSource): tinygltf never decodes, slices
//     or reads an image; the Converter reads and decodes only the images a material uses, once
//     each, through libpng / libjpeg-turbo (io/image_decode.h) under pixel and byte caps,
//   - swap EXT_meshopt_compression placeholder buffers (no data) for a 1-byte stub,
// and hand tinygltf file-system callbacks that only open regular files inside the scene folder.
// After tinygltf, every index and every accessor is checked before a single byte is read.
// Compressed geometry (Draco, meshopt) is decoded into plain accessor data by
// scene/gltf_compression.h and then goes through the same checks and readers.
#include "scene/gltf_loader.h"

#include <fstream>  // tinygltf's writer needs it even with TINYGLTF_NO_FS

#include <nlohmann/json.hpp>

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_FS  // our own callbacks only: tinygltf's defaults would escape the folder
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_INCLUDE_JSON
#include <tiny_gltf.h>

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "../../shaders/shared/volume.h"
#include "brdf/merl.h"
#include "io/image_decode.h"
#include "scene/gltf_compression.h"
#include "scene/tangents.h"
#include "util/error.h"

namespace nusselt {
namespace {

using Json = nlohmann::json;

// Scene files and external buffers above this size are refused rather than read.
constexpr std::uint64_t kMaxFileBytes = 1ull << 30;
// A hostile file can instance one large mesh from many nodes; cap the output (~1.3 GB of
// triangle data) so it fails with a message instead of exhausting memory.
constexpr std::uint64_t kMaxTriangles = 1ull << 24;
// Deeper JSON is refused: tinygltf converts extension/extras values recursively.
constexpr int kMaxJsonDepth = 64;
// Triangles with a vertex coordinate beyond this (after the node transforms) are dropped like
// non-finite ones: the renderer's float arithmetic (ray offsets, the default view's distance)
// would overflow near the float range (fuzz_gltf found a camera at infinity from 3e38).
constexpr double kMaxCoordinate = 1e15;

// Texture coordinates beyond this (or not finite) are replaced by 0 and counted: float spacing is
// 8 there, so no texel can be addressed, and KHR_texture_transform values (capped alike) times
// such a coordinate could overflow to Inf on the GPU.
constexpr double kMaxTexcoord = 1e8;

const char* const kSupportedExtensions[] = {
    "NUSSELT_brdf", "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_texture_transform",
    "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume", "KHR_mesh_quantization",
    "KHR_draco_mesh_compression", "EXT_meshopt_compression"};

// Why a well-known extension is not supported, for the extensionsRequired error.
const char* unsupportedReason(const std::string& name) {
  if (name == "KHR_texture_basisu") return "KTX2 / Basis Universal textures are not decoded (nusselt decodes PNG and JPEG)";
  if (name == "EXT_texture_webp") return "WebP textures are not decoded (nusselt decodes PNG and JPEG)";
  if (name == "EXT_texture_avif") return "AVIF textures are not decoded (nusselt decodes PNG and JPEG)";
  if (name == "MSFT_texture_dds") return "DDS textures are not decoded (nusselt decodes PNG and JPEG)";
  if (name == "KHR_materials_pbrSpecularGlossiness") return "the specular-glossiness workflow is not supported";
  if (name == "EXT_mesh_gpu_instancing") return "GPU instancing is not supported";
  return nullptr;
}

bool isSupportedExtension(const std::string& name) {
  for (const char* s : kSupportedExtensions)
    if (name == s) return true;
  return false;
}

std::string supportedExtensionList() {
  std::string s;
  for (const char* e : kSupportedExtensions) s += (s.empty() ? "" : ", ") + std::string(e);
  return s;
}

std::string str(std::uint64_t v) { return std::to_string(v); }
std::string str(std::int64_t v) { return std::to_string(v); }
std::string str(int v) { return std::to_string(v); }

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// Text from the file made safe for a message: valid UTF-8 sequences pass (names in any script),
// control characters, DEL, C1 controls and bytes that are not UTF-8 become \xNN. Applied to
// every message and warning the loader produces (guarded(), loadImpl()), so no byte of the
// input reaches a terminal raw, whatever library produced the text.
std::string printable(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  auto hex = [&](unsigned char c) {
    char b[5];
    std::snprintf(b, sizeof b, "\\x%02x", c);
    out += b;
  };
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7f) hex(c);
      else out += char(c);
      ++i;
      continue;
    }
    // A UTF-8 sequence: lead byte, length, minimum code point (no overlong forms), no
    // surrogates, nothing above U+10FFFF, and not a C1 control (U+0080..U+009F).
    int len = c >= 0xf0 && c <= 0xf4 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 && c <= 0xdf ? 2 : 0;
    std::uint32_t cp = len == 4 ? c & 0x07u : len == 3 ? c & 0x0fu : c & 0x1fu;
    bool ok = len > 0 && c < 0xf5 && i + std::size_t(len) <= s.size();
    for (int k = 1; ok && k < len; ++k) {
      const unsigned char d = static_cast<unsigned char>(s[i + std::size_t(k)]);
      ok = (d & 0xc0) == 0x80;
      cp = (cp << 6) | (d & 0x3fu);
    }
    ok = ok && !(len == 3 && cp < 0x800) && !(len == 4 && (cp < 0x10000 || cp > 0x10ffff)) &&
         !(cp >= 0xd800 && cp <= 0xdfff) && !(cp >= 0x80 && cp <= 0x9f);
    if (!ok) {
      hex(c);
      ++i;
      continue;
    }
    out.append(s, i, std::size_t(len));
    i += std::size_t(len);
  }
  return out;
}

std::string quoted(const std::string& s) {
  // Names come from the file; keep messages one line and bounded.
  std::string out = "\"" + printable(s.substr(0, 200));
  if (s.size() > 200) out += "...";
  return out + "\"";
}

bool addChecked(std::uint64_t a, std::uint64_t b, std::uint64_t* r) { return !__builtin_add_overflow(a, b, r); }
bool mulChecked(std::uint64_t a, std::uint64_t b, std::uint64_t* r) { return !__builtin_mul_overflow(a, b, r); }

// ---------------------------------------------------------------------------------------------
// Files and the scene-folder sandbox.

struct Sandbox {
  std::string root;  // canonical scene directory; empty: no external files at all
};

// True when `path` resolves (symlinks followed) to a regular file inside the sandbox, of at most
// kMaxFileBytes; otherwise `why` says what is wrong.
bool resolveInside(const Sandbox& box, const std::string& path, std::string* resolved, std::string* why) {
  if (box.root.empty()) {
    *why = "external files are not allowed for a scene loaded from memory";
    return false;
  }
  char* real = realpath(path.c_str(), nullptr);
  if (!real) {
    *why = std::strerror(errno);
    return false;
  }
  std::string canonical(real);
  std::free(real);
  std::string prefix = box.root == "/" ? "/" : box.root + "/";
  if (canonical.compare(0, prefix.size(), prefix) != 0) {
    *why = "resolves outside the scene directory";
    return false;
  }
  struct stat st {};
  if (stat(canonical.c_str(), &st) != 0) {
    *why = std::strerror(errno);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    *why = "is not a regular file";
    return false;
  }
  if (static_cast<std::uint64_t>(st.st_size) > kMaxFileBytes) {
    *why = "is larger than the 1 GiB limit";
    return false;
  }
  if (resolved) *resolved = canonical;
  return true;
}

// Reads a regular file of at most kMaxFileBytes; `why` explains a failure.
bool readRegularFile(const std::string& path, std::vector<unsigned char>* out, std::string* why) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) {
    *why = std::strerror(errno);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    *why = S_ISDIR(st.st_mode) ? "is a directory" : "is not a regular file";
    return false;
  }
  if (static_cast<std::uint64_t>(st.st_size) > kMaxFileBytes) {
    *why = "is larger than the 1 GiB limit";
    return false;
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    *why = std::strerror(errno);
    return false;
  }
  out->resize(static_cast<std::size_t>(st.st_size));
  std::size_t got = out->empty() ? 0 : std::fread(out->data(), 1, out->size(), f);
  bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed || got != out->size()) {
    *why = "read error (file changed while reading?)";
    return false;
  }
  return true;
}

// tinygltf file-system callbacks: no shell expansion, sandboxed reads, no writes.
bool fsFileExists(const std::string& path, void* user) {
  std::string why;
  return resolveInside(*static_cast<Sandbox*>(user), path, nullptr, &why);
}

std::string fsExpandFilePath(const std::string& path, void*) { return path; }

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  std::string resolved, why;
  if (!resolveInside(*static_cast<Sandbox*>(user), path, &resolved, &why) ||
      !readRegularFile(resolved, out, &why)) {
    if (err) *err += why;
    return false;
  }
  return true;
}

bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is disabled";
  return false;
}

// Images are removed before tinygltf parses (see the top of this file); this is a safety net
// that accepts without decoding should one slip through.
bool ignoreImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                 void*) {
  return true;
}

// ---------------------------------------------------------------------------------------------
// GLB container.

struct GlbParts {
  std::string json;
  const unsigned char* bin = nullptr;
  std::uint64_t binSize = 0;
  bool hasBin = false;
};

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

void putU32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

GlbParts splitGlb(const unsigned char* bytes, std::uint64_t size, const std::string& name) {
  const std::string where = name + ": GLB: ";
  if (size < 12) throw Error(where + "truncated: " + str(size) + " bytes, the header alone is 12");
  std::uint32_t version = readU32(bytes + 4), length = readU32(bytes + 8);
  if (version != 2) throw Error(where + "version " + str(std::uint64_t(version)) + " is not supported (expected 2)");
  if (length > size)
    throw Error(where + "truncated: the header declares " + str(std::uint64_t(length)) + " bytes but the file has " +
                str(size));
  if (length < 20) throw Error(where + "truncated: no room for the JSON chunk (length " + str(std::uint64_t(length)) + ")");
  std::uint64_t jsonLength = readU32(bytes + 12);
  if (readU32(bytes + 16) != 0x4E4F534Au) throw Error(where + "the first chunk is not JSON");
  if (20 + jsonLength > length)
    throw Error(where + "truncated: the JSON chunk (" + str(jsonLength) + " bytes) extends past the end (length " +
                str(std::uint64_t(length)) + ")");
  GlbParts parts;
  parts.json.assign(reinterpret_cast<const char*>(bytes + 20), static_cast<std::size_t>(jsonLength));
  // Chunks are 4-byte aligned; tolerate a writer that forgot the JSON padding.
  std::uint64_t offset = 20 + jsonLength;
  offset = (offset + 3) & ~std::uint64_t(3);
  if (offset + 8 <= length) {
    std::uint64_t binLength = readU32(bytes + offset);
    std::uint32_t type = readU32(bytes + offset + 4);
    if (type == 0x004E4942u) {
      if (offset + 8 + binLength > length)
        throw Error(where + "truncated: the BIN chunk (" + str(binLength) + " bytes) extends past the end (length " +
                    str(std::uint64_t(length)) + ")");
      parts.bin = bytes + offset + 8;
      parts.binSize = binLength;
      parts.hasBin = binLength > 0;
    }
  }
  return parts;
}

// ---------------------------------------------------------------------------------------------
// JSON pre-pass.

// Maximum bracket nesting outside strings; cheap, and runs before any recursive code sees it.
int jsonDepth(const std::string& text) {
  int depth = 0, maxDepth = 0;
  bool inString = false, escaped = false;
  for (char c : text) {
    if (inString) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      maxDepth = std::max(maxDepth, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return maxDepth;
}

// tinygltf only decodes these media types; any other data: URI it would try to open as a file.
const char* const kDataUriPrefixes[] = {"data:application/octet-stream;base64,",
                                        "data:application/gltf-buffer;base64,"};

void checkUnsignedFields(const Json& root, const char* array, std::initializer_list<const char*> fields,
                         const std::string& name) {
  auto it = root.find(array);
  if (it == root.end() || !it->is_array()) return;
  for (std::size_t i = 0; i < it->size(); ++i) {
    const Json& item = (*it)[i];
    if (!item.is_object()) throw Error(name + ": " + array + "[" + str(std::uint64_t(i)) + "] is not an object");
    for (const char* field : fields) {
      auto f = item.find(field);
      if (f != item.end() && !f->is_number_unsigned())
        throw Error(name + ": " + array + "[" + str(std::uint64_t(i)) + "]." + field + ": " + f->dump() +
                    " is not a non-negative integer");
    }
  }
}

// tinygltf 2.7.0 reads JSON integers through static_cast<int>(get<int64_t>()) (GetInt for index
// and enum fields, ParseJsonAsValue for extension values): 4294967296 becomes index 0 and
// 4294967396 becomes parameter value 100, silently in range. So, before tinygltf sees the JSON,
// an integer that does not fit an int is
//   - turned into the same number as a double inside `extensions` (NUSSELT_brdf parameters,
//     emissiveStrength: numbers that are range-checked as numbers afterwards) and in the glTF
//     fields tinygltf reads as doubles anyway (translation, yfov, min, ...),
//   - left alone in `extras` (never read) and in the size_t fields (read without truncation),
//   - refused everywhere else: there glTF expects an index or an enum.
const char* const kNumberFields[] = {"min", "max", "translation", "rotation", "scale", "matrix", "weights",
                                     "baseColorFactor", "emissiveFactor", "metallicFactor", "roughnessFactor",
                                     "alphaCutoff", "strength", "yfov", "aspectRatio", "znear", "zfar", "xmag",
                                     "ymag", "intensity", "color", "range", "innerConeAngle", "outerConeAngle"};

void checkIntegers(Json& j, const std::string& path, bool asNumber, const std::string& name) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& key = it.key();
      if (key == "extras") continue;
      if (!asNumber && (key == "byteLength" || key == "byteOffset" || key == "byteStride" || key == "count")) continue;
      bool number = asNumber || key == "extensions";
      for (const char* f : kNumberFields) number = number || key == f;
      checkIntegers(it.value(), path + "." + key, number, name);
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      checkIntegers(j[i], path + "[" + str(std::uint64_t(i)) + "]", asNumber, name);
  } else if (j.is_number_unsigned() || j.is_number_integer()) {
    const bool fits = j.is_number_unsigned() ? j.get<std::uint64_t>() <= std::uint64_t(std::numeric_limits<int>::max())
                                             : j.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                                                   j.get<std::int64_t>() <= std::numeric_limits<int>::max();
    if (fits) return;
    if (asNumber) {
      j = j.get<double>();
      return;
    }
    throw Error(name + ": " + path.substr(1) + ": " + j.dump() + " is out of range for an index (at most " +
                str(std::numeric_limits<int>::max()) + ")");
  }
}

// A relative URI (buffer or image) vetted against the sandbox: no scheme, not absolute, no ".."
// segment, resolving to a regular file inside the scene folder. Returns the resolved path.
std::string vetUri(const std::string& uri, const std::string& field, const Sandbox& box) {
  std::string shown = quoted(uri);
  std::size_t colon = uri.find(':'), slash = uri.find('/');
  if (colon != std::string::npos && (slash == std::string::npos || colon < slash))
    throw Error(field + " " + shown + ": URI schemes are not supported (use a relative path inside the scene directory)");
  if (box.root.empty()) throw Error(field + " " + shown + ": external URIs are refused for a scene loaded from memory");
  std::string path = tinygltf::dlib::urldecode(uri);
  if (path.empty()) throw Error(field + ": empty URI");
  if (path[0] == '/' || path[0] == '\\')
    throw Error(field + " " + shown + ": absolute paths are refused (use a path relative to the scene file)");
  if (path.find('\0') != std::string::npos) throw Error(field + " " + shown + ": contains a NUL character");
  std::size_t start = 0;
  while (start <= path.size()) {
    std::size_t end = path.find_first_of("/\\", start);
    if (end == std::string::npos) end = path.size();
    if (path.compare(start, end - start, "..") == 0 && end - start == 2)
      throw Error(field + " " + shown + ": \"..\" would leave the scene directory");
    start = end + 1;
  }
  std::string resolved, why;
  if (!resolveInside(box, box.root + "/" + path, &resolved, &why)) throw Error(field + " " + shown + ": " + why);
  return resolved;
}

// EXT_meshopt_compression placeholder: a buffer without a uri that is not the GLB BIN chunk,
// allowed when it is marked {"fallback": true} or the extension is required (the extension's
// "Fallback buffers" section). Its bytes do not exist; only compressed bufferViews may use it.
bool isMeshoptPlaceholder(const Json& root, const Json& buffer, std::size_t index, bool binary) {
  if (buffer.contains("uri") || (binary && index == 0)) return false;
  auto ext = buffer.find("extensions");
  if (ext != buffer.end() && ext->is_object()) {
    auto m = ext->find("EXT_meshopt_compression");
    if (m != ext->end() && m->is_object()) {
      auto f = m->find("fallback");
      if (f != m->end() && f->is_boolean() && f->get<bool>()) return true;
    }
  }
  auto req = root.find("extensionsRequired");
  if (req == root.end() || !req->is_array()) return false;
  for (const Json& e : *req)
    if (e.is_string() && e.get<std::string>() == "EXT_meshopt_compression") return true;
  return false;
}

// Checks the buffers before tinygltf copies them: buffers[i].uri against the sandbox (data URIs
// must decode to exactly byteLength bytes), the GLB BIN chunk reference, and the total size.
// tinygltf 2.7.0 copies the BIN chunk once for every buffer without a uri and reads an external
// file once for every buffer naming it, so a small file could otherwise ask for gigabytes; and it
// takes &data.at(0) of an empty vector for a BIN buffer of byteLength 0 (std::out_of_range).
// Placeholder buffers (isMeshoptPlaceholder) are replaced by a 1-byte data URI and listed in
// `placeholders`; they still count towards the total, which also caps their decoded contents.
void checkBuffers(Json& root, const Sandbox& box, const std::string& name, bool binary, std::uint64_t binSize,
                  std::set<int>* placeholders) {
  auto buffers = root.find("buffers");
  if (buffers == root.end() || !buffers->is_array()) return;
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < buffers->size(); ++i) {
    Json& b = (*buffers)[i];
    const std::string at = name + ": buffers[" + str(std::uint64_t(i)) + "]";
    auto bl = b.find("byteLength");
    const std::uint64_t declared = bl != b.end() && bl->is_number_unsigned() ? bl->get<std::uint64_t>() : 0;
    if (!addChecked(total, declared, &total) || total > kMaxFileBytes)
      throw Error(at + ".byteLength: the buffers add up to more than the 1 GiB limit");
    if (isMeshoptPlaceholder(root, b, i, binary)) {
      placeholders->insert(int(i));
      b["byteLength"] = 1;
      b["uri"] = "data:application/octet-stream;base64,AA==";
      continue;
    }
    auto u = b.find("uri");
    if (u == b.end()) {
      if (!binary) throw Error(at + ": no uri (only a .glb file can hold a buffer without one)");
      if (i != 0) throw Error(at + ": no uri, but only buffers[0] can refer to the GLB BIN chunk");
      if (binSize == 0) throw Error(at + ": refers to the GLB BIN chunk, but the file has none (or it is empty)");
      if (declared == 0 || declared > binSize)
        throw Error(at + ".byteLength: " + str(declared) + " must be between 1 and the BIN chunk size " + str(binSize));
      continue;
    }
    const std::string field = at + ".uri";
    if (!u->is_string()) throw Error(field + ": not a string");
    const std::string& uri = u->get_ref<const std::string&>();
    const std::uint64_t byteLength = declared;
    if (uri.compare(0, 5, "data:") == 0) {
      const char* prefix = nullptr;
      for (const char* p : kDataUriPrefixes)
        if (uri.compare(0, std::strlen(p), p) == 0) prefix = p;
      if (!prefix)
        throw Error(field + ": unsupported data URI (expected data:application/octet-stream;base64, or "
                            "data:application/gltf-buffer;base64,)");
      std::string decoded = tinygltf::base64_decode(uri.substr(std::strlen(prefix)));
      if (decoded.size() != byteLength)
        throw Error(field + ": the data URI holds " + str(std::uint64_t(decoded.size())) + " bytes but byteLength is " +
                    str(byteLength));
      continue;
    }
    vetUri(uri, field, box);
  }
}

// KHR_draco_mesh_compression primitives: their indices accessor has no bufferView (the indices
// are in the Draco data), which tinygltf 2.7.0 refuses ("accessor[i] invalid bufferView"). The
// `indices` field is taken out before tinygltf parses and kept here, by (mesh, primitive).
using DracoIndices = std::map<std::pair<int, int>, int>;

DracoIndices takeDracoIndices(Json& root, const std::string& name) {
  DracoIndices out;
  auto meshes = root.find("meshes");
  if (meshes == root.end() || !meshes->is_array()) return out;
  for (std::size_t m = 0; m < meshes->size(); ++m) {
    Json& mesh = (*meshes)[m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    Json& prims = mesh["primitives"];
    for (std::size_t p = 0; p < prims.size(); ++p) {
      Json& prim = prims[p];
      if (!prim.is_object() || !prim.contains("indices")) continue;
      auto ext = prim.find("extensions");
      if (ext == prim.end() || !ext->is_object() || !ext->contains("KHR_draco_mesh_compression")) continue;
      const Json& idx = prim["indices"];
      if (!idx.is_number_unsigned() || idx.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<int>::max()))
        throw Error(name + ": meshes[" + str(std::uint64_t(m)) + "].primitives[" + str(std::uint64_t(p)) +
                    "].indices: " + idx.dump() + " is not an index");
      out[{int(m), int(p)}] = int(idx.get<std::uint64_t>());
      prim.erase("indices");
    }
  }
  return out;
}

// An image as the file declares it; `images` never reaches tinygltf (see the top of this file).
struct ImageSource {
  std::string name;
  std::string uri;      // data: URI or relative path; empty with a bufferView
  int bufferView = -1;  // >= 0: the bytes are this bufferView
};

std::vector<ImageSource> parseImages(const Json& root, const std::string& name) {
  std::vector<ImageSource> out;
  auto images = root.find("images");
  if (images == root.end()) return out;
  if (!images->is_array()) throw Error(name + ": images: not an array");
  for (std::size_t i = 0; i < images->size(); ++i) {
    const Json& im = (*images)[i];
    const std::string at = name + ": images[" + str(std::uint64_t(i)) + "]";
    if (!im.is_object()) throw Error(at + ": not an object");
    ImageSource src;
    if (auto n = im.find("name"); n != im.end()) {
      if (!n->is_string()) throw Error(at + ".name: not a string");
      src.name = n->get<std::string>();
    }
    auto u = im.find("uri");
    auto bv = im.find("bufferView");
    if ((u != im.end()) == (bv != im.end())) throw Error(at + ": needs exactly one of \"uri\" and \"bufferView\"");
    if (u != im.end()) {
      if (!u->is_string()) throw Error(at + ".uri: not a string");
      src.uri = u->get<std::string>();
      if (src.uri.empty()) throw Error(at + ".uri: empty URI");
    } else {
      if (!bv->is_number_unsigned() || bv->get<std::uint64_t>() > std::uint64_t(std::numeric_limits<int>::max()))
        throw Error(at + ".bufferView: " + bv->dump() + " is not an index");
      src.bufferView = int(bv->get<std::uint64_t>());
    }
    if (auto m = im.find("mimeType"); m != im.end() && !m->is_string()) throw Error(at + ".mimeType: not a string");
    out.push_back(std::move(src));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Model -> Scene.

// An accessor's elements: `count` elements `stride` bytes apart from `base`, each `components`
// values of `componentType` (normalized integers map to [0, 1] or [-1, 1]). `base` points into
// a buffer of the model or into decoded data the Converter owns.
struct AccessorData {
  const unsigned char* base = nullptr;
  std::uint64_t stride = 0;
  std::uint64_t count = 0;
  int componentType = 0;
  int components = 0;
  bool normalized = false;
};

// An accepted (componentType, normalized) pair of a vertex attribute. normalized: 0 false,
// 1 true, 2 either. quantized: only with KHR_mesh_quantization.
struct AttributeFormat {
  int componentType;
  int normalized;
  bool quantized;
};

constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE;
constexpr int kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;
constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;

// glTF 2.0 section 3.7.2.1 (core) and KHR_mesh_quantization (quantized).
const std::vector<AttributeFormat> kPositionFormats = {
    {kFloat, 0, false}, {kByte, 2, true}, {kUByte, 2, true}, {kShort, 2, true}, {kUShort, 2, true}};
const std::vector<AttributeFormat> kNormalFormats = {{kFloat, 0, false}, {kByte, 1, true}, {kShort, 1, true}};
const std::vector<AttributeFormat> kTexcoordFormats = {{kFloat, 0, false}, {kUByte, 1, false}, {kUShort, 1, false},
                                                       {kByte, 2, true},   {kUByte, 0, true},  {kShort, 2, true},
                                                       {kUShort, 0, true}};
const std::vector<AttributeFormat> kIndexFormats = {{kUByte, 0, false}, {kUShort, 0, false}, {kUInt, 0, false}};

const char* componentTypeName(int t) {
  switch (t) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "5120 (byte)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "5121 (unsigned byte)";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "5122 (short)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "5123 (unsigned short)";
    case TINYGLTF_COMPONENT_TYPE_INT: return "5124 (int)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "5125 (unsigned int)";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "5126 (float)";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "5130 (double)";
    default: return "unknown";
  }
}

const char* typeName(int t) {
  switch (t) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

const char* modeName(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS (0)";
    case TINYGLTF_MODE_LINE: return "LINES (1)";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP (2)";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP (3)";
    default: return "invalid";
  }
}

bool allFinite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

class Converter {
 public:
  Converter(const tinygltf::Model& model, const std::string& name, const LoadOptions& options, const Sandbox& box,
            const std::vector<ImageSource>& images, const std::set<int>& placeholders, const DracoIndices& dracoIndices,
            Scene& scene)
      : model_(model), name_(name), options_(options), box_(box), images_(images), placeholders_(placeholders),
        dracoIndices_(dracoIndices), scene_(scene) {}

  void run() {
    checkExtensionLists();
    checkModelFeatures();
    for (std::size_t i = 0; i < model_.materials.size(); ++i) scene_.materials.push_back(convertMaterial(int(i)));
    traverse();
    if (badTexcoords_ > 0)
      warnOnce(str(badTexcoords_) + " texture coordinate(s) not finite or beyond " + fmt(kMaxTexcoord) +
               "; replaced by (0, 0)");
    if (badTangents_ > 0)
      warnOnce(str(badTangents_) + " TANGENT value(s) not finite, zero or along the normal; replaced by a tangent "
               "perpendicular to the normal");
    if (!notRendered_.empty()) {
      std::string list;
      for (const std::string& f : notRendered_) list += (list.empty() ? "" : ", ") + f;
      warnOnce("read but not rendered yet: " + list + " (rendered as if absent: opaque, reflecting only, "
               "without those textures)");
    }
    if (flatUvTangents_ > 0)
      warnOnce(str(flatUvTangents_) + " triangle corner(s) of normal-mapped primitives have texture coordinates of "
               "zero area; their tangent is arbitrary (perpendicular to the normal)");
    chooseCamera();
  }

 private:
  struct CameraInstance {
    int camera;
    int node;
    glm::dmat4 world;
  };

  const tinygltf::Model& model_;
  const std::string& name_;
  const LoadOptions& options_;
  const Sandbox& box_;
  const std::vector<ImageSource>& images_;
  const std::set<int>& placeholders_;  // EXT_meshopt_compression fallback buffers: no data
  const DracoIndices& dracoIndices_;   // the indices accessors of Draco primitives
  Scene& scene_;
  std::set<std::string> warned_;
  std::set<std::string> seenExtensions_;  // used by materials/nodes, for the extensionsUsed check
  int defaultMaterial_ = -1;
  std::vector<CameraInstance> cameras_;
  std::map<int, std::int32_t> sceneImage_;  // glTF image index -> Scene::images index
  std::uint64_t totalImagePixels_ = 0;
  std::map<int, std::vector<std::uint8_t>> meshoptViews_;  // decoded EXT_meshopt_compression views
  std::uint64_t decodedBytes_ = 0;  // meshopt and Draco output, capped at kMaxFileBytes
  std::map<std::pair<int, int>, DracoMesh> draco_;  // (mesh, primitive) -> decoded once
  std::uint64_t badTexcoords_ = 0, badTangents_ = 0, flatUvTangents_ = 0;

  [[noreturn]] void fail(const std::string& what) const { throw Error(name_ + ": " + what); }

  void warnOnce(const std::string& text) {
    if (warned_.insert(text).second) scene_.warnings.push_back(name_ + ": " + text);
  }

  static std::string at(const char* array, std::int64_t i) { return std::string(array) + "[" + str(i) + "]"; }

  void checkIndex(int index, std::size_t size, const std::string& field, const char* what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= size)
      fail(field + ": " + str(index) + " is out of range (the file has " + str(std::uint64_t(size)) + " " + what + ")");
  }

  bool declared(const char* extension) const {
    return std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), extension) !=
           model_.extensionsUsed.end();
  }

  // ---- extensions and unsupported features ----

  void checkExtensionLists() {
    for (const std::string& e : model_.extensionsRequired)
      if (!isSupportedExtension(e)) {
        const char* why = unsupportedReason(e);
        fail("extensionsRequired: " + quoted(e) + " is not supported" + (why ? std::string(": ") + why : "") +
             " (supported: " + supportedExtensionList() + ")");
      }
    for (const std::string& e : model_.extensionsUsed)
      if (!isSupportedExtension(e)) warnOnce("extension " + e + " is not supported; ignored");
  }

  void checkDeclared() {
    for (const std::string& e : seenExtensions_)
      if (std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), e) == model_.extensionsUsed.end())
        warnOnce("extension " + e + " is used but not declared in extensionsUsed");
  }

  // What the loader reads but the renderer does not use yet (the GPU side of issue 18): named in
  // one warning at the end of run(), so that a user is told. Remove a call when the renderer
  // uses the feature.
  std::set<std::string> notRendered_;
  void notRenderedYet(const char* feature) { notRendered_.insert(feature); }

  void checkModelFeatures() {
    if (!model_.skins.empty()) warnOnce("skins are not supported; skinned meshes are drawn in their bind pose");
    if (!model_.animations.empty()) warnOnce("animations are not supported; the static pose is rendered");
    if (model_.scenes.size() > 1) warnOnce("the file has " + str(std::uint64_t(model_.scenes.size())) +
                                           " scenes; only the default one is rendered");
  }

  // ---- images ----

  struct Bytes {
    const std::uint8_t* data = nullptr;
    std::uint64_t size = 0;
  };

  // The bytes of bufferViews[index] (decoded first when it is EXT_meshopt_compression).
  Bytes viewBytes(int index, const std::string& user) {
    checkIndex(index, model_.bufferViews.size(), user + ": bufferView", "bufferViews");
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(index)];
    const std::string bvField = at("bufferViews", index);
    auto ext = bv.extensions.find("EXT_meshopt_compression");
    if (ext != bv.extensions.end()) {
      seenExtensions_.insert("EXT_meshopt_compression");
      const std::vector<std::uint8_t>& decoded = meshoptView(index, ext->second);
      return {decoded.data(), decoded.size()};
    }
    checkIndex(bv.buffer, model_.buffers.size(), bvField + ".buffer", "buffers");
    if (placeholders_.count(bv.buffer))
      fail(bvField + ".buffer: buffers[" + str(bv.buffer) + "] is an EXT_meshopt_compression fallback buffer "
           "without data, but this bufferView is not compressed");
    const tinygltf::Buffer& buffer = model_.buffers[std::size_t(bv.buffer)];
    std::uint64_t bvEnd = 0;
    if (!addChecked(bv.byteOffset, bv.byteLength, &bvEnd) || bvEnd > buffer.data.size())
      fail(bvField + ": byteOffset " + str(std::uint64_t(bv.byteOffset)) + " + byteLength " +
           str(std::uint64_t(bv.byteLength)) + " exceeds buffers[" + str(bv.buffer) + "] (byteLength " +
           str(std::uint64_t(buffer.data.size())) + ")");
    return {buffer.data.data() + bv.byteOffset, bv.byteLength};
  }

  const std::vector<std::uint8_t>& meshoptView(int index, const tinygltf::Value& ext) {
    auto cached = meshoptViews_.find(index);
    if (cached != meshoptViews_.end()) return cached->second;
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(index)];
    const std::string field = at("bufferViews", index) + ".extensions.EXT_meshopt_compression";
    if (!ext.IsObject()) fail(field + ": must be an object");
    auto integer = [&](const char* key, bool required, std::uint64_t fallback) -> std::uint64_t {
      if (!ext.Has(key)) {
        if (required) fail(field + ": needs \"" + key + "\"");
        return fallback;
      }
      const tinygltf::Value& v = ext.Get(key);
      if (!v.IsInt() || v.Get<int>() < 0)
        fail(field + "." + key + ": must be a non-negative integer (at most " + str(std::numeric_limits<int>::max()) + ")");
      return std::uint64_t(v.Get<int>());
    };
    auto text = [&](const char* key, const char* fallback) -> std::string {
      if (!ext.Has(key)) return fallback;
      if (!ext.Get(key).IsString()) fail(field + "." + key + ": must be a string");
      return ext.Get(key).Get<std::string>();
    };
    const std::uint64_t buffer = integer("buffer", true, 0), offset = integer("byteOffset", false, 0),
                        length = integer("byteLength", true, 0), stride = integer("byteStride", true, 0),
                        count = integer("count", true, 0);
    const std::string modeName = text("mode", ""), filterName = text("filter", "NONE");
    MeshoptMode mode;
    if (modeName == "ATTRIBUTES") mode = MeshoptMode::Attributes;
    else if (modeName == "TRIANGLES") mode = MeshoptMode::Triangles;
    else if (modeName == "INDICES") mode = MeshoptMode::Indices;
    else fail(field + ".mode: " + quoted(modeName) + " (expected ATTRIBUTES, TRIANGLES or INDICES)");
    MeshoptFilter filter;
    if (filterName == "NONE") filter = MeshoptFilter::None;
    else if (filterName == "OCTAHEDRAL") filter = MeshoptFilter::Octahedral;
    else if (filterName == "QUATERNION") filter = MeshoptFilter::Quaternion;
    else if (filterName == "EXPONENTIAL") filter = MeshoptFilter::Exponential;
    else fail(field + ".filter: " + quoted(filterName) + " (expected NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL)");
    if (bv.byteStride != 0 && bv.byteStride != stride)
      fail(field + ".byteStride: " + str(stride) + " differs from the bufferView's byteStride " +
           str(std::uint64_t(bv.byteStride)));
    std::uint64_t decodedSize = 0;
    if (!mulChecked(count, stride, &decodedSize) || decodedSize != bv.byteLength)
      fail(field + ": count " + str(count) + " x byteStride " + str(stride) + " differs from the bufferView's "
           "byteLength " + str(std::uint64_t(bv.byteLength)));
    checkIndex(int(buffer), model_.buffers.size(), field + ".buffer", "buffers");
    if (placeholders_.count(int(buffer)))
      fail(field + ".buffer: buffers[" + str(buffer) + "] is a fallback buffer without data");
    const tinygltf::Buffer& b = model_.buffers[std::size_t(buffer)];
    std::uint64_t end = 0;
    if (!addChecked(offset, length, &end) || end > b.data.size())
      fail(field + ": byteOffset " + str(offset) + " + byteLength " + str(length) + " exceeds buffers[" + str(buffer) +
           "] (byteLength " + str(std::uint64_t(b.data.size())) + ")");
    if (!addChecked(decodedBytes_, decodedSize, &decodedBytes_) || decodedBytes_ > kMaxFileBytes)
      fail(field + ": the decoded geometry adds up to more than the 1 GiB limit");
    try {
      return meshoptViews_[index] = decodeMeshopt(b.data.data() + offset, std::size_t(length), count, stride, mode,
                                                  filter, kMaxFileBytes);
    } catch (const Error& e) {
      fail(field + ": " + e.what());
    }
  }

  // The Scene image of glTF images[index], decoded on first use. `user` names who needs it, for
  // messages ("baseColorTexture of materials[0] \"Wood\" (textures[2])").
  std::int32_t sceneImage(int index, const std::string& user) {
    auto cached = sceneImage_.find(index);
    if (cached != sceneImage_.end()) return cached->second;
    const ImageSource& src = images_[std::size_t(index)];
    std::string where = at("images", index);
    if (!src.name.empty()) where += " " + quoted(src.name);
    if (!src.uri.empty() && src.uri.compare(0, 5, "data:") != 0) where += " (uri " + quoted(src.uri) + ")";
    where += ", used by " + user;
    std::vector<unsigned char> owned;
    Bytes bytes;
    if (src.bufferView >= 0) {
      bytes = viewBytes(src.bufferView, where);
    } else if (src.uri.compare(0, 5, "data:") == 0) {
      const std::size_t comma = src.uri.find(',');
      const std::string header = src.uri.substr(0, std::min(comma, std::size_t(200)));
      if (comma == std::string::npos || header.size() < 7 || header.compare(header.size() - 7, 7, ";base64") != 0)
        fail(where + ": only base64 data: URIs are supported for images");
      std::string decoded = tinygltf::base64_decode(src.uri.substr(comma + 1));
      owned.assign(decoded.begin(), decoded.end());
      bytes = {owned.data(), owned.size()};
    } else {
      std::string path;
      try {
        path = vetUri(src.uri, name_ + ": " + at("images", index) + ".uri", box_);
      } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (used by " + user + ")");
      }
      std::string why;
      if (!readRegularFile(path, &owned, &why)) fail(where + ": cannot read " + quoted(src.uri) + ": " + why);
      bytes = {owned.data(), owned.size()};
    }
    ImageLimits limits;
    limits.maxPixels = options_.maxImagePixels;
    limits.maxBytes = options_.maxImageBytes;
    DecodedImage decoded;
    try {
      decoded = decodeImage(bytes.data, std::size_t(bytes.size), limits);
    } catch (const Error& e) {
      fail(where + ": " + e.what());
    }
    const std::uint64_t pixels = std::uint64_t(decoded.width) * std::uint64_t(decoded.height);
    if (!addChecked(totalImagePixels_, pixels, &totalImagePixels_) || totalImagePixels_ > options_.maxTotalImagePixels)
      fail(where + ": the scene's images add up to more than the limit of " + str(options_.maxTotalImagePixels) +
           " pixels");
    TextureImage image;
    image.name = !src.name.empty() ? src.name : (src.bufferView < 0 && src.uri.compare(0, 5, "data:") != 0)
                                                    ? src.uri
                                                    : at("images", index);
    image.source = std::uint32_t(index);
    image.width = std::uint32_t(decoded.width);
    image.height = std::uint32_t(decoded.height);
    image.rgba = std::move(decoded.rgba);
    const std::int32_t slot = std::int32_t(scene_.images.size());
    scene_.images.push_back(std::move(image));
    sceneImage_[index] = slot;
    return slot;
  }

  // ---- textures ----

  // A textureInfo wherever it comes from (tinygltf structs or an extension's JSON value).
  struct TextureInfoView {
    int index = -1;
    int texCoord = 0;
    const tinygltf::Value* transform = nullptr;  // KHR_texture_transform, if present
  };

  template <typename Info>
  TextureInfoView viewOf(const Info& info) {
    TextureInfoView v;
    v.index = info.index;
    v.texCoord = info.texCoord;
    auto t = info.extensions.find("KHR_texture_transform");
    if (t != info.extensions.end()) v.transform = &t->second;
    for (const auto& [ext, value] : info.extensions) seenExtensions_.insert(ext);
    return v;
  }

  // A textureInfo inside an extension object (KHR_materials_transmission, ...).
  TextureInfoView viewOf(const tinygltf::Value& info, const std::string& field) {
    if (!info.IsObject()) fail(field + ": must be an object {\"index\": ...}");
    TextureInfoView v;
    if (!info.Has("index") || !info.Get("index").IsInt()) fail(field + ".index: must be an integer");
    v.index = info.Get("index").Get<int>();
    if (info.Has("texCoord")) {
      if (!info.Get("texCoord").IsInt()) fail(field + ".texCoord: must be an integer");
      v.texCoord = info.Get("texCoord").Get<int>();
    }
    if (info.Has("extensions") && info.Get("extensions").IsObject() &&
        info.Get("extensions").Has("KHR_texture_transform")) {
      v.transform = &info.Get("extensions").Get("KHR_texture_transform");
      seenExtensions_.insert("KHR_texture_transform");
    }
    return v;
  }

  // KHR_texture_transform as uv' = T(offset) R(rotation) S(scale) uv, with the rotation of the
  // glTF implementations and the extension's example (issue KhronosGroup/glTF#1563: the GLSL
  // listing of the specification has the transposed matrix): u' = cos r u + sin r v,
  // v' = -sin r u + cos r v, i.e. counter-clockwise in the u-right, v-down texture space.
  glm::mat3x2 parseTransform(const tinygltf::Value& t, const std::string& field, int* texCoord) {
    if (!t.IsObject()) fail(field + ": must be an object");
    auto number = [&](const tinygltf::Value& v, const std::string& f) {
      if (!v.IsNumber()) fail(f + ": must be a number");
      double x = v.GetNumberAsDouble();
      if (!std::isfinite(x) || std::fabs(x) > kMaxTexcoord)
        fail(f + ": " + fmt(x) + " is not a finite number of magnitude at most " + fmt(kMaxTexcoord));
      return x;
    };
    auto pair = [&](const char* key, double fallback, double out[2]) {
      out[0] = out[1] = fallback;
      if (!t.Has(key)) return;
      const tinygltf::Value& v = t.Get(key);
      if (!v.IsArray() || v.ArrayLen() != 2) fail(field + "." + key + ": expected 2 numbers");
      for (int k = 0; k < 2; ++k) out[k] = number(v.Get(k), field + "." + key + "[" + str(k) + "]");
    };
    double offset[2], scale[2];
    pair("offset", 0.0, offset);
    pair("scale", 1.0, scale);
    const double rotation = t.Has("rotation") ? number(t.Get("rotation"), field + ".rotation") : 0.0;
    if (t.Has("texCoord")) {
      const tinygltf::Value& v = t.Get("texCoord");
      if (!v.IsInt() || v.Get<int>() < 0) fail(field + ".texCoord: must be a non-negative integer");
      *texCoord = v.Get<int>();
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    glm::mat3x2 m;  // m[column][row]
    m[0][0] = float(c * scale[0]);
    m[0][1] = float(-s * scale[0]);
    m[1][0] = float(s * scale[1]);
    m[1][1] = float(c * scale[1]);
    m[2][0] = float(offset[0]);
    m[2][1] = float(offset[1]);
    return m;
  }

  static WrapMode wrapMode(int v, const std::string& field, const Converter& self) {
    switch (v) {
      case TINYGLTF_TEXTURE_WRAP_REPEAT: return WrapMode::Repeat;
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WrapMode::ClampToEdge;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WrapMode::MirroredRepeat;
      default:
        self.fail(field + ": " + str(v) + " is not a wrap mode (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT)");
    }
  }

  // A material slot's texture, or an absent one (image -1) when the slot is unused or the
  // texture cannot be used (then a warning says why and the factor is used alone).
  TextureRef textureRef(const TextureInfoView& info, const std::string& slot, ColorSpace colorSpace) {
    TextureRef ref;
    ref.colorSpace = colorSpace;
    if (info.index == -1) return ref;
    checkIndex(info.index, model_.textures.size(), slot + ".index", "textures");
    const tinygltf::Texture& texture = model_.textures[std::size_t(info.index)];
    const std::string tfield = at("textures", info.index);
    for (const auto& [ext, value] : texture.extensions) seenExtensions_.insert(ext);
    if (texture.source < 0) {
      std::string only;
      for (const auto& [ext, value] : texture.extensions) only += (only.empty() ? "" : ", ") + ext;
      warnOnce(tfield + " has no PNG or JPEG source" + (only.empty() ? "" : " (only " + only + ")") + "; " + slot +
               " uses its factor alone");
      return ref;
    }
    checkIndex(texture.source, images_.size(), tfield + ".source", "images");
    int texCoord = info.texCoord;
    if (texCoord < 0) fail(slot + ".texCoord: " + str(texCoord) + " is negative");
    if (info.transform) ref.transform = parseTransform(*info.transform, slot + ".extensions.KHR_texture_transform", &texCoord);
    if (texCoord > 1) {
      warnOnce(slot + " uses TEXCOORD_" + str(texCoord) + "; only TEXCOORD_0 and TEXCOORD_1 are read, so it uses its "
               "factor alone");
      return TextureRef{};
    }
    ref.texCoord = std::uint32_t(texCoord);
    if (texture.sampler != -1) {
      checkIndex(texture.sampler, model_.samplers.size(), tfield + ".sampler", "samplers");
      const tinygltf::Sampler& sampler = model_.samplers[std::size_t(texture.sampler)];
      const std::string sfield = at("samplers", texture.sampler);
      ref.wrapS = wrapMode(sampler.wrapS, sfield + ".wrapS", *this);
      ref.wrapT = wrapMode(sampler.wrapT, sfield + ".wrapT", *this);
      switch (sampler.magFilter) {
        case -1:
        case TINYGLTF_TEXTURE_FILTER_LINEAR: ref.magFilter = FilterMode::Linear; break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST: ref.magFilter = FilterMode::Nearest; break;
        default: fail(sfield + ".magFilter: " + str(sampler.magFilter) + " is not a filter (9728 NEAREST, 9729 LINEAR)");
      }
      // Mipmapped filters keep their filter within a level: there are no mipmaps.
      switch (sampler.minFilter) {
        case -1:
        case TINYGLTF_TEXTURE_FILTER_LINEAR:
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR: ref.minFilter = FilterMode::Linear; break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST:
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR: ref.minFilter = FilterMode::Nearest; break;
        default:
          fail(sfield + ".minFilter: " + str(sampler.minFilter) +
               " is not a filter (9728 NEAREST, 9729 LINEAR, 9984-9987 the mipmapped ones)");
      }
    }
    ref.image = sceneImage(texture.source, slot + " (" + tfield + ")");
    return ref;
  }

  // ---- materials ----

  ParamValue toParamValue(const tinygltf::Value& v, const std::string& where) const {
    if (v.IsNumber()) return ParamValue::num(v.GetNumberAsDouble());
    if (v.IsString()) return ParamValue::str(v.Get<std::string>());
    if (v.IsArray()) {
      ParamValue p;
      p.kind = ParamValue::Kind::Array;
      for (std::size_t i = 0; i < v.ArrayLen(); ++i) p.items.push_back(toParamValue(v.Get(int(i)), where));
      return p;
    }
    throw Error(where + ": must be a number, a string or an array");
  }

  Material convertMaterial(int index) {
    const tinygltf::Material& gm = model_.materials[std::size_t(index)];
    const std::string field = at("materials", index) + (gm.name.empty() ? "" : " " + quoted(gm.name));
    Material m;
    m.name = gm.name.empty() ? at("materials", index) : gm.name;

    for (const auto& [ext, value] : gm.extensions) {
      seenExtensions_.insert(ext);
      if (!isSupportedExtension(ext)) warnOnce("extension " + ext + " is not supported; ignored");
    }
    readGltfMaterialData(gm, field, m);

    auto brdf = gm.extensions.find("NUSSELT_brdf");
    if (brdf != gm.extensions.end()) {
      const std::string context = name_ + ": " + field + " NUSSELT_brdf";
      const tinygltf::Value& v = brdf->second;
      const std::string known = knownModelNames();
      if (!v.IsObject())
        throw Error(context + ": must be an object {\"model\": ..., \"params\": {...}} or {\"components\": [...]}");
      // One model and its parameters: {"model": name, "params": {...}} (the object `where` names).
      auto parseModel = [&](const tinygltf::Value& o, const std::string& where) -> std::pair<const ModelSpec*, BrdfParams> {
        if (!o.Has("model") || !o.Get("model").IsString())
          throw Error(where + ": \"model\" must be a string (known models: " + known + ")");
        const std::string modelName = o.Get("model").Get<std::string>();
        const ModelSpec* spec = findModel(modelName);
        if (!spec) throw Error(where + ": unknown model " + quoted(modelName) + " (known models: " + known + ")");
        if (spec->measured) {
          // A measured table: {"model": "merl", "file": "name.binary"}, the path relative to the
          // scene file and inside its folder, as buffers and images (docs/measured.md).
          if (o.Has("params")) throw Error(where + ": model " + quoted(modelName) + " has no \"params\" (it reads \"file\")");
          if (!o.Has("file") || !o.Get("file").IsString())
            throw Error(where + ".file: model " + quoted(modelName) + " needs \"file\", a MERL binary file relative to the scene");
          const std::string file = o.Get("file").Get<std::string>();
          const std::string path = vetUri(file, where + ".file", box_);
          BrdfParams p = loadMerl(path, where + ".file " + quoted(file));
          const MerlTable& t = merlTable(p);
          if (t.unmeasured)
            warnOnce(file + ": " + str(std::uint64_t(t.unmeasured)) + " of " + str(std::uint64_t(MERL_NODES)) +
                     " table nodes not measured (negative), filled from the nearest measured node (docs/measured.md)");
          return {spec, p};
        }
        if (o.Has("file")) throw Error(where + ".file: only measured models (merl) read a file");
        NamedParams params;
        if (o.Has("params")) {
          const tinygltf::Value& p = o.Get("params");
          if (!p.IsObject()) throw Error(where + ": \"params\" must be an object");
          for (const std::string& key : p.Keys())
            params.emplace_back(key, toParamValue(p.Get(key), where + ": parameter " + quoted(key)));
        }
        return {spec, packParams(*spec, params, where)};
      };
      if (v.Has("components")) {
        // A combined material: f = sum_k weight_k f_k (docs/scenes.md).
        if (v.Has("model") || v.Has("params"))
          throw Error(context + ": give either \"model\" (and \"params\") or \"components\", not both");
        const tinygltf::Value& list = v.Get("components");
        if (!list.IsArray() || list.ArrayLen() == 0)
          throw Error(context + ".components: must be a non-empty array of {\"model\": ..., \"weight\": ..., "
                                "\"params\": {...}}");
        if (list.ArrayLen() > MAX_COMPONENTS)
          throw Error(context + ".components: " + str(std::uint64_t(list.ArrayLen())) + " components, at most " +
                      str(std::uint64_t(MAX_COMPONENTS)));
        for (std::size_t k = 0; k < list.ArrayLen(); ++k) {
          const std::string where = context + ".components[" + str(std::uint64_t(k)) + "]";
          const tinygltf::Value& c = list.Get(int(k));
          if (!c.IsObject()) throw Error(where + ": must be an object {\"model\": ..., \"weight\": ..., \"params\": {...}}");
          for (const std::string& key : c.Keys())
            if (key != "model" && key != "weight" && key != "params" && key != "file")
              throw Error(where + ": unknown field " + quoted(key) + " (expected model, weight, params, file)");
          MaterialComponent mc;
          if (c.Has("weight")) {
            const tinygltf::Value& w = c.Get("weight");
            if (!w.IsNumber()) throw Error(where + ".weight: must be a number");
            double weight = w.GetNumberAsDouble();
            if (!std::isfinite(weight) || weight < 0 || weight > 1e6)
              throw Error(where + ".weight: " + fmt(weight) + " is not a finite number in [0, 1e6]");
            mc.weight = static_cast<float>(weight);
          }
          auto [spec, params] = parseModel(c, where);
          mc.model = spec->id;
          mc.params = params;
          m.components.push_back(mc);
        }
        m.model = m.components[0].model;
        m.params = m.components[0].params;
        // One component of weight 1 is the single-model form (same shading code and performance).
        if (m.components.size() == 1 && m.components[0].weight == 1.0f) m.components.clear();
      } else {
        // (tinygltf drops an empty array, so "components": [] arrives here.)
        if (!v.Has("model"))
          throw Error(context + ": needs \"model\" (a string; known models: " + known +
                      ") or \"components\" (a non-empty array of {\"model\": ..., \"weight\": ..., \"params\": {...}})");
        auto [spec, params] = parseModel(v, context);
        m.model = spec->id;
        m.params = params;
      }
    } else {
      // Without NUSSELT_brdf a material uses the glTF 2.0 metallic-roughness BRDF itself
      // (gltf_pbr): baseColor = baseColorFactor.rgb clamped to [0, 1] (alpha is ignored),
      // metallic = metallicFactor, roughness = roughnessFactor (glTF defaults 1 and 1).
      const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
      const std::vector<double>& c = pbr.baseColorFactor;
      if (c.size() != 4 || !allFinite(c))
        fail(field + ".pbrMetallicRoughness.baseColorFactor: expected 4 finite numbers");
      ParamValue base;
      base.kind = ParamValue::Kind::Array;
      for (int k = 0; k < 3; ++k) base.items.push_back(ParamValue::num(std::clamp(c[std::size_t(k)], 0.0, 1.0)));
      auto factor = [&](double v, const char* name) {
        if (!std::isfinite(v) || v < 0 || v > 1)
          fail(field + ".pbrMetallicRoughness." + name + ": " + fmt(v) + " is not in [0, 1]");
        return ParamValue::num(v);
      };
      m.model = MODEL_GLTF_PBR;
      m.params = packParams(*findModel("gltf_pbr"),
                            {{"baseColor", base},
                             {"metallic", factor(pbr.metallicFactor, "metallicFactor")},
                             {"roughness", factor(pbr.roughnessFactor, "roughnessFactor")}},
                            name_ + ": " + field);
      transmissiveMaterial(m, name_ + ": " + field);
    }

    const std::vector<double>& e = gm.emissiveFactor;
    if (e.size() != 3) fail(field + ".emissiveFactor: expected 3 numbers");
    for (double x : e)
      if (!std::isfinite(x) || x < 0) fail(field + ".emissiveFactor: " + fmt(x) + " is not a finite number >= 0");
    double strength = 1.0;
    auto es = gm.extensions.find("KHR_materials_emissive_strength");
    if (es != gm.extensions.end()) {
      const std::string esField = field + " KHR_materials_emissive_strength.emissiveStrength";
      if (!es->second.IsObject()) fail(field + " KHR_materials_emissive_strength: must be an object");
      if (es->second.Has("emissiveStrength")) {
        const tinygltf::Value& s = es->second.Get("emissiveStrength");
        if (!s.IsNumber()) fail(esField + ": must be a number");
        strength = s.GetNumberAsDouble();
        if (!std::isfinite(strength) || strength < 0) fail(esField + ": " + fmt(strength) + " is not a finite number >= 0");
      }
    }
    glm::dvec3 emission = glm::dvec3(e[0], e[1], e[2]) * strength;
    if (!std::isfinite(emission.x) || !std::isfinite(emission.y) || !std::isfinite(emission.z))
      fail(field + ": emissiveFactor x emissiveStrength overflows");
    m.emission = glm::vec3(emission);
    warnUnrenderedTextures(m);
    return m;
  }

  // The glTF material data beyond the BRDF parameters: factors, textures, alpha, sidedness,
  // transmission, ior and volume (scene.h, Material).
  void readGltfMaterialData(const tinygltf::Material& gm, const std::string& field, Material& m) {
    const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
    const std::vector<double>& c = pbr.baseColorFactor;
    if (c.size() != 4 || !allFinite(c)) fail(field + ".pbrMetallicRoughness.baseColorFactor: expected 4 finite numbers");
    for (int k = 0; k < 4; ++k) m.baseColorFactor[k] = float(std::clamp(c[std::size_t(k)], 0.0, 1.0));
    auto unit = [&](double v, const std::string& f) {
      if (!std::isfinite(v) || v < 0 || v > 1) fail(f + ": " + fmt(v) + " is not in [0, 1]");
      return float(v);
    };
    m.metallicFactor = unit(pbr.metallicFactor, field + ".pbrMetallicRoughness.metallicFactor");
    m.roughnessFactor = unit(pbr.roughnessFactor, field + ".pbrMetallicRoughness.roughnessFactor");
    m.baseColorTexture = textureRef(viewOf(pbr.baseColorTexture), field + ".pbrMetallicRoughness.baseColorTexture",
                                    ColorSpace::Srgb);
    m.metallicRoughnessTexture = textureRef(viewOf(pbr.metallicRoughnessTexture),
                                            field + ".pbrMetallicRoughness.metallicRoughnessTexture", ColorSpace::Linear);
    m.normalTexture = textureRef(viewOf(gm.normalTexture), field + ".normalTexture", ColorSpace::Linear);
    if (!std::isfinite(gm.normalTexture.scale) || std::fabs(gm.normalTexture.scale) > 1e6)
      fail(field + ".normalTexture.scale: " + fmt(gm.normalTexture.scale) + " is not a finite number in [-1e6, 1e6]");
    m.normalScale = float(gm.normalTexture.scale);
    m.emissiveTexture = textureRef(viewOf(gm.emissiveTexture), field + ".emissiveTexture", ColorSpace::Srgb);
    if (gm.occlusionTexture.index != -1)
      warnOnce("occlusionTexture is ignored: a path tracer computes occlusion itself (" + field + ")");

    if (gm.alphaMode == "OPAQUE" || gm.alphaMode.empty()) m.alphaMode = AlphaMode::Opaque;
    else if (gm.alphaMode == "MASK") m.alphaMode = AlphaMode::Mask;
    else if (gm.alphaMode == "BLEND") m.alphaMode = AlphaMode::Blend;
    else fail(field + ".alphaMode: " + quoted(gm.alphaMode) + " (expected OPAQUE, MASK or BLEND)");
    if (!std::isfinite(gm.alphaCutoff) || gm.alphaCutoff < 0)
      fail(field + ".alphaCutoff: " + fmt(gm.alphaCutoff) + " is not a finite number >= 0");
    m.alphaCutoff = float(std::min(gm.alphaCutoff, 2.0));  // above 1 all alike: nothing passes
    m.doubleSided = gm.doubleSided;

    auto extension = [&](const char* name) -> const tinygltf::Value* {
      auto it = gm.extensions.find(name);
      if (it == gm.extensions.end()) return nullptr;
      if (!it->second.IsObject()) fail(field + " " + name + ": must be an object");
      return &it->second;
    };
    auto number = [&](const tinygltf::Value& o, const char* key, const std::string& f, double fallback) {
      if (!o.Has(key)) return fallback;
      const tinygltf::Value& v = o.Get(key);
      if (!v.IsNumber()) fail(f + "." + key + ": must be a number");
      return v.GetNumberAsDouble();
    };
    if (const tinygltf::Value* t = extension("KHR_materials_transmission")) {
      const std::string f = field + " KHR_materials_transmission";
      m.transmissionFactor = unit(number(*t, "transmissionFactor", f, 0.0), f + ".transmissionFactor");
      if (t->Has("transmissionTexture")) {
        m.transmissionTexture = textureRef(viewOf(t->Get("transmissionTexture"), f + ".transmissionTexture"),
                                           f + ".transmissionTexture", ColorSpace::Linear);
      }
      // Rendered (convertMaterial, transmissiveMaterial) unless NUSSELT_brdf sets the BRDF.
      if (gm.extensions.count("NUSSELT_brdf")) notRenderedYet("KHR_materials_transmission with NUSSELT_brdf");
    }
    if (const tinygltf::Value* t = extension("KHR_materials_ior")) {
      const std::string f = field + " KHR_materials_ior";
      double ior = number(*t, "ior", f, 1.5);
      if (!std::isfinite(ior) || ior < 1 || ior > 100) fail(f + ".ior: " + fmt(ior) + " is not in [1, 100]");
      m.ior = float(ior);
      // Rendered as the dielectric's index of a transmitting material; not in the reflection
      // (gltf_pbr's f0 stays 0.04).
      if (!(m.transmissionFactor > 0) || gm.extensions.count("NUSSELT_brdf"))
        notRenderedYet("KHR_materials_ior (used only with KHR_materials_transmission)");
    }
    if (const tinygltf::Value* t = extension("KHR_materials_volume")) {
      const std::string f = field + " KHR_materials_volume";
      m.hasVolume = true;
      double thickness = number(*t, "thicknessFactor", f, 0.0);
      if (!std::isfinite(thickness) || thickness < 0 || thickness > 1e30)
        fail(f + ".thicknessFactor: " + fmt(thickness) + " is not a number in [0, 1e30]");
      m.thicknessFactor = float(thickness);
      if (t->Has("thicknessTexture"))
        warnOnce("KHR_materials_volume thicknessTexture is ignored: a path tracer measures thickness in the geometry");
      double distance = number(*t, "attenuationDistance", f, INFINITY);
      // (A positive distance below 1e-30 would round to a float 0.)
      if (!(distance >= 1e-30))
        fail(f + ".attenuationDistance: " + fmt(distance) + " is not a distance >= 1e-30 (metres)");
      m.attenuationDistance = distance > 1e30 ? INFINITY : float(distance);
      if (t->Has("attenuationColor")) {
        const tinygltf::Value& a = t->Get("attenuationColor");
        if (!a.IsArray() || a.ArrayLen() != 3) fail(f + ".attenuationColor: expected 3 numbers");
        for (int k = 0; k < 3; ++k) {
          if (!a.Get(k).IsNumber()) fail(f + ".attenuationColor: expected 3 numbers");
          m.attenuationColor[k] = unit(a.Get(k).GetNumberAsDouble(), f + ".attenuationColor[" + str(k) + "]");
        }
      }
      // Its presence (thicknessFactor > 0) makes the transmission refract (transmissiveMaterial),
      // and the attenuation then absorbs inside (Material::absorption). Without a refracting
      // volume no path travels inside, and the attenuation is not rendered.
      const bool refracts = m.thicknessFactor > 0.0f && m.transmissionFactor * (1.0f - m.metallicFactor) > 0.0f &&
                            !gm.extensions.count("NUSSELT_brdf");
      if (std::isfinite(m.attenuationDistance) && !refracts)
        notRenderedYet("KHR_materials_volume attenuation without thicknessFactor > 0 and transmission");
    }
  }

  // KHR_materials_transmission (docs/scenes.md, "Transmission"): a combined material, gltf_pbr with
  // weight 1 - w and a dielectric with weight w = transmissionFactor x (1 - metallic): the
  // dielectric's Fresnel reflection and the gltf_pbr component's reflection together reflect as
  // gltf_pbr alone, and the gltf_pbr diffuse lobe is scaled by 1 - w, as the extension's mix of
  // diffuse and transmission does. w = 1 without a transmission texture: the dielectric alone. The
  // dielectric refracts when KHR_materials_volume gives the mesh a thickness (thicknessFactor > 0);
  // otherwise the surface is thin-walled, as the extension defines, and light passes straight
  // through. Smooth (roughnessFactor 0): `dielectric` or `thin_dielectric` of index ior (clamped to
  // the model's [0.1, 10]). Rough (roughnessFactor r > 0): `rough_dielectric` or
  // `rough_thin_dielectric`, alpha = r^2 (clamped to the model's [0.001, 1]) and eta = ior (clamped
  // to its [1.01, 4], named in a warning when clamped); the microfacet roughness blurs reflection
  // and transmission alike, alone or as the combination's transmitting component
  // (material_table.cpp, shade_body.glsl).
  void transmissiveMaterial(Material& m, const std::string& context) {
    const float w = m.transmissionFactor * (1.0f - m.metallicFactor);
    if (!(w > 0.0f)) return;
    const bool thin = !m.hasVolume || !(m.thicknessFactor > 0.0f);
    // Beer-Lambert inside the refracting volume (shaders/shared/volume.h).
    if (!thin) m.absorption = shared::volumeAbsorption(m.attenuationColor, m.attenuationDistance);
    // A transmission texture varies w over the surface: the combination even where w = 1.
    const bool textured = m.transmissionTexture.present();
    const float r = m.roughnessFactor;
    // The extension's tint: the base colour (baseColorFactor, times its texture at the hit:
    // shade_body.glsl) colours the transmitted light at every crossing of the surface.
    const ParamValue tint = arrayValue({ParamValue::num(m.baseColorFactor[0]), ParamValue::num(m.baseColorFactor[1]),
                                        ParamValue::num(m.baseColorFactor[2])});
    std::uint32_t glassModel = 0;
    BrdfParams glass;
    if (r > 0.0f) {
      const ModelSpec& rough = *findModel(thin ? "rough_thin_dielectric" : "rough_dielectric");
      const float eta = std::clamp(m.ior, 1.01f, 4.0f);
      if (eta != m.ior)
        warnOnce("KHR_materials_ior " + fmt(m.ior) + " of a rough transmitting material is rendered as " + fmt(eta) +
                 " (" + rough.name + "'s eta is in [1.01, 4])");
      glassModel = rough.id;
      glass = packParams(rough, {{"alpha", ParamValue::num(std::clamp(r * r, 0.001f, 1.0f))},
                                 {"eta", ParamValue::num(eta)}, {"tint", tint}},
                         context + " (rough transmission)");
    } else {
      const ModelSpec& smooth = *findModel(thin ? "thin_dielectric" : "dielectric");
      glassModel = smooth.id;
      glass = packParams(smooth, {{"eta", ParamValue::num(std::min(m.ior, 10.0f))}, {"tint", tint}},
                         context + " (transmission)");
    }
    if (w >= 1.0f && !textured) {
      m.model = glassModel;
      m.params = glass;
      return;
    }
    MaterialComponent base;
    base.model = MODEL_GLTF_PBR;
    base.weight = std::max(0.0f, 1.0f - w);
    base.params = m.params;
    MaterialComponent clear;
    clear.model = glassModel;
    clear.weight = w;
    clear.params = glass;
    m.components = {base, clear};
    m.transmissionTextured = textured;
  }

  // The textures the renderer does not apply yet (src/render/texture_table.h applies baseColor and
  // metallicRoughness of gltf_pbr materials, every emissive and normal texture, and the
  // transmission texture of the transmission combination).
  void warnUnrenderedTextures(const Material& m) {
    if (m.transmissionTexture.present() && !m.transmissionTextured) notRenderedYet("transmissionTexture");
    if ((m.baseColorTexture.present() && !m.hasGltfPbr() && !m.hasTintedTransmission()) ||
        (m.metallicRoughnessTexture.present() && !m.hasGltfPbr()))
      notRenderedYet("baseColorTexture/metallicRoughnessTexture RGB of materials without a gltf_pbr (or, for the "
                     "base colour, transmitting) model or component (NUSSELT_brdf models)");
  }

  std::uint32_t defaultMaterial() {
    if (defaultMaterial_ < 0) {
      Material m;
      m.name = "default";
      m.model = MODEL_LAMBERT;
      ParamValue rho = ParamValue::num(0.8);
      m.params = packParams(*findModel("lambert"), {{"rho", rho}}, "default material");
      defaultMaterial_ = int(scene_.materials.size());
      scene_.materials.push_back(m);
    }
    return std::uint32_t(defaultMaterial_);
  }

  // ---- node hierarchy ----

  glm::dmat4 localTransform(int index) const {
    const tinygltf::Node& n = model_.nodes[std::size_t(index)];
    const std::string field = at("nodes", index);
    if (!n.matrix.empty()) {
      if (n.matrix.size() != 16 || !allFinite(n.matrix)) fail(field + ".matrix: expected 16 finite numbers");
      glm::dmat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[std::size_t(4 * c + r)];  // column-major, as glm
      return m;
    }
    glm::dmat4 m(1.0);
    if (!n.translation.empty()) {
      if (n.translation.size() != 3 || !allFinite(n.translation))
        fail(field + ".translation: expected 3 finite numbers");
      m[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
    }
    if (!n.rotation.empty()) {
      if (n.rotation.size() != 4 || !allFinite(n.rotation)) fail(field + ".rotation: expected 4 finite numbers");
      glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);  // glTF: x, y, z, w
      double len = glm::length(q);
      if (!(len > 1e-12) || !std::isfinite(len)) fail(field + ".rotation: the quaternion has zero length");
      m = m * glm::mat4_cast(q / len);
    }
    if (!n.scale.empty()) {
      if (n.scale.size() != 3 || !allFinite(n.scale)) fail(field + ".scale: expected 3 finite numbers");
      m = m * glm::dmat4(glm::dvec4(n.scale[0], 0, 0, 0), glm::dvec4(0, n.scale[1], 0, 0),
                         glm::dvec4(0, 0, n.scale[2], 0), glm::dvec4(0, 0, 0, 1));
    }
    return m;
  }

  void traverse() {
    const std::size_t nodeCount = model_.nodes.size();
    // glTF requires disjoint strict trees: at most one parent per node. With that checked, a
    // node reached twice in the walk below can only mean a cycle.
    std::vector<int> parent(nodeCount, -1);
    for (std::size_t i = 0; i < nodeCount; ++i) {
      for (int child : model_.nodes[i].children) {
        checkIndex(child, nodeCount, at("nodes", std::int64_t(i)) + ".children", "nodes");
        if (parent[std::size_t(child)] >= 0 || std::size_t(child) == i)
          fail(at("nodes", child) + " has more than one parent (nodes[" + str(parent[std::size_t(child)] < 0 ? int(i) : parent[std::size_t(child)]) +
               "] and nodes[" + str(std::int64_t(i)) + "]); the node hierarchy must be a tree");
        parent[std::size_t(child)] = int(i);
      }
    }
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      checkIndex(s, model_.scenes.size(), "scene", "scenes");
      const std::string field = at("scenes", s) + ".nodes";
      for (int r : model_.scenes[std::size_t(s)].nodes) {
        checkIndex(r, nodeCount, field, "nodes");
        roots.push_back(r);
      }
    } else {
      for (std::size_t i = 0; i < nodeCount; ++i)
        if (parent[i] < 0) roots.push_back(int(i));
    }

    std::vector<char> visited(nodeCount, 0);
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
      auto [index, parentWorld] = stack.back();
      stack.pop_back();
      if (visited[std::size_t(index)])
        fail(at("nodes", index) + " is reached twice: the node hierarchy has a cycle or a scene lists a node twice");
      visited[std::size_t(index)] = 1;
      glm::dmat4 world = parentWorld * localTransform(index);
      visitNode(index, world);
      const std::vector<int>& children = model_.nodes[std::size_t(index)].children;
      for (auto c = children.rbegin(); c != children.rend(); ++c) stack.emplace_back(*c, world);
    }
    checkDeclared();
  }

  void visitNode(int index, const glm::dmat4& world) {
    const tinygltf::Node& n = model_.nodes[std::size_t(index)];
    const std::string field = at("nodes", index);
    if (n.skin >= 0) warnOnce("skins are not supported; skinned meshes are drawn in their bind pose");
    if (!n.weights.empty()) warnOnce("morph targets are not supported; base geometry is used");
    for (const auto& [ext, value] : n.extensions) {
      seenExtensions_.insert(ext);
      if (!isSupportedExtension(ext)) warnOnce("extension " + ext + " is not supported; ignored");
    }
    if (n.mesh >= 0 || n.mesh < -1) {
      checkIndex(n.mesh, model_.meshes.size(), field + ".mesh", "meshes");
      const tinygltf::Mesh& mesh = model_.meshes[std::size_t(n.mesh)];
      for (std::size_t p = 0; p < mesh.primitives.size(); ++p) addPrimitive(n.mesh, int(p), world);
    }
    if (n.camera >= 0 || n.camera < -1) {
      checkIndex(n.camera, model_.cameras.size(), field + ".camera", "cameras");
      cameras_.push_back({n.camera, index, world});
    }
    auto light = n.extensions.find("KHR_lights_punctual");
    if (light != n.extensions.end()) addLight(index, light->second, world);
  }

  // ---- accessors ----

  // Type, componentType and normalized of accessor `a` against what its role accepts; the
  // quantized formats only with KHR_mesh_quantization declared.
  AccessorData accessorFormat(const tinygltf::Accessor& a, const std::string& where, std::initializer_list<int> types,
                              const std::vector<AttributeFormat>& formats) const {
    if (std::find(types.begin(), types.end(), a.type) == types.end()) {
      std::string expected;
      for (int t : types) expected += (expected.empty() ? "" : " or ") + std::string(typeName(t));
      fail(where + ": type " + typeName(a.type) + ", expected " + expected);
    }
    const AttributeFormat* match = nullptr;
    bool typeKnown = false;
    for (const AttributeFormat& f : formats) {
      if (f.componentType != a.componentType) continue;
      typeKnown = true;
      if (f.normalized == 2 || (f.normalized == 1) == a.normalized) {
        if (!match || match->quantized) match = &f;
      }
    }
    if (!typeKnown) {
      std::string expected;
      for (const AttributeFormat& f : formats)
        if (expected.find(componentTypeName(f.componentType)) == std::string::npos)
          expected += (expected.empty() ? "" : " or ") + std::string(componentTypeName(f.componentType));
      fail(where + ": componentType " + componentTypeName(a.componentType) + ", expected " + expected);
    }
    if (!match)
      fail(where + ": normalized is " + (a.normalized ? "true" : "false") + ", which is invalid for componentType " +
           componentTypeName(a.componentType) + " here");
    if (match->quantized && !declared("KHR_mesh_quantization"))
      fail(where + ": componentType " + componentTypeName(a.componentType) + (a.normalized ? " normalized" : "") +
           " needs the KHR_mesh_quantization extension (declare it in extensionsUsed and extensionsRequired)");
    AccessorData d;
    d.componentType = a.componentType;
    d.components = tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
    d.normalized = a.normalized;
    d.count = a.count;
    return d;
  }

  AccessorData checkAccessor(int index, const std::string& role, std::initializer_list<int> types,
                             const std::vector<AttributeFormat>& formats) {
    checkIndex(index, model_.accessors.size(), role, "accessors");
    const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
    const std::string where = at("accessors", index) + " (" + role + ")";
    if (a.sparse.isSparse) fail(where + ": sparse accessors are not supported");
    AccessorData d = accessorFormat(a, where, types, formats);
    if (a.count == 0) return d;
    if (a.bufferView < 0) fail(where + ": no bufferView (an all-zero accessor); not supported");
    const Bytes view = viewBytes(a.bufferView, where);
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(a.bufferView)];
    const std::string bvField = at("bufferViews", a.bufferView);
    const std::uint64_t elementSize =
        std::uint64_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType))) * std::uint64_t(d.components);
    if (bv.byteStride != 0 && bv.byteStride < elementSize)
      fail(where + ": " + bvField + ".byteStride " + str(std::uint64_t(bv.byteStride)) +
           " is smaller than the element size " + str(elementSize));
    d.stride = bv.byteStride != 0 ? bv.byteStride : elementSize;
    std::uint64_t span = 0, end = 0;
    if (!mulChecked(d.stride, a.count - 1, &span) || !addChecked(span, elementSize, &span) ||
        !addChecked(span, a.byteOffset, &end) || end > view.size)
      fail(where + ": byteOffset " + str(std::uint64_t(a.byteOffset)) + " + count " + str(std::uint64_t(a.count)) +
           " x stride " + str(d.stride) + " exceeds " + bvField + " (byteLength " + str(view.size) + ")");
    d.base = view.data + a.byteOffset;
    return d;
  }

  // The Draco mesh of a primitive, decoded once however often the mesh is instanced.
  const DracoMesh& dracoMesh(int meshIndex, int primIndex, const tinygltf::Value& ext, const std::string& field) {
    auto cached = draco_.find({meshIndex, primIndex});
    if (cached != draco_.end()) return cached->second;
    if (!ext.IsObject() || !ext.Has("bufferView") || !ext.Get("bufferView").IsInt())
      fail(field + ": expected {\"bufferView\": <index>, \"attributes\": {...}}");
    if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) fail(field + ".attributes: must be an object");
    const Bytes bytes = viewBytes(ext.Get("bufferView").Get<int>(), field);
    DracoMesh mesh;
    try {
      mesh = DracoMesh::decode(bytes.data, std::size_t(bytes.size));
    } catch (const Error& e) {
      fail(field + ": " + e.what());
    }
    if (!addChecked(decodedBytes_, 4 * std::uint64_t(mesh.indices().size()), &decodedBytes_) ||
        decodedBytes_ > kMaxFileBytes)
      fail(field + ": the decoded geometry adds up to more than the 1 GiB limit");
    return draco_.emplace(std::make_pair(meshIndex, primIndex), std::move(mesh)).first->second;
  }

  // Accessor `index` whose data is Draco attribute `id`: the accessor gives type, componentType
  // and count (= the decoded point count), Draco the values; `storage` keeps them alive.
  AccessorData dracoAccessor(int index, const std::string& role, std::initializer_list<int> types,
                             const std::vector<AttributeFormat>& formats, const DracoMesh& mesh, const tinygltf::Value& id,
                             const std::string& field, std::vector<std::vector<std::uint8_t>>* storage) {
    checkIndex(index, model_.accessors.size(), role, "accessors");
    const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
    const std::string where = at("accessors", index) + " (" + role + ")";
    if (a.sparse.isSparse) fail(where + ": sparse accessors are not supported");
    AccessorData d = accessorFormat(a, where, types, formats);
    if (!id.IsInt() || id.Get<int>() < 0) fail(field + ": must be a non-negative integer (a Draco attribute id)");
    if (a.count != mesh.pointCount())
      fail(where + ": count " + str(std::uint64_t(a.count)) + " differs from the " + str(std::uint64_t(mesh.pointCount())) +
           " points the Draco data decodes to");
    std::vector<std::uint8_t> values;
    try {
      values = mesh.attribute(std::uint32_t(id.Get<int>()), a.componentType, d.components);
    } catch (const Error& e) {
      fail(field + ": " + e.what());
    }
    if (!addChecked(decodedBytes_, values.size(), &decodedBytes_) || decodedBytes_ > kMaxFileBytes)
      fail(field + ": the decoded geometry adds up to more than the 1 GiB limit");
    d.stride = std::uint64_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType))) * std::uint64_t(d.components);
    storage->push_back(std::move(values));
    d.base = storage->back().data();
    return d;
  }

  // Component c of element i, as glTF defines it: floats as they are, normalized integers
  // mapped to [0, 1] (unsigned) or [-1, 1] (signed, max(v / (2^(n-1) - 1), -1)), other integers
  // as their value (KHR_mesh_quantization).
  static double component(const AccessorData& d, std::uint64_t i, int c) {
    const unsigned char* p = d.base + i * d.stride;
    switch (d.componentType) {
      case kFloat: {
        float v;
        std::memcpy(&v, p + 4 * c, 4);  // memcpy: buffers need not be aligned
        return v;
      }
      case kByte: {
        const double v = static_cast<std::int8_t>(p[c]);
        return d.normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case kUByte: return d.normalized ? p[c] / 255.0 : p[c];
      case kShort: {
        std::int16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return d.normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case kUShort: {
        std::uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return d.normalized ? v / 65535.0 : v;
      }
      default: {
        std::uint32_t v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
    }
  }

  static glm::dvec2 readVec2(const AccessorData& d, std::uint64_t i) { return {component(d, i, 0), component(d, i, 1)}; }
  static glm::dvec3 readVec3(const AccessorData& d, std::uint64_t i) {
    return {component(d, i, 0), component(d, i, 1), component(d, i, 2)};
  }
  static glm::dvec4 readVec4(const AccessorData& d, std::uint64_t i) {
    return {component(d, i, 0), component(d, i, 1), component(d, i, 2), component(d, i, 3)};
  }

  static std::uint32_t readIndex(const AccessorData& d, std::uint64_t i) {
    const unsigned char* p = d.base + i * d.stride;
    switch (d.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        std::uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      default: {
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
    }
  }

  // ---- primitives ----

  void addPrimitive(int meshIndex, int primIndex, const glm::dmat4& world) {
    const tinygltf::Primitive& prim = model_.meshes[std::size_t(meshIndex)].primitives[std::size_t(primIndex)];
    const std::string pname = at("meshes", meshIndex) + "." + at("primitives", primIndex);
    if (!prim.targets.empty()) warnOnce("morph targets are not supported; base geometry is used");
    const tinygltf::Value* dracoExt = nullptr;
    for (const auto& [ext, value] : prim.extensions) {
      if (ext == "KHR_draco_mesh_compression") {
        seenExtensions_.insert(ext);
        dracoExt = &value;
      } else {
        warnOnce("extension " + ext + " is not supported; ignored");
      }
    }
    const int mode = prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      if (mode >= 0 && mode <= 3)
        warnOnce(std::string("primitives with mode ") + modeName(mode) + " are not supported; skipped");
      else
        warnOnce(pname + ".mode: " + str(mode) + " is not a valid primitive mode; skipped");
      return;
    }
    if (prim.attributes.find("POSITION") == prim.attributes.end()) {
      warnOnce(pname + " has no POSITION attribute; skipped");
      return;
    }
    const std::string dracoField = pname + ".extensions.KHR_draco_mesh_compression";
    const DracoMesh* draco = nullptr;
    if (dracoExt) {
      if (mode != TINYGLTF_MODE_TRIANGLES) fail(dracoField + ": Draco primitives must have mode 4 (TRIANGLES)");
      draco = &dracoMesh(meshIndex, primIndex, *dracoExt, dracoField);
    }
    std::vector<std::vector<std::uint8_t>> storage;  // Draco-decoded accessor data
    // Attribute `semantic`, if the primitive has it: from the Draco data when the extension
    // lists it, from its accessor otherwise.
    auto attribute = [&](const char* semantic, std::initializer_list<int> types,
                         const std::vector<AttributeFormat>& formats, AccessorData* out) {
      auto it = prim.attributes.find(semantic);
      if (it == prim.attributes.end()) return false;
      const std::string role = std::string(semantic) + " of " + pname;
      if (draco && dracoExt->Get("attributes").Has(semantic))
        *out = dracoAccessor(it->second, role, types, formats, *draco, dracoExt->Get("attributes").Get(semantic),
                             dracoField + ".attributes." + semantic, &storage);
      else
        *out = checkAccessor(it->second, role, types, formats);
      return true;
    };
    auto sameCount = [&](const char* semantic, const AccessorData& d, std::uint64_t expected) {
      if (d.count != expected)
        fail(at("accessors", prim.attributes.at(semantic)) + " (" + semantic + " of " + pname + "): count " +
             str(d.count) + " differs from the POSITION count " + str(expected));
    };
    AccessorData pos, nrm, tan, uv[2];
    attribute("POSITION", {TINYGLTF_TYPE_VEC3}, kPositionFormats, &pos);
    const bool hasNormals = attribute("NORMAL", {TINYGLTF_TYPE_VEC3}, kNormalFormats, &nrm);
    if (hasNormals) sameCount("NORMAL", nrm, pos.count);
    const bool hasTangents = attribute("TANGENT", {TINYGLTF_TYPE_VEC4}, kNormalFormats, &tan);
    if (hasTangents) sameCount("TANGENT", tan, pos.count);
    bool hasUv[2];
    for (int s = 0; s < 2; ++s) {
      const char* semantic = s == 0 ? "TEXCOORD_0" : "TEXCOORD_1";
      hasUv[s] = attribute(semantic, {TINYGLTF_TYPE_VEC2}, kTexcoordFormats, &uv[s]);
      if (hasUv[s]) sameCount(semantic, uv[s], pos.count);
    }
    AccessorData idx;
    const bool indexed = draco || prim.indices >= 0 || prim.indices < -1;
    std::uint64_t cornerCount = pos.count;
    if (draco) {
      // The indices are the Draco faces; an indices accessor, if given, must agree in count.
      auto given = dracoIndices_.find({meshIndex, primIndex});
      if (given != dracoIndices_.end()) {
        const int ia = given->second;
        checkIndex(ia, model_.accessors.size(), "indices of " + pname, "accessors");
        const tinygltf::Accessor& a = model_.accessors[std::size_t(ia)];
        accessorFormat(a, at("accessors", ia) + " (indices of " + pname + ")", {TINYGLTF_TYPE_SCALAR}, kIndexFormats);
        if (a.count != draco->indices().size())
          fail(at("accessors", ia) + " (indices of " + pname + "): count " + str(std::uint64_t(a.count)) +
               " differs from the " + str(std::uint64_t(draco->indices().size())) + " indices of the Draco data");
      }
      idx.base = reinterpret_cast<const unsigned char*>(draco->indices().data());
      idx.stride = 4;
      idx.count = draco->indices().size();
      idx.componentType = kUInt;
      idx.components = 1;
    } else if (indexed) {
      idx = checkAccessor(prim.indices, "indices of " + pname, {TINYGLTF_TYPE_SCALAR}, kIndexFormats);
    }
    if (indexed) {
      cornerCount = idx.count;
      for (std::uint64_t i = 0; i < idx.count; ++i) {
        std::uint32_t v = readIndex(idx, i);
        if (v >= pos.count)
          fail((draco ? dracoField : at("accessors", prim.indices) + " (indices of " + pname + ")") + ": index " +
               str(std::uint64_t(v)) + " (element " + str(i) + ") is out of range for " + str(pos.count) + " vertices");
      }
    }
    std::uint32_t material;
    if (prim.material == -1) {
      material = defaultMaterial();
    } else {
      checkIndex(prim.material, model_.materials.size(), pname + ".material", "materials");
      material = std::uint32_t(prim.material);
    }

    std::uint64_t triangles = 0;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (cornerCount % 3 != 0)
        warnOnce(pname + ": " + str(cornerCount) + " vertices is not a multiple of 3; the remainder is ignored");
      triangles = cornerCount / 3;
    } else {
      triangles = cornerCount >= 3 ? cornerCount - 2 : 0;
    }
    if (scene_.triangleCount() + scene_.droppedTriangles + triangles > kMaxTriangles)
      fail(pname + ": the scene exceeds " + str(kMaxTriangles) + " triangles");
    auto corner = [&](std::uint64_t k) -> std::uint64_t { return indexed ? readIndex(idx, k) : k; };

    const glm::dmat3 linear(world);
    const double det = glm::determinant(linear);
    const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
    // A mirroring transform reverses the winding; swapping two corners keeps the geometric
    // normal on the same side as the (inverse-transpose transformed) shading normal.
    const bool flip = det < 0;

    const std::size_t firstCorner = scene_.positions.size();
    std::vector<std::uint32_t> cornerVertex;  // the primitive's vertex of each corner kept
    cornerVertex.reserve(3 * triangles);
    scene_.positions.reserve(scene_.positions.size() + 3 * triangles);
    scene_.normals.reserve(scene_.normals.size() + 3 * triangles);
    scene_.triangleMaterial.reserve(scene_.triangleMaterial.size() + triangles);
    for (std::uint64_t t = 0; t < triangles; ++t) {
      std::uint64_t c[3];
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        c[0] = corner(3 * t), c[1] = corner(3 * t + 1), c[2] = corner(3 * t + 2);
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // glTF 2.0 3.7.2.1: odd triangles swap their first two corners to keep the winding.
        if (t % 2 == 0) c[0] = corner(t), c[1] = corner(t + 1), c[2] = corner(t + 2);
        else c[0] = corner(t + 1), c[1] = corner(t), c[2] = corner(t + 2);
      } else {
        c[0] = corner(t + 1), c[1] = corner(t + 2), c[2] = corner(0);
      }
      if (flip) std::swap(c[1], c[2]);
      glm::vec3 p[3];
      bool finite = true;
      for (int k = 0; k < 3; ++k) {
        glm::dvec3 q = glm::dvec3(world * glm::dvec4(readVec3(pos, c[k]), 1.0));
        finite = finite && std::abs(q.x) <= kMaxCoordinate && std::abs(q.y) <= kMaxCoordinate &&
                 std::abs(q.z) <= kMaxCoordinate;  // false for NaN too
        p[k] = finite ? glm::vec3(q) : glm::vec3(0.0f);
      }
      // In float, as the renderer computes it: a zero cross product has no geometric normal.
      glm::vec3 g = glm::cross(p[1] - p[0], p[2] - p[0]);
      float g2 = glm::dot(g, g);
      if (!finite || !std::isfinite(g2) || !(g2 > 0.0f)) {
        ++scene_.droppedTriangles;
        continue;
      }
      glm::vec3 gn = glm::vec3(glm::normalize(glm::dvec3(g)));
      for (int k = 0; k < 3; ++k) {
        glm::vec3 n = gn;
        if (hasNormals) {
          glm::dvec3 m = normalMatrix * readVec3(nrm, c[k]);
          double len = glm::length(m);
          if (std::isfinite(len) && len > 0) n = glm::vec3(m / len);
        }
        scene_.positions.push_back(p[k]);
        scene_.normals.push_back(n);
        cornerVertex.push_back(std::uint32_t(c[k]));
      }
      scene_.triangleMaterial.push_back(material);
    }

    // Texture coordinates, per corner kept.
    for (int s = 0; s < 2; ++s) {
      std::vector<glm::vec2>& out = s == 0 ? scene_.texcoords0 : scene_.texcoords1;
      if (!hasUv[s]) {
        if (!out.empty()) out.resize(scene_.positions.size(), glm::vec2(0.0f));
        continue;
      }
      out.resize(firstCorner, glm::vec2(0.0f));  // the first primitive with the set: earlier corners get 0
      for (std::uint32_t v : cornerVertex) {
        glm::dvec2 w = readVec2(uv[s], v);
        if (!(std::fabs(w.x) <= kMaxTexcoord) || !(std::fabs(w.y) <= kMaxTexcoord)) {
          ++badTexcoords_;
          w = glm::dvec2(0.0);
        }
        out.push_back(glm::vec2(w));
      }
    }

    // Tangents: given, generated for a normal map, or perpendicular to the normal as filler.
    const Material& mat = scene_.materials[material];
    const bool generate = !hasTangents && mat.normalMapped();
    if (!hasTangents && !generate && scene_.tangents.empty()) return;
    for (std::size_t j = scene_.tangents.size(); j < firstCorner; ++j)
      scene_.tangents.push_back(glm::vec4(perpendicularTo(scene_.normals[j]), 1.0f));
    const std::size_t corners = scene_.positions.size() - firstCorner;
    scene_.tangents.resize(firstCorner + corners);
    glm::vec4* out = scene_.tangents.data() + firstCorner;
    const glm::vec3* normals = scene_.normals.data() + firstCorner;
    if (hasTangents) {
      // Tangents are directions on the surface: they transform by the linear part itself; a
      // mirroring transform reverses the handedness (w).
      for (std::size_t j = 0; j < corners; ++j) {
        const glm::dvec4 t = readVec4(tan, cornerVertex[j]);
        const glm::dvec3 d = linear * glm::dvec3(t);
        const glm::dvec3 n(normals[j]);
        const glm::dvec3 o = d - n * glm::dot(n, d);
        const double len = glm::length(o);
        if (!std::isfinite(len) || !(len > 1e-6 * glm::length(d))) ++badTangents_;
        const float w = (t.w < 0 ? -1.0f : 1.0f) * (flip ? -1.0f : 1.0f);
        out[j] = glm::vec4(orthonormalTangent(glm::vec3(d), normals[j]), w);
      }
    } else if (generate) {
      const std::uint32_t set = mat.normalTexture.texCoord;
      if (!hasUv[set]) {
        warnOnce(pname + ": its material's normal map reads TEXCOORD_" + str(std::uint64_t(set)) +
                 ", which the primitive lacks; its tangents are arbitrary");
        for (std::size_t j = 0; j < corners; ++j) out[j] = glm::vec4(perpendicularTo(normals[j]), 1.0f);
      } else {
        const glm::vec2* uvs = (set == 0 ? scene_.texcoords0 : scene_.texcoords1).data() + firstCorner;
        flatUvTangents_ += generateTangents(corners / 3, scene_.positions.data() + firstCorner, normals, uvs,
                                            cornerVertex.data(), std::size_t(pos.count), out);
      }
    } else {
      for (std::size_t j = 0; j < corners; ++j) out[j] = glm::vec4(perpendicularTo(normals[j]), 1.0f);
    }
  }

  // ---- lights ----

  void addLight(int nodeIndex, const tinygltf::Value& ext, const glm::dmat4& world) {
    const std::string field = at("nodes", nodeIndex) + ".extensions.KHR_lights_punctual";
    if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
      fail(field + ": expected {\"light\": <index>}");
    int li = ext.Get("light").Get<int>();
    checkIndex(li, model_.lights.size(), field + ".light", "KHR_lights_punctual lights");
    const tinygltf::Light& gl = model_.lights[std::size_t(li)];
    const std::string lfield = "KHR_lights_punctual.lights[" + str(li) + "]";
    PunctualLight l;
    l.name = gl.name.empty() ? lfield : gl.name;
    if (gl.type == "point") l.type = LightType::Point;
    else if (gl.type == "spot") l.type = LightType::Spot;
    else if (gl.type == "directional") l.type = LightType::Directional;
    else fail(lfield + ".type: " + quoted(gl.type) + " (expected point, spot or directional)");
    glm::dvec3 colour(1.0);
    if (!gl.color.empty()) {
      if (gl.color.size() != 3) fail(lfield + ".color: expected 3 numbers");
      for (int k = 0; k < 3; ++k) {
        double c = gl.color[std::size_t(k)];
        if (!std::isfinite(c) || c < 0) fail(lfield + ".color: " + fmt(c) + " is not a finite number >= 0");
        colour[k] = c;
      }
    }
    if (!std::isfinite(gl.intensity) || gl.intensity < 0)
      fail(lfield + ".intensity: " + fmt(gl.intensity) + " is not a finite number >= 0");
    glm::dvec3 intensity = colour * gl.intensity;
    if (!std::isfinite(intensity.x) || !std::isfinite(intensity.y) || !std::isfinite(intensity.z))
      fail(lfield + ": color x intensity overflows");
    l.intensity = glm::vec3(intensity);
    if (l.type == LightType::Spot) {
      double inner = gl.spot.innerConeAngle, outer = gl.spot.outerConeAngle;
      if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0 || outer <= inner || outer > M_PI / 2 + 1e-9)
        fail(lfield + ".spot: innerConeAngle " + fmt(inner) + " and outerConeAngle " + fmt(outer) +
             " must satisfy 0 <= inner < outer <= pi/2");
      l.innerConeAngle = float(inner);
      l.outerConeAngle = float(outer);
    }
    glm::dvec3 position(world * glm::dvec4(0, 0, 0, 1));
    glm::dvec3 direction = glm::dmat3(world) * glm::dvec3(0, 0, -1);
    double len = glm::length(direction);
    if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z))
      fail(at("nodes", nodeIndex) + ": the light position is not finite");
    if (!(len > 0) || !std::isfinite(len)) {
      if (l.type != LightType::Point) fail(at("nodes", nodeIndex) + ": the light direction is degenerate (zero scale?)");
      direction = glm::dvec3(0, 0, -1);
    } else {
      direction /= len;
    }
    l.position = glm::vec3(position);
    l.direction = glm::vec3(direction);
    scene_.lights.push_back(l);
  }

  // ---- camera ----

  std::string cameraLabel(const CameraInstance& ci) const {
    const tinygltf::Camera& c = model_.cameras[std::size_t(ci.camera)];
    if (!c.name.empty()) return c.name;
    const tinygltf::Node& n = model_.nodes[std::size_t(ci.node)];
    return n.name.empty() ? at("cameras", ci.camera) : n.name;
  }

  void chooseCamera() {
    if (cameras_.empty()) {
      if (!options_.cameraName.empty())
        fail("--camera " + quoted(options_.cameraName) + ": the scene has no camera instanced by a node");
      scene_.hasCamera = false;
      scene_.camera = frameScene(scene_);
      return;
    }
    const CameraInstance* chosen = &cameras_.front();
    if (!options_.cameraName.empty()) {
      chosen = nullptr;
      // The camera's own name first, then the name of the node that instances it.
      for (const CameraInstance& ci : cameras_)
        if (!chosen && model_.cameras[std::size_t(ci.camera)].name == options_.cameraName) chosen = &ci;
      for (const CameraInstance& ci : cameras_)
        if (!chosen && model_.nodes[std::size_t(ci.node)].name == options_.cameraName) chosen = &ci;
      if (!chosen) {
        std::string names;
        for (const CameraInstance& ci : cameras_) names += (names.empty() ? "" : ", ") + quoted(cameraLabel(ci));
        fail("--camera " + quoted(options_.cameraName) + ": no such camera (available: " + names + ")");
      }
    }
    const tinygltf::Camera& gc = model_.cameras[std::size_t(chosen->camera)];
    const std::string field = at("cameras", chosen->camera);
    Camera cam;
    cam.name = cameraLabel(*chosen);
    if (gc.type == "perspective") {
      double yfov = gc.perspective.yfov, aspect = gc.perspective.aspectRatio;
      if (!std::isfinite(yfov) || yfov <= 0 || yfov >= M_PI)
        fail(field + ".perspective.yfov: " + fmt(yfov) + " is not in (0, pi)");
      if (!std::isfinite(aspect) || aspect < 0) fail(field + ".perspective.aspectRatio: " + fmt(aspect) + " is not > 0");
      cam.yfov = float(yfov);
      cam.aspectRatio = float(aspect);
    } else if (gc.type == "orthographic") {
      double xmag = gc.orthographic.xmag, ymag = gc.orthographic.ymag;
      if (!std::isfinite(xmag) || xmag == 0) fail(field + ".orthographic.xmag: " + fmt(xmag) + " must be finite and non-zero");
      if (!std::isfinite(ymag) || ymag == 0) fail(field + ".orthographic.ymag: " + fmt(ymag) + " must be finite and non-zero");
      cam.orthographic = true;
      cam.xmag = float(std::fabs(xmag));
      cam.ymag = float(std::fabs(ymag));
    } else {
      fail(field + ".type: " + quoted(gc.type) + " (expected perspective or orthographic)");
    }
    // glTF cameras look down -z with +y up; scale and shear are removed by Gram-Schmidt.
    const glm::dmat4& w = chosen->world;
    glm::dvec3 position(w * glm::dvec4(0, 0, 0, 1));
    glm::dvec3 forward = glm::dmat3(w) * glm::dvec3(0, 0, -1);
    glm::dvec3 up = glm::dmat3(w) * glm::dvec3(0, 1, 0);
    double fl = glm::length(forward);
    if (!(fl > 0) || !std::isfinite(fl) || !std::isfinite(position.x + position.y + position.z))
      fail(at("nodes", chosen->node) + ": the camera transform is degenerate");
    forward /= fl;
    up -= glm::dot(up, forward) * forward;
    double ul = glm::length(up);
    if (!(ul > 1e-12 * fl) || !std::isfinite(ul)) fail(at("nodes", chosen->node) + ": the camera transform is degenerate");
    up /= ul;
    cam.position = glm::vec3(position);
    cam.forward = glm::vec3(forward);
    cam.up = glm::vec3(up);
    scene_.camera = cam;
    scene_.hasCamera = true;
  }
};

// ---------------------------------------------------------------------------------------------

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n') c = ';';
  if (s.size() > 500) s = s.substr(0, 500) + "...";
  return s;
}

Scene loadImpl(const unsigned char* bytes, std::uint64_t size, const std::string& name, const Sandbox& box,
               const LoadOptions& options) {
  if (size > kMaxFileBytes) throw Error(name + ": larger than the 1 GiB limit");
  const bool binary = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
  GlbParts glb;
  if (binary) {
    glb = splitGlb(bytes, size, name);
  } else {
    // Not GLB: it must be JSON, i.e. start with '{' (or '[', refused below as not an object)
    // after white space and a UTF-8 byte order mark, which nlohmann skips. Anything else is named
    // by its first bytes, escaped, instead of reaching the JSON parser.
    std::size_t first = 0;
    if (size >= 3 && std::memcmp(bytes, "\xEF\xBB\xBF", 3) == 0) first = 3;
    while (first < size && (bytes[first] == ' ' || bytes[first] == '\t' || bytes[first] == '\r' || bytes[first] == '\n'))
      ++first;
    if (first == size) throw Error(name + ": empty file (expected glTF JSON or GLB)");
    auto endsWith = [&](const char* suffix) {
      std::size_t n = std::strlen(suffix);
      if (name.size() < n) return false;
      for (std::size_t i = 0; i < n; ++i)
        if (std::tolower(static_cast<unsigned char>(name[name.size() - n + i])) != suffix[i]) return false;
      return true;
    };
    if (endsWith(".glb"))
      throw Error(name + ": not a GLB file: it " + describeSignature(bytes, std::size_t(std::min<std::uint64_t>(size, 8))) +
                  ", a GLB starts with the magic \"glTF\"");
    if (bytes[first] != '{' && bytes[first] != '[')
      throw Error(name + ": neither glTF JSON (an object, starting with '{') nor GLB (magic \"glTF\"): the file " +
                  describeSignature(bytes + first, std::size_t(std::min<std::uint64_t>(size - first, 8))));
    glb.json.assign(reinterpret_cast<const char*>(bytes), static_cast<std::size_t>(size));
  }
  if (glb.json.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error(name + ": empty file (expected glTF JSON or GLB)");
  if (jsonDepth(glb.json) > kMaxJsonDepth)
    throw Error(name + ": JSON is nested deeper than " + str(kMaxJsonDepth) + " levels");
  Json root;
  try {
    root = Json::parse(glb.json);
  } catch (const Json::exception& e) {
    throw Error(name + ": malformed JSON: " + printable(e.what()));
  }
  if (!root.is_object()) throw Error(name + ": the JSON top level is not an object");

  checkUnsignedFields(root, "buffers", {"byteLength"}, name);
  checkUnsignedFields(root, "bufferViews", {"byteOffset", "byteLength", "byteStride"}, name);
  checkUnsignedFields(root, "accessors", {"byteOffset", "count"}, name);
  checkIntegers(root, "", false, name);
  std::set<int> placeholders;
  checkBuffers(root, box, name, binary, glb.hasBin ? glb.binSize : 0, &placeholders);
  const std::vector<ImageSource> images = parseImages(root, name);
  root.erase("images");
  const DracoIndices dracoIndices = takeDracoIndices(root, name);
  const std::string json = root.dump();

  tinygltf::TinyGLTF loader;
  Sandbox sandbox = box;
  loader.SetFsCallbacks({&fsFileExists, &fsExpandFilePath, &fsReadWholeFile, &fsWriteWholeFile, &sandbox});
  loader.SetImageLoader(&ignoreImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  bool ok;
  if (binary) {
    // Re-assemble a GLB around the vetted JSON; the BIN chunk is padded to 4 bytes as tinygltf wants.
    std::uint64_t jsonPadded = (json.size() + 3) & ~std::uint64_t(3);
    std::uint64_t binPadded = (glb.binSize + 3) & ~std::uint64_t(3);
    std::uint64_t total = 12 + 8 + jsonPadded + (glb.hasBin ? 8 + binPadded : 0);
    if (total > kMaxFileBytes + 64) throw Error(name + ": larger than the 1 GiB limit");
    std::vector<unsigned char> out;
    out.reserve(static_cast<std::size_t>(total));
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    putU32(out, 2);
    putU32(out, std::uint32_t(total));
    putU32(out, std::uint32_t(jsonPadded));
    putU32(out, 0x4E4F534Au);
    out.insert(out.end(), json.begin(), json.end());
    out.resize(out.size() + (jsonPadded - json.size()), ' ');
    if (glb.hasBin) {
      putU32(out, std::uint32_t(binPadded));
      putU32(out, 0x004E4942u);
      out.insert(out.end(), glb.bin, glb.bin + glb.binSize);
      out.resize(out.size() + (binPadded - glb.binSize), 0);
    }
    ok = loader.LoadBinaryFromMemory(&model, &err, &warn, out.data(), unsigned(out.size()), box.root);
  } else {
    ok = loader.LoadASCIIFromString(&model, &err, &warn, json.c_str(), unsigned(json.size()), box.root);
  }
  if (!ok)
    throw Error(name + ": invalid glTF: " + printable(trimmed(err.empty() ? "tinygltf failed without a message" : err)));

  Scene scene;
  scene.sourcePath = name;
  std::istringstream warnings(warn);
  for (std::string line; std::getline(warnings, line);)
    if (!line.empty()) scene.warnings.push_back(name + ": " + line);
  Converter(model, name, options, box, images, placeholders, dracoIndices, scene).run();
  for (std::string& w : scene.warnings) w = printable(w);
  return scene;
}

// nusselt::Error is the only exception callers handle; library exceptions that escape the
// checks above (a JSON type error, an allocation failure) still name the file.
template <typename F>
Scene guarded(const std::string& name, F&& load) {
  try {
    return load();
  } catch (const Error& e) {
    throw Error(printable(e.what()));
  } catch (const Json::exception& e) {
    throw Error(printable(name + ": invalid glTF: " + e.what()));
  } catch (const std::bad_alloc&) {
    throw Error(name + ": out of memory while loading");
  } catch (const std::length_error& e) {
    throw Error(name + ": out of memory while loading (" + e.what() + ")");
  }
}

}  // namespace

Scene loadScene(const std::string& path, const LoadOptions& options) {
  std::vector<unsigned char> bytes;
  std::string why;
  if (!readRegularFile(path, &bytes, &why)) throw Error(path + ": cannot read: " + why);
  // The sandbox is the canonical directory of the scene file; external buffers must resolve
  // inside it.
  std::string dir = path;
  std::size_t slash = dir.find_last_of('/');
  dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : dir.substr(0, slash));
  char* real = realpath(dir.c_str(), nullptr);
  if (!real) throw Error(path + ": cannot resolve its directory: " + std::strerror(errno));
  Sandbox box{real};
  std::free(real);
  return guarded(path, [&] { return loadImpl(bytes.data(), bytes.size(), path, box, options); });
}

Scene loadSceneFromMemory(const unsigned char* bytes, std::size_t size, const std::string& displayName,
                          const LoadOptions& options) {
  if (!bytes && size) throw Error(displayName + ": no data");
  static const unsigned char empty = 0;
  return guarded(displayName, [&] { return loadImpl(bytes ? bytes : &empty, size, displayName, Sandbox{}, options); });
}

}  // namespace nusselt
