// test_gltf_loader.cpp: the glTF loader on good, odd and hostile inputs. Errors are checked by
// message content: the file name and the offending field must be named.
#include "scene/gltf_loader.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "util/error.h"

namespace nusselt {
namespace {

using Json = nlohmann::json;

const std::string kData = std::string(NUSSELT_TEST_DATA) + "/gltf/";
const std::string kSource = NUSSELT_SOURCE_DIR;

// The message of the nusselt::Error thrown by f, or "" (a test failure) when none is thrown.
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a nusselt::Error: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

std::string fileError(const std::string& file, const LoadOptions& options = {}) {
  return errorOf([&] { loadScene(kData + file, options); });
}

#define EXPECT_HAS(haystack, needle) EXPECT_NE((haystack).find(needle), std::string::npos) << (haystack)

std::string base64(const std::vector<unsigned char>& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    std::uint32_t v = std::uint32_t(in[i]) << 16;
    if (i + 1 < in.size()) v |= std::uint32_t(in[i + 1]) << 8;
    if (i + 2 < in.size()) v |= in[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? t[v & 63] : '=';
  }
  return out;
}

std::vector<unsigned char> floats(const std::vector<float>& v) {
  std::vector<unsigned char> out(v.size() * 4);
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

// One triangle in the xy plane, front face +z, as a glTF document to modify per test.
Json triangleModel() {
  Json j = Json::parse(R"({
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"byteLength": 36}]})");
  j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(floats({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  return j;
}

Scene loadJson(const Json& j, const LoadOptions& options = {}) {
  std::string text = j.dump();
  return loadSceneFromMemory(reinterpret_cast<const unsigned char*>(text.data()), text.size(), "mem.gltf", options);
}

std::string jsonError(const Json& j) {
  return errorOf([&] { loadJson(j); });
}

bool hasWarning(const Scene& s, const std::string& needle) {
  for (const std::string& w : s.warnings)
    if (w.find(needle) != std::string::npos) return true;
  return false;
}

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

// Scratch directory for tests that need symlinks or files outside the checked-in data.
struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/nusselt_gltf_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path + "/" + name) << text; }
};

// ---------------------------------------------------------------------------------------------
// Good scenes.

TEST(GltfLoader, CornellBox) {
  Scene s = loadScene(kSource + "/scenes/cornell-box.glb");
  EXPECT_EQ(s.triangleCount(), 32u);
  EXPECT_EQ(s.positions.size(), 96u);
  EXPECT_EQ(s.normals.size(), 96u);
  EXPECT_EQ(s.droppedTriangles, 0u);
  EXPECT_TRUE(s.hasCamera);
  EXPECT_EQ(s.camera.name, "cornell_camera");
  EXPECT_NEAR(s.camera.yfov, 0.6860478808414068, 1e-6);
  expectNear(s.camera.position, {278, 273, -800}, 1e-3f);
  expectNear(s.camera.forward, {0, 0, 1});  // rotated 180 degrees about y
  expectNear(s.camera.up, {0, 1, 0});
  ASSERT_EQ(s.materials.size(), 4u);
  int emissive = 0;
  for (const Material& m : s.materials) {
    EXPECT_EQ(m.model, MODEL_LAMBERT);
    if (m.emission != glm::vec3(0)) {
      ++emissive;
      EXPECT_EQ(m.name, "light");
      EXPECT_NEAR(m.emission.x, 18.387, 1e-3);
      EXPECT_NEAR(m.emission.y, 18.387 * 0.7607168107902321, 1e-3);
    }
  }
  EXPECT_EQ(emissive, 1);
  // baseColorFactor -> rho
  EXPECT_NEAR(s.materials[1].params.v[0][0], 0.570068, 1e-6);
  for (std::size_t t = 0; t < s.triangleCount(); ++t) {
    glm::vec3 g = glm::cross(s.positions[3 * t + 1] - s.positions[3 * t], s.positions[3 * t + 2] - s.positions[3 * t]);
    EXPECT_GT(glm::dot(g, s.normals[3 * t]), 0.0f) << "triangle " << t;
  }
  EXPECT_TRUE(s.lights.empty());
}

TEST(GltfLoader, CornellBoxFromMemoryAndCameraByName) {
  std::vector<unsigned char> bytes = readBytes(kSource + "/scenes/cornell-box.glb");
  LoadOptions o;
  o.cameraName = "cornell_camera";
  Scene s = loadSceneFromMemory(bytes.data(), bytes.size(), "box.glb", o);
  EXPECT_EQ(s.triangleCount(), 32u);
  EXPECT_TRUE(s.hasCamera);
}

TEST(GltfLoader, IndexTypesAndNonIndexed) {
  Scene s = loadScene(kData + "index_types.gltf");
  ASSERT_EQ(s.triangleCount(), 8u);  // u8, u16, u32 and non-indexed quads
  for (int q = 0; q < 4; ++q) {
    expectNear(s.positions[6 * q], {2.0f * q, 0, 0});
    expectNear(s.positions[6 * q + 2], {2.0f * q + 1, 1, 0});
    expectNear(s.normals[6 * q], {0, 0, 1});  // no NORMAL: the geometric normal
  }
  // no material: the default one
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_FLOAT_EQ(s.materials[0].params.v[0][0], 0.8f);
  EXPECT_FALSE(s.hasCamera);
}

TEST(GltfLoader, ExternalBufferInsideTheDirectory) {
  Scene s = loadScene(kData + "external_buffer.gltf");
  EXPECT_EQ(s.triangleCount(), 1u);
}

TEST(GltfLoader, NodeHierarchyAndMirroring) {
  Scene s = loadScene(kData + "hierarchy.gltf");
  ASSERT_EQ(s.triangleCount(), 2u);
  // root: translate (10,0,0), scale 2; child: 90 degrees about z
  expectNear(s.positions[0], {10, 0, 0});
  expectNear(s.positions[1], {10, 2, 0});
  expectNear(s.positions[2], {8, 0, 0});
  expectNear(s.normals[0], {0, 0, 1});
  // mirrored (x -> -x): the winding is flipped so the geometric normal agrees with the normal
  expectNear(s.positions[3], {0, 0, 0});
  expectNear(s.positions[4], {0, 1, 0});
  expectNear(s.positions[5], {-1, 0, 0});
  for (std::size_t t = 0; t < 2; ++t) {
    glm::vec3 g = glm::cross(s.positions[3 * t + 1] - s.positions[3 * t], s.positions[3 * t + 2] - s.positions[3 * t]);
    EXPECT_GT(glm::dot(g, s.normals[3 * t]), 0.0f);
  }
}

TEST(GltfLoader, DegenerateTrianglesAreDropped) {
  Scene s = loadScene(kData + "degenerate.gltf");
  EXPECT_EQ(s.triangleCount(), 1u);
  EXPECT_EQ(s.droppedTriangles, 2u);  // one NaN vertex, one zero-area
}

TEST(GltfLoader, NonFiniteNormalFallsBackToGeometric) {
  Json j = triangleModel();
  std::vector<unsigned char> data = floats({0, 0, 0, 1, 0, 0, 0, 1, 0, NAN, 0, 0, 0, 0, 0, 0, 0, 1});
  j["buffers"][0] = {{"byteLength", data.size()}, {"uri", "data:application/octet-stream;base64," + base64(data)}};
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 36}});
  j["accessors"].push_back({{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1;
  Scene s = loadJson(j);
  ASSERT_EQ(s.triangleCount(), 1u);
  expectNear(s.normals[0], {0, 0, 1});  // NaN -> geometric
  expectNear(s.normals[1], {0, 0, 1});  // zero -> geometric
  expectNear(s.normals[2], {0, 0, 1});
}

TEST(GltfLoader, CamerasByName) {
  Scene s = loadScene(kData + "cameras.gltf");
  EXPECT_EQ(s.camera.name, "left");  // the first one by default
  expectNear(s.camera.position, {-1, 0, 5});
  expectNear(s.camera.forward, {0, 0, -1});
  EXPECT_FLOAT_EQ(s.camera.yfov, 0.5f);
  EXPECT_FLOAT_EQ(s.camera.aspectRatio, 0.0f);

  LoadOptions o;
  o.cameraName = "right";
  s = loadScene(kData + "cameras.gltf", o);
  expectNear(s.camera.forward, {-1, 0, 0});
  expectNear(s.camera.up, {0, 1, 0});
  EXPECT_FLOAT_EQ(s.camera.aspectRatio, 1.5f);

  o.cameraName = "top_node";  // a node name works too
  s = loadScene(kData + "cameras.gltf", o);
  EXPECT_TRUE(s.camera.orthographic);
  EXPECT_FLOAT_EQ(s.camera.xmag, 2.0f);
  EXPECT_FLOAT_EQ(s.camera.ymag, 1.5f);
  expectNear(s.camera.position, {0, 5, 0});
  expectNear(s.camera.forward, {0, -1, 0});  // scale 3 removed
  expectNear(s.camera.up, {0, 0, -1});

  o.cameraName = "nope";
  std::string e = fileError("cameras.gltf", o);
  EXPECT_HAS(e, "cameras.gltf");
  EXPECT_HAS(e, "\"nope\"");
  EXPECT_HAS(e, "\"left\", \"right\", \"top\"");
}

TEST(GltfLoader, PunctualLights) {
  Scene s = loadScene(kData + "lights.gltf");
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  EXPECT_EQ(s.lights[0].name, "bulb");
  expectNear(s.lights[0].position, {0, 2, 0});
  expectNear(s.lights[0].intensity, {4, 2, 1});
  EXPECT_EQ(s.lights[1].type, LightType::Spot);
  expectNear(s.lights[1].position, {1, 3, 0});
  expectNear(s.lights[1].direction, {0, -1, 0});
  expectNear(s.lights[1].intensity, {2, 2, 2});
  EXPECT_FLOAT_EQ(s.lights[1].innerConeAngle, 0.2f);
  EXPECT_FLOAT_EQ(s.lights[1].outerConeAngle, 0.6f);
  EXPECT_EQ(s.lights[2].type, LightType::Directional);
  expectNear(s.lights[2].direction, {-1, 0, 0});
  expectNear(s.lights[2].intensity, {3, 3, 3});
  EXPECT_TRUE(s.warnings.empty());
}

TEST(GltfLoader, NoCameraFramesTheScene) {
  Scene s = loadJson(triangleModel());
  EXPECT_FALSE(s.hasCamera);
  EXPECT_NEAR(s.camera.yfov, 0.785398, 1e-5);
  expectNear(s.camera.forward, {0, 0, -1});
  EXPECT_NEAR(s.camera.position.x, 0.5f, 1e-5);
  EXPECT_NEAR(s.camera.position.y, 0.5f, 1e-5);
  EXPECT_GT(s.camera.position.z, 1.0f);  // radius sqrt(0.5) / sin(22.5 deg) ~ 1.85
}

TEST(GltfLoader, StripsAndFansAreTriangulated) {
  Json j = triangleModel();
  std::vector<unsigned char> data = floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
  j["buffers"][0] = {{"byteLength", 48}, {"uri", "data:application/octet-stream;base64," + base64(data)}};
  j["bufferViews"][0]["byteLength"] = 48;
  j["accessors"][0]["count"] = 4;
  j["meshes"][0]["primitives"][0]["mode"] = 5;
  Scene s = loadJson(j);
  ASSERT_EQ(s.triangleCount(), 2u);
  for (std::size_t t = 0; t < 2; ++t) {
    glm::vec3 g = glm::cross(s.positions[3 * t + 1] - s.positions[3 * t], s.positions[3 * t + 2] - s.positions[3 * t]);
    EXPECT_GT(g.z, 0.0f);  // strips keep the winding
  }
  j["meshes"][0]["primitives"][0]["mode"] = 6;
  EXPECT_EQ(loadJson(j).triangleCount(), 2u);
  j["meshes"][0]["primitives"][0]["mode"] = 1;
  s = loadJson(j);
  EXPECT_EQ(s.triangleCount(), 0u);
  EXPECT_TRUE(hasWarning(s, "LINES"));
}

TEST(GltfLoader, MaterialsBrdfAndEmission) {
  Json j = triangleModel();
  j["extensionsUsed"] = {"NUSSELT_brdf", "KHR_materials_emissive_strength"};
  j["materials"] = Json::parse(R"([{"name": "lamp", "emissiveFactor": [1, 0.5, 0],
      "pbrMetallicRoughness": {"baseColorFactor": [2, -1, 0.5, 1]},
      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}},
    {"name": "Floor", "extensions": {"NUSSELT_brdf": {"model": "lambert", "params": {"rho": [0.1, 0.2, 0.3]}}}}])");
  j["meshes"][0]["primitives"][0]["material"] = 1;
  Scene s = loadJson(j);
  ASSERT_EQ(s.materials.size(), 2u);
  expectNear(s.materials[0].emission, {4, 2, 0});
  EXPECT_FLOAT_EQ(s.materials[0].params.v[0][0], 1.0f);  // clamped
  EXPECT_FLOAT_EQ(s.materials[0].params.v[0][1], 0.0f);
  EXPECT_FLOAT_EQ(s.materials[0].params.v[0][2], 0.5f);
  EXPECT_FLOAT_EQ(s.materials[1].params.v[0][1], 0.2f);
  EXPECT_EQ(s.triangleMaterial[0], 1u);
  EXPECT_TRUE(s.warnings.empty());
  // Without NUSSELT_brdf: the glTF metallic-roughness BRDF with the material's factors (glTF
  // defaults metallic 1, roughness 1 when absent).
  EXPECT_EQ(s.materials[0].model, MODEL_GLTF_PBR);
  EXPECT_FLOAT_EQ(shared::brdfParam(s.materials[0].params, GLTF_PBR_METALLIC), 1.0f);
  EXPECT_FLOAT_EQ(shared::brdfParam(s.materials[0].params, GLTF_PBR_ROUGHNESS), 1.0f);
  EXPECT_EQ(s.materials[1].model, MODEL_LAMBERT);
  {
    Json k = j;
    k["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 0.25;
    k["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 0.5;
    Scene t = loadJson(k);
    EXPECT_FLOAT_EQ(shared::brdfParam(t.materials[0].params, GLTF_PBR_METALLIC), 0.25f);
    EXPECT_FLOAT_EQ(shared::brdfParam(t.materials[0].params, GLTF_PBR_ROUGHNESS), 0.5f);
    k["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = 1.5;
    EXPECT_NE(jsonError(k).find("roughnessFactor"), std::string::npos);
  }

  j.erase("extensionsUsed");
  s = loadJson(j);
  EXPECT_TRUE(hasWarning(s, "NUSSELT_brdf is used but not declared"));

  j["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = -1;
  std::string e = jsonError(j);
  EXPECT_HAS(e, "mem.gltf: materials[0] \"lamp\"");
  EXPECT_HAS(e, "emissiveStrength");
}

TEST(GltfLoader, CombinedMaterialComponents) {
  Json j = triangleModel();
  j["extensionsUsed"] = {"NUSSELT_brdf"};
  j["materials"] = Json::parse(R"([{"name": "Glaze", "extensions": {"NUSSELT_brdf": {"components": [
      {"model": "lambert", "weight": 0.6, "params": {"rho": [0.5, 0.4, 0.3]}},
      {"model": "phong", "params": {"ks": 0.3, "n": 50}},
      {"model": "mirror", "weight": 0.2}]}}},
    {"name": "One", "extensions": {"NUSSELT_brdf": {"components": [{"model": "phong"}]}}}])");
  j["meshes"][0]["primitives"][0]["material"] = 0;
  Scene s = loadJson(j);
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& m = s.materials[0];
  ASSERT_EQ(m.components.size(), 3u);
  EXPECT_TRUE(m.combined());
  EXPECT_EQ(m.components[0].model, MODEL_LAMBERT);
  EXPECT_FLOAT_EQ(m.components[0].weight, 0.6f);
  EXPECT_FLOAT_EQ(m.components[0].params.v[0][1], 0.4f);
  EXPECT_EQ(m.components[1].model, MODEL_PHONG);
  EXPECT_FLOAT_EQ(m.components[1].weight, 1.0f);  // default weight
  EXPECT_FLOAT_EQ(shared::brdfParam(m.components[1].params, PHONG_N), 50.0f);
  EXPECT_EQ(m.components[2].model, MODEL_MIRROR);
  EXPECT_FLOAT_EQ(m.components[2].weight, 0.2f);
  EXPECT_EQ(m.model, MODEL_LAMBERT);  // repeats the first component
  // One component of weight 1 is the single-model form.
  EXPECT_FALSE(s.materials[1].combined());
  EXPECT_EQ(s.materials[1].model, MODEL_PHONG);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(GltfLoaderErrors, CombinedMaterialComponents) {
  auto errorWith = [](const char* brdf) {
    Json j = triangleModel();
    j["extensionsUsed"] = {"NUSSELT_brdf"};
    j["materials"] = Json::array({Json::object()});
    j["materials"][0]["name"] = "Glaze";
    j["materials"][0]["extensions"]["NUSSELT_brdf"] = Json::parse(brdf);
    return jsonError(j);
  };
  const std::string where = "mem.gltf: materials[0] \"Glaze\" NUSSELT_brdf";
  std::string e = errorWith(R"({"components": [{"model": "lambert"}, {"model": "no_such_model"}]})");
  EXPECT_HAS(e, where + ".components[1]");
  EXPECT_HAS(e, "unknown model \"no_such_model\"");
  e = errorWith(R"({"components": [{"model": "lambert", "weight": -0.5}]})");
  EXPECT_HAS(e, where + ".components[0].weight");
  EXPECT_HAS(e, "-0.5");
  e = errorWith(R"({"components": [{"model": "lambert", "weight": "heavy"}]})");
  EXPECT_HAS(e, where + ".components[0].weight: must be a number");
  e = errorWith(R"({"components": [{"model": "lambert", "weight": 1e300}, {"model": "phong"}]})");
  EXPECT_HAS(e, where + ".components[0].weight");
  e = errorWith(R"({"components": [{"model": "lambert"}, {"model": "phong"}, {"model": "mirror"},
                                   {"model": "ward"}, {"model": "lambert"}]})");
  EXPECT_HAS(e, where + ".components: 5 components, at most 4");
  e = errorWith(R"({"components": []})");
  EXPECT_HAS(e, where + ": needs \"model\"");
  EXPECT_HAS(e, "\"components\" (a non-empty array");
  e = errorWith(R"({"components": {"model": "lambert"}})");
  EXPECT_HAS(e, where + ".components: must be a non-empty array");
  e = errorWith(R"({"model": "lambert", "components": [{"model": "phong"}]})");
  EXPECT_HAS(e, "not both");
  e = errorWith(R"({"components": [{"model": "lambert", "params": {"rho": 1.5}}]})");
  EXPECT_HAS(e, where + ".components[0]");
  EXPECT_HAS(e, "\"rho\" = 1.5");
  e = errorWith(R"({"components": [{"model": "lambert", "colour": 1}]})");
  EXPECT_HAS(e, where + ".components[0]: unknown field \"colour\"");
  e = errorWith(R"({"components": [7]})");
  EXPECT_HAS(e, where + ".components[0]: must be an object");
}

TEST(GltfLoader, UnsupportedFeaturesWarn) {
  Json j = triangleModel();
  j["extensionsUsed"] = {"KHR_materials_clearcoat", "EXT_mesh_gpu_instancing"};
  j["materials"] = Json::parse(R"([{"extensions": {"KHR_materials_clearcoat": {}}}])");
  j["meshes"][0]["primitives"][0]["material"] = 0;
  j["animations"] = Json::array();
  Scene s = loadJson(j);
  EXPECT_EQ(s.triangleCount(), 1u);
  EXPECT_TRUE(hasWarning(s, "EXT_mesh_gpu_instancing"));
  EXPECT_TRUE(hasWarning(s, "KHR_materials_clearcoat"));
  int clearcoat = 0;
  for (const std::string& w : s.warnings) clearcoat += w.find("KHR_materials_clearcoat") != std::string::npos;
  EXPECT_EQ(clearcoat, 1);  // one line per feature
}

// ---------------------------------------------------------------------------------------------
// Bad files: each error names the file and the field.

TEST(GltfLoaderErrors, MissingFile) {
  std::string e = fileError("does_not_exist.gltf");
  EXPECT_HAS(e, "does_not_exist.gltf");
  EXPECT_HAS(e, "No such file");
}

TEST(GltfLoaderErrors, SceneIsADirectory) {
  std::string e = fileError("a_directory.bin");
  EXPECT_HAS(e, "a_directory.bin");
  EXPECT_HAS(e, "directory");
}

TEST(GltfLoaderErrors, MalformedJson) {
  std::string e = fileError("malformed.gltf");
  EXPECT_HAS(e, "malformed.gltf");
  EXPECT_HAS(e, "malformed JSON");
}

TEST(GltfLoaderErrors, TruncatedGlb) {
  std::string e = fileError("truncated.glb");
  EXPECT_HAS(e, "truncated.glb");
  EXPECT_HAS(e, "truncated");
  // every prefix of a valid GLB fails cleanly
  std::vector<unsigned char> bytes = readBytes(kSource + "/scenes/cornell-box.glb");
  for (std::size_t n : {0, 3, 4, 11, 12, 19, 20, 21, 100, 1000, 6000, 8403}) {
    std::string m = errorOf([&] { loadSceneFromMemory(bytes.data(), n, "cut.glb"); });
    EXPECT_HAS(m, "cut.glb");
  }
}

TEST(GltfLoaderErrors, AccessorOutOfBounds) {
  std::string e = fileError("accessor_oob.gltf");
  EXPECT_HAS(e, "accessor_oob.gltf: accessors[0] (POSITION of meshes[0].primitives[0]): byteOffset 0 + count 500 x stride 12 exceeds bufferViews[0] (byteLength 36)");
}

TEST(GltfLoaderErrors, IndexOutOfRange) {
  std::string e = fileError("index_oob.gltf");
  EXPECT_HAS(e, "index_oob.gltf: accessors[1] (indices of meshes[0].primitives[0]): index 7");
  EXPECT_HAS(e, "3 vertices");
}

TEST(GltfLoaderErrors, UnknownModel) {
  std::string e = fileError("unknown_model.gltf");
  EXPECT_HAS(e, "unknown_model.gltf: materials[0] \"Floor\" NUSSELT_brdf");
  EXPECT_HAS(e, "unknown model \"no_such_model\"");
  EXPECT_HAS(e, "lambert");
}

TEST(GltfLoaderErrors, UnknownParameter) {
  std::string e = fileError("unknown_param.gltf");
  EXPECT_HAS(e, "unknown_param.gltf: materials[0] \"Floor\" NUSSELT_brdf");
  EXPECT_HAS(e, "\"albedo\"");
  EXPECT_HAS(e, "rho");
}

TEST(GltfLoaderErrors, ParameterOutOfRange) {
  std::string e = fileError("param_range.gltf");
  EXPECT_HAS(e, "param_range.gltf: materials[0] \"Floor\" NUSSELT_brdf");
  EXPECT_HAS(e, "\"rho\" = 1.5");
}

TEST(GltfLoaderErrors, UriEscapingTheDirectory) {
  std::string e = fileError("uri_escape.gltf");
  EXPECT_HAS(e, "uri_escape.gltf: buffers[0].uri \"../gltf_secret.bin\"");
  EXPECT_HAS(e, "leave the scene directory");
}

TEST(GltfLoaderErrors, AbsoluteUri) {
  std::string e = fileError("uri_absolute.gltf");
  EXPECT_HAS(e, "uri_absolute.gltf: buffers[0].uri \"/etc/hostname\"");
  EXPECT_HAS(e, "absolute");
}

TEST(GltfLoaderErrors, UriNamingADirectory) {
  std::string e = fileError("uri_directory.gltf");
  EXPECT_HAS(e, "uri_directory.gltf: buffers[0].uri \"a_directory.bin\"");
  EXPECT_HAS(e, "not a regular file");
}

TEST(GltfLoaderErrors, SymlinkEscapingTheDirectory) {
  TempDir outside, inside;
  outside.write("secret.bin", std::string(36, 'x'));
  ASSERT_EQ(symlink((outside.path + "/secret.bin").c_str(), (inside.path + "/link.bin").c_str()), 0);
  Json j = triangleModel();
  j["buffers"][0]["uri"] = "link.bin";
  inside.write("scene.gltf", j.dump());
  std::string e = errorOf([&] { loadScene(inside.path + "/scene.gltf"); });
  EXPECT_HAS(e, "scene.gltf: buffers[0].uri \"link.bin\"");
  EXPECT_HAS(e, "outside the scene directory");
  // URI schemes and memory scenes
  j["buffers"][0]["uri"] = "file:///etc/hostname";
  EXPECT_HAS(jsonError(j), "URI schemes");
  j["buffers"][0]["uri"] = "triangle.bin";
  EXPECT_HAS(jsonError(j), "mem.gltf: buffers[0].uri \"triangle.bin\": external URIs are refused");
}

TEST(GltfLoaderErrors, DataUriSizeMismatch) {
  Json j = triangleModel();
  j["buffers"][0]["byteLength"] = 1000000000;
  std::string e = jsonError(j);
  EXPECT_HAS(e, "mem.gltf: buffers[0].uri: the data URI holds 36 bytes but byteLength is 1000000000");
}

TEST(GltfLoaderErrors, HostileNumbers) {
  Json j = triangleModel();
  j["accessors"][0]["count"] = 4611686018427387904ull;  // 2^62: stride x count overflows
  EXPECT_HAS(jsonError(j), "accessors[0] (POSITION of meshes[0].primitives[0])");
  j = triangleModel();
  j["accessors"][0]["byteOffset"] = 18446744073709551615ull;
  EXPECT_HAS(jsonError(j), "exceeds bufferViews[0]");
  j = triangleModel();
  j["accessors"][0]["byteOffset"] = -4;
  EXPECT_HAS(jsonError(j), "mem.gltf: accessors[0].byteOffset: -4 is not a non-negative integer");
  j = triangleModel();
  j["bufferViews"][0]["byteOffset"] = 18446744073709551600ull;
  EXPECT_HAS(jsonError(j), "mem.gltf: bufferViews[0]: byteOffset 18446744073709551600 + byteLength 36 exceeds buffers[0]");
  j = triangleModel();
  j["bufferViews"][0]["byteStride"] = 4;
  EXPECT_HAS(jsonError(j), "byteStride");
  j = triangleModel();
  j["accessors"][0]["componentType"] = 5123;
  EXPECT_HAS(jsonError(j), "accessors[0] (POSITION of meshes[0].primitives[0]): componentType 5123");
  j = triangleModel();
  j["accessors"][0]["type"] = "VEC2";
  EXPECT_HAS(jsonError(j), "type VEC2, expected VEC3");
  j = triangleModel();
  j["accessors"][0]["normalized"] = true;
  EXPECT_HAS(jsonError(j), "normalized");
  j = triangleModel();
  j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 99;
  EXPECT_HAS(jsonError(j), "POSITION of meshes[0].primitives[0]: 99 is out of range");
  j = triangleModel();
  j["nodes"][0]["mesh"] = 5;
  EXPECT_HAS(jsonError(j), "nodes[0].mesh: 5 is out of range");
  j = triangleModel();
  j["meshes"][0]["primitives"][0]["material"] = 3;
  EXPECT_HAS(jsonError(j), "meshes[0].primitives[0].material: 3 is out of range");
  j = triangleModel();
  j["scene"] = 7;
  EXPECT_HAS(jsonError(j), "scene: 7 is out of range");
  j = triangleModel();
  j["accessors"][0]["sparse"] = Json::parse(R"({"count": 1, "indices": {"bufferView": 0, "componentType": 5125},
                                               "values": {"bufferView": 0}})");
  EXPECT_HAS(jsonError(j), "sparse accessors are not supported");
  j = triangleModel();
  j["nodes"][0]["rotation"] = {0, 0, 0, 0};
  EXPECT_HAS(jsonError(j), "nodes[0].rotation");
  j = triangleModel();
  j["nodes"][0]["scale"] = {1, 2};
  EXPECT_HAS(jsonError(j), "nodes[0].scale");
}

TEST(GltfLoaderErrors, NodeCycles) {
  Json j = triangleModel();
  j["nodes"] = Json::parse(R"([{"mesh": 0, "children": [1]}, {"children": [0]}])");
  EXPECT_HAS(jsonError(j), "nodes[0]");
  j["nodes"] = Json::parse(R"([{"mesh": 0, "children": [0]}])");
  EXPECT_HAS(jsonError(j), "nodes[0]");
  j["nodes"] = Json::parse(R"([{"mesh": 0, "children": [1]}, {"children": [2]}, {"children": [1]}])");
  EXPECT_HAS(jsonError(j), "more than one parent");
  // no scenes: the roots are the parentless nodes; a detached cycle is never walked
  j.erase("scenes");
  j.erase("scene");
  j["nodes"] = Json::parse(R"([{"mesh": 0}, {"children": [2]}, {"children": [1]}])");
  EXPECT_EQ(loadJson(j).triangleCount(), 1u);
}

TEST(GltfLoaderErrors, RequiredExtensions) {
  Json j = triangleModel();
  j["extensionsRequired"] = {"KHR_lights_punctual", "KHR_draco_mesh_compression", "EXT_meshopt_compression",
                             "KHR_materials_clearcoat"};
  std::string e = jsonError(j);
  EXPECT_HAS(e, "mem.gltf: extensionsRequired: \"KHR_materials_clearcoat\" is not supported (supported: ");
}

TEST(GltfLoaderErrors, BadLightsAndCameras) {
  Json j = triangleModel();
  j["extensions"]["KHR_lights_punctual"]["lights"] = Json::parse(R"([{"type": "point", "intensity": -2}])");
  j["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  EXPECT_HAS(jsonError(j), "KHR_lights_punctual.lights[0].intensity: -2");
  j["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 4;
  EXPECT_HAS(jsonError(j), "nodes[0].extensions.KHR_lights_punctual.light: 4 is out of range");
  j = triangleModel();
  j["extensions"]["KHR_lights_punctual"]["lights"] =
      Json::parse(R"([{"type": "spot", "spot": {"innerConeAngle": 0.8, "outerConeAngle": 0.5}}])");
  j["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0;
  EXPECT_HAS(jsonError(j), "KHR_lights_punctual.lights[0].spot");
  j = triangleModel();
  j["cameras"] = Json::parse(R"([{"type": "perspective", "perspective": {"yfov": 4, "znear": 0.1}}])");
  j["nodes"][0]["camera"] = 0;
  EXPECT_HAS(jsonError(j), "mem.gltf: cameras[0].perspective.yfov: 4");
}

TEST(GltfLoaderErrors, DeepJsonAndGarbage) {
  std::string deep(100000, '[');
  EXPECT_HAS(errorOf([&] {
               loadSceneFromMemory(reinterpret_cast<const unsigned char*>(deep.data()), deep.size(), "deep.gltf");
             }),
             "deep.gltf: JSON is nested deeper");
  std::string garbage = "\x01\x02 not json";
  EXPECT_HAS(errorOf([&] {
               loadSceneFromMemory(reinterpret_cast<const unsigned char*>(garbage.data()), garbage.size(), "g.gltf");
             }),
             "g.gltf: neither glTF JSON (an object, starting with '{') nor GLB (magic \"glTF\"): the file starts "
             "with 01 02 20 6e 6f 74 20 6a (\".. not j\")");
  garbage = "{\x01\x02 not json";
  EXPECT_HAS(errorOf([&] {
               loadSceneFromMemory(reinterpret_cast<const unsigned char*>(garbage.data()), garbage.size(), "g.gltf");
             }),
             "g.gltf: malformed JSON");
  EXPECT_HAS(errorOf([&] { loadSceneFromMemory(nullptr, 0, "empty.gltf"); }), "empty.gltf");
  EXPECT_HAS(errorOf([&] { loadSceneFromMemory(reinterpret_cast<const unsigned char*>("[]"), 2, "arr.gltf"); }),
             "arr.gltf: the JSON top level is not an object");
  EXPECT_HAS(errorOf([&] { loadSceneFromMemory(reinterpret_cast<const unsigned char*>("{}"), 2, "noasset.gltf"); }),
             "noasset.gltf: invalid glTF");
}

// Random byte flips in a valid GLB must give an Error or a Scene, never a crash.
TEST(GltfLoaderErrors, MutatedGlbNeverCrashes) {
  const std::vector<unsigned char> original = readBytes(kSource + "/scenes/cornell-box.glb");
  std::uint32_t seed = 12345;
  auto next = [&] { return seed = seed * 1664525u + 1013904223u; };
  for (int round = 0; round < 300; ++round) {
    std::vector<unsigned char> bytes = original;
    int flips = 1 + int(next() % 8);
    for (int k = 0; k < flips; ++k) bytes[next() % bytes.size()] = static_cast<unsigned char>(next() >> 24);
    try {
      loadSceneFromMemory(bytes.data(), bytes.size(), "mutated.glb");
    } catch (const Error&) {
    }
  }
}

// The same for the JSON text: characters replaced by JSON punctuation and digits.
TEST(GltfLoaderErrors, MutatedJsonNeverCrashes) {
  std::vector<unsigned char> original = readBytes(kData + "lights.gltf");
  const std::string alphabet = "{}[]\",:-0123456789e.9";
  std::uint32_t seed = 777;
  auto next = [&] { return seed = seed * 1664525u + 1013904223u; };
  for (int round = 0; round < 300; ++round) {
    std::vector<unsigned char> bytes = original;
    int flips = 1 + int(next() % 4);
    for (int k = 0; k < flips; ++k) bytes[next() % bytes.size()] = static_cast<unsigned char>(alphabet[next() % alphabet.size()]);
    try {
      loadSceneFromMemory(bytes.data(), bytes.size(), "mutated.gltf");
    } catch (const Error&) {
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The generated renderer test scenes load as the renderer tests expect.

TEST(GltfLoaderScenes, Furnace) {
  Scene s = loadScene(kSource + "/scenes/tests/furnace.gltf");
  EXPECT_EQ(s.triangleCount() + s.droppedTriangles, 1024u);
  EXPECT_EQ(s.droppedTriangles, 64u);  // the pole triangles
  ASSERT_TRUE(s.hasCamera);
  expectNear(s.camera.position, {0, 0, 0});
  expectNear(s.camera.forward, {0, 0, -1});
  EXPECT_FLOAT_EQ(s.camera.yfov, 1.0f);
  ASSERT_EQ(s.materials.size(), 1u);
  expectNear(s.materials[0].emission, {1, 1, 1});
  EXPECT_FLOAT_EQ(s.materials[0].params.v[0][0], 0.5f);
  for (std::size_t t = 0; t < s.triangleCount(); ++t) {
    glm::vec3 c = (s.positions[3 * t] + s.positions[3 * t + 1] + s.positions[3 * t + 2]) / 3.0f;
    glm::vec3 g = glm::cross(s.positions[3 * t + 1] - s.positions[3 * t], s.positions[3 * t + 2] - s.positions[3 * t]);
    ASSERT_LT(glm::dot(g, c), 0.0f) << "triangle " << t << " faces outward";
    ASSERT_LT(glm::dot(s.normals[3 * t], c), 0.0f);
  }
  EXPECT_TRUE(s.warnings.empty());
}

TEST(GltfLoaderScenes, MisAndPunctual) {
  Scene mis = loadScene(kSource + "/scenes/tests/mis.gltf");
  EXPECT_EQ(mis.triangleCount(), 6u);
  EXPECT_TRUE(mis.hasCamera);
  EXPECT_TRUE(mis.lights.empty());
  int emitters = 0;
  for (std::size_t t = 0; t < mis.triangleCount(); ++t) {
    const Material& m = mis.materials[mis.triangleMaterial[t]];
    if (m.emission == glm::vec3(0)) continue;
    ++emitters;
    glm::vec3 g = glm::cross(mis.positions[3 * t + 1] - mis.positions[3 * t], mis.positions[3 * t + 2] - mis.positions[3 * t]);
    EXPECT_LT(g.y, 0.0f);  // facing the floor
  }
  EXPECT_EQ(emitters, 4);
  EXPECT_LT(mis.camera.position.y, 1.5f);  // below the emitters: sees their emitting side
  EXPECT_TRUE(mis.warnings.empty());

  Scene p = loadScene(kSource + "/scenes/tests/punctual.gltf");
  EXPECT_EQ(p.triangleCount(), 2u);
  ASSERT_EQ(p.lights.size(), 2u);
  EXPECT_EQ(p.lights[0].type, LightType::Point);
  EXPECT_EQ(p.lights[1].type, LightType::Spot);
  expectNear(p.lights[1].direction, {0, -1, 0});
  EXPECT_TRUE(p.hasCamera);
  EXPECT_TRUE(p.warnings.empty());
}

}  // namespace
}  // namespace nusselt

// Regressions of the loader bugs found by review (inputs shared with the fuzz corpus): each is
// now a clear error naming the file and the field, not an escaped exception, a multi-gigabyte
// allocation or a silently truncated integer.
TEST(GltfLoader, RegressionsFoundByReview) {
  const std::string dir = std::string(NUSSELT_SOURCE_DIR) + "/tests/fuzz/corpus/gltf/";
  auto errorFor = [](const std::string& path) {
    try {
      nusselt::loadScene(path);
    } catch (const nusselt::Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  struct Case {
    const char* file;
    const char* field;
  } cases[] = {
      {"regress_bin_buffer_zero_length.glb", "buffers[0].byteLength"},        // tinygltf: &data.at(0) threw
      {"regress_bin_buffer_amplification.glb", "buffers[1]"},                 // BIN chunk copied per buffer
      {"regress_int_truncation_index.gltf", "nodes[0].mesh: 4294967296"},     // became mesh 0
      {"regress_int_truncation_param.gltf", "parameter \"n\" = 4.29497e+09"},  // became n = 100
  };
  for (const Case& c : cases) {
    std::string msg = errorFor(dir + c.file);
    EXPECT_NE(msg.find(c.file), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.field), std::string::npos) << c.file << ": " << msg;
  }
}

// Found by fuzz_gltf (a long run): a triangle with a coordinate near the float maximum framed by
// the default view put the camera at infinity. Coordinates beyond 1e15 now drop their triangle
// (counted), and the default view of what is left is finite.
TEST(GltfLoader, RegressionHugeCoordinatesDropTheirTriangles) {
  const std::string path = std::string(NUSSELT_SOURCE_DIR) + "/tests/fuzz/corpus/gltf/regress_camera_at_infinity.glb";
  nusselt::Scene s = nusselt::loadScene(path);
  EXPECT_GT(s.droppedTriangles, 0u);
  for (const glm::vec3& p : s.positions)
    for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(p[k]), 1e15f);
  EXPECT_TRUE(std::isfinite(s.camera.position.x) && std::isfinite(s.camera.position.y) && std::isfinite(s.camera.position.z));
}
