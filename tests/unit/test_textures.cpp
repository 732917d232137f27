// test_textures.cpp: issue 18, CPU side. PNG/JPEG decoding (io/image_decode.h) against the
// formulas of tools/make_test_assets.cpp, the loader's textures, samplers, texture transforms,
// material extensions, texture coordinates, tangents, compressed geometry (quantized, Draco,
// meshopt) and every bad-input case with its message.
#include <gtest/gtest.h>
#include <turbojpeg.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../../shaders/shared/brdf/dispatch.h"
#include "../../shaders/shared/volume.h"
#include "io/image_decode.h"
#include "scene/gltf_loader.h"
#include "scene/tangents.h"
#include "util/error.h"

namespace nusselt {
namespace {

using Json = nlohmann::json;
using Bytes = std::vector<unsigned char>;

const std::string kSource = NUSSELT_SOURCE_DIR;
const std::string kImages = std::string(NUSSELT_TEST_DATA) + "/images/";
const std::string kGltf = std::string(NUSSELT_TEST_DATA) + "/gltf/";

#define EXPECT_HAS(haystack, needle) EXPECT_NE((haystack).find(needle), std::string::npos) << (haystack)

Bytes readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  return Bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

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

// No control character and no byte outside printable ASCII (for inputs without valid UTF-8).
bool asciiClean(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c >= 0x7f) return false;
  return true;
}

std::string base64(const Bytes& in) {
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

// ---------------------------------------------------------------------------------------------
// The test images' formulas (tools/make_test_assets.cpp): 5 x 3 pixels.

const int W = 5, H = 3;
int r8(int x, int y) { return x * 60 + y * 3; }
int g8(int x, int y) { return y * 80 + x; }
int b8(int x, int y) { return 200 - x * 10 - y * 20; }
int a8(int x, int y) { return 255 - x * 30 - y * 40; }
int grey8(int x, int y) { return x * 50 + y * 20; }
int r16(int x, int y) { return x * 15000 + y * 111 + 7; }
int g16(int x, int y) { return y * 20000 + x * 999; }
int b16(int x, int y) { return 65535 - x * 12345 - y * 3; }
int a16(int x, int y) { return 65535 - x * 9000 - y * 7000; }
int grey16(int x, int y) { return x * 13107 + y * 1000 + 123; }
// 16 -> 8 bits, correctly rounded.
int to8(int v16) { return int(std::lround(v16 * 255.0 / 65535.0)); }

struct Rgba {
  int r, g, b, a;
};

DecodedImage decodeFile(const std::string& name, const ImageLimits& limits = {}) {
  Bytes b = readBytes(kImages + name);
  return decodeImage(b.data(), b.size(), limits);
}

void expectPixels(const std::string& name, const std::function<Rgba(int, int)>& expected, int channels, int bits) {
  SCOPED_TRACE(name);
  DecodedImage im = decodeFile(name);
  ASSERT_EQ(im.width, W);
  ASSERT_EQ(im.height, H);
  ASSERT_EQ(im.rgba.size(), std::size_t(4 * W * H));
  EXPECT_EQ(im.format, ImageFormat::Png);
  EXPECT_EQ(im.sourceChannels, channels);
  EXPECT_EQ(im.sourceBits, bits);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::uint8_t* p = &im.rgba[std::size_t(4 * (y * W + x))];
      Rgba e = expected(x, y);
      EXPECT_EQ(int(p[0]), e.r) << "x " << x << " y " << y;
      EXPECT_EQ(int(p[1]), e.g) << "x " << x << " y " << y;
      EXPECT_EQ(int(p[2]), e.b) << "x " << x << " y " << y;
      EXPECT_EQ(int(p[3]), e.a) << "x " << x << " y " << y;
    }
}

TEST(ImageDecode, PngEveryColourTypeAndDepth) {
  expectPixels("grey1.png", [](int x, int y) { int v = (x + y) % 2 * 255; return Rgba{v, v, v, 255}; }, 1, 1);
  expectPixels("grey4.png", [](int x, int y) { int v = (x + 5 * y) % 16 * 17; return Rgba{v, v, v, 255}; }, 1, 4);
  expectPixels("grey8.png", [](int x, int y) { int v = grey8(x, y); return Rgba{v, v, v, 255}; }, 1, 8);
  expectPixels("grey16.png", [](int x, int y) { int v = to8(grey16(x, y)); return Rgba{v, v, v, 255}; }, 1, 16);
  expectPixels("greyalpha8.png", [](int x, int y) { int v = grey8(x, y); return Rgba{v, v, v, a8(x, y)}; }, 2, 8);
  expectPixels("greyalpha16.png",
               [](int x, int y) { int v = to8(grey16(x, y)); return Rgba{v, v, v, to8(a16(x, y))}; }, 2, 16);
  const Rgba palette[4] = {{255, 0, 0, 128}, {0, 255, 0, 0}, {0, 0, 255, 255}, {10, 20, 30, 255}};
  expectPixels("palette2_trns.png", [&](int x, int y) { return palette[(x + y) % 4]; }, 4, 2);
  expectPixels("palette8.png", [](int x, int y) {
    int i = x + W * y;
    return Rgba{i * 17, 255 - i * 17, i * 5, 255};
  }, 3, 8);
  auto rgb = [](int x, int y) { return Rgba{r8(x, y), g8(x, y), b8(x, y), 255}; };
  expectPixels("rgb8.png", rgb, 3, 8);
  // glTF: colour-space chunks are ignored; a gAMA of 1.0 changes nothing.
  expectPixels("rgb8_gamma1.png", rgb, 3, 8);
  expectPixels("rgb16.png", [](int x, int y) { return Rgba{to8(r16(x, y)), to8(g16(x, y)), to8(b16(x, y)), 255}; }, 3, 16);
  auto rgba = [](int x, int y) { return Rgba{r8(x, y), g8(x, y), b8(x, y), a8(x, y)}; };
  expectPixels("rgba8.png", rgba, 4, 8);
  expectPixels("rgba8_interlaced.png", rgba, 4, 8);
  expectPixels("rgba16.png", [](int x, int y) {
    return Rgba{to8(r16(x, y)), to8(g16(x, y)), to8(b16(x, y)), to8(a16(x, y))};
  }, 4, 16);
  // tRNS colour key: the colour of pixel (0, 0) (and no other) is transparent.
  expectPixels("rgb8_trns.png", [](int x, int y) { return Rgba{r8(x, y), g8(x, y), b8(x, y), x == 0 && y == 0 ? 0 : 255}; },
               4, 8);
}

// 16 x 16 JPEGs of four flat 8 x 8 blocks (make_test_assets.cpp, quality 95). JPEG is lossy:
// pixels at least 2 away from a block edge (chroma upsampling blends across edges) must be
// within `tolerance` code values of the block colour.
void expectJpegBlocks(const std::string& name, bool grey, int tolerance) {
  SCOPED_TRACE(name);
  const int colours[4][3] = {{200, 30, 40}, {20, 180, 60}, {40, 50, 220}, {250, 250, 250}};
  DecodedImage im = decodeFile(name);
  ASSERT_EQ(im.width, 16);
  ASSERT_EQ(im.height, 16);
  EXPECT_EQ(im.format, ImageFormat::Jpeg);
  EXPECT_EQ(im.sourceChannels, grey ? 1 : 3);
  int worst = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const std::uint8_t* p = &im.rgba[std::size_t(4 * (y * 16 + x))];
      EXPECT_EQ(p[3], 255);
      if (x % 8 < 2 || x % 8 > 5 || y % 8 < 2 || y % 8 > 5) continue;
      const int* c = colours[(y / 8) * 2 + x / 8];
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int(p[k]) - (grey ? c[0] : c[k])));
    }
  EXPECT_LE(worst, tolerance);
}

TEST(ImageDecode, JpegBaselineGreyAndProgressive) {
  expectJpegBlocks("rgb444.jpg", false, 4);
  expectJpegBlocks("grey.jpg", true, 2);
  expectJpegBlocks("progressive420.jpg", false, 8);
}

TEST(ImageDecode, CorruptTruncatedAndOversizedImages) {
  // Truncated JPEG: libjpeg's "premature end of data" warning is an error.
  Bytes jpeg = readBytes(kImages + "rgb444.jpg");
  Bytes half(jpeg.begin(), jpeg.begin() + std::ptrdiff_t(jpeg.size() / 2));
  std::string e = errorOf([&] { decodeImage(half.data(), half.size()); });
  EXPECT_HAS(e, "JPEG: corrupt");
  EXPECT_TRUE(asciiClean(e)) << e;
  // Truncated PNG, in the image data.
  Bytes png = readBytes(kImages + "rgba8.png");
  Bytes cut(png.begin(), png.end() - 20);
  e = errorOf([&] { decodeImage(cut.data(), cut.size()); });
  EXPECT_HAS(e, "PNG: corrupt");
  // Corrupt PNG: a flipped byte inside IDAT fails the chunk's CRC (a critical chunk: an error).
  Bytes flipped = png;
  std::size_t idat = 0;
  for (std::size_t i = 8; i + 4 < flipped.size(); ++i)
    if (std::memcmp(&flipped[i], "IDAT", 4) == 0) idat = i;
  ASSERT_GT(idat, 0u);
  flipped[idat + 6] ^= 0x55;
  e = errorOf([&] { decodeImage(flipped.data(), flipped.size()); });
  EXPECT_HAS(e, "PNG: corrupt: IDAT");
  // A bad CRC on intact image data: a critical chunk, so an error too.
  flipped = png;
  const std::uint32_t idatLength = std::uint32_t(png[idat - 4]) << 24 | std::uint32_t(png[idat - 3]) << 16 |
                                   std::uint32_t(png[idat - 2]) << 8 | png[idat - 1];
  flipped[idat + 4 + idatLength] ^= 0x01;
  e = errorOf([&] { decodeImage(flipped.data(), flipped.size()); });
  EXPECT_HAS(e, "PNG: corrupt: IDAT: CRC error");
  // Too many pixels for the cap: refused from the header.
  ImageLimits small;
  small.maxPixels = 14;
  e = errorOf([&] { decodeImage(png.data(), png.size(), small); });
  EXPECT_HAS(e, "PNG: 5 x 3 = 15 pixels exceeds the limit of 14 pixels per image");
  e = errorOf([&] { decodeImage(jpeg.data(), jpeg.size(), small); });
  EXPECT_HAS(e, "JPEG: 16 x 16 = 256 pixels exceeds the limit of 14");
  small = ImageLimits{};
  small.maxBytes = 50;
  e = errorOf([&] { decodeImage(png.data(), png.size(), small); });
  EXPECT_HAS(e, "exceeds the limit of 50 bytes");
  // A header claiming 100000 x 100000 pixels (valid CRC) is refused before any allocation.
  Bytes huge = png;
  std::size_t ihdr = 12;
  ASSERT_EQ(std::memcmp(&huge[ihdr], "IHDR", 4), 0);
  for (int k = 0; k < 2; ++k) {
    const std::uint32_t v = 100000;
    for (int b = 0; b < 4; ++b) huge[ihdr + 4 + 4 * std::size_t(k) + std::size_t(b)] = std::uint8_t(v >> (24 - 8 * b));
  }
  std::uint32_t crc = std::uint32_t(crc32(0, &huge[ihdr], 17));
  for (int b = 0; b < 4; ++b) huge[ihdr + 17 + std::size_t(b)] = std::uint8_t(crc >> (24 - 8 * b));
  e = errorOf([&] { decodeImage(huge.data(), huge.size()); });
  EXPECT_HAS(e, "PNG: 100000 x 100000 = 10000000000 pixels exceeds the limit of 67108864 pixels per image");
}

TEST(ImageDecode, UnsupportedFormatsAreNamedWithoutRawBytes) {
  const unsigned char webp[] = {'R', 'I', 'F', 'F', 0x10, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', ' '};
  std::string e = errorOf([&] { decodeImage(webp, sizeof webp); });
  EXPECT_HAS(e, "not a PNG or JPEG image");
  EXPECT_HAS(e, "WebP");
  EXPECT_HAS(e, "52 49 46 46 10 00 00 00");
  EXPECT_TRUE(asciiClean(e)) << e;
  const unsigned char junk[] = {0x01, 0x9b, 0x1b, '[', '2', 'J', 0xff, 0x00};
  e = errorOf([&] { decodeImage(junk, sizeof junk); });
  EXPECT_HAS(e, "01 9b 1b 5b 32 4a ff 00");
  EXPECT_TRUE(asciiClean(e)) << e;
  EXPECT_HAS(errorOf([&] { decodeImage(junk, 0); }), "no bytes");
  // CMYK JPEG (encoded here with TurboJPEG): refused by name.
  tjhandle tj = tjInitCompress();
  std::vector<unsigned char> cmyk(8 * 8 * 4, 100);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  ASSERT_EQ(tjCompress2(tj, cmyk.data(), 8, 0, 8, TJPF_CMYK, &out, &size, TJSAMP_444, 90, 0), 0);
  Bytes cmykJpeg(out, out + size);
  tjFree(out);
  tjDestroy(tj);
  EXPECT_HAS(errorOf([&] { decodeImage(cmykJpeg.data(), cmykJpeg.size()); }), "CMYK");
}

// ---------------------------------------------------------------------------------------------
// The loader: textures, samplers, transforms, material extensions.

std::vector<unsigned char> floatBytes(const std::vector<float>& v) {
  Bytes out(v.size() * 4);
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

std::string dataUri(const Bytes& b, const char* type = "application/octet-stream") {
  return std::string("data:") + type + ";base64," + base64(b);
}

// A unit quad (two triangles) in the xy plane facing +z, with TEXCOORD_0 (0,0) at the top-left
// corner (-1, 1); material 0 uses the images given as data URIs.
Json texturedQuad(const std::vector<std::string>& imageFiles = {"rgba8.png"}) {
  Bytes buffer = floatBytes({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0,  // positions
                             0, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0});                        // uv
  Json j = Json::parse(R"({
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5126, "count": 6, "type": "VEC2"}],
    "bufferViews": [{"buffer": 0, "byteLength": 72}, {"buffer": 0, "byteOffset": 72, "byteLength": 48}],
    "materials": [{"name": "mat", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}]})");
  j["buffers"] = {{{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}}};
  j["images"] = Json::array();
  for (const std::string& f : imageFiles) j["images"].push_back({{"uri", dataUri(readBytes(kImages + f), "image/png")}});
  return j;
}

Scene loadJson(const Json& j, const LoadOptions& options = {}) {
  std::string text = j.dump();
  return loadSceneFromMemory(reinterpret_cast<const unsigned char*>(text.data()), text.size(), "mem.gltf", options);
}

std::string jsonError(const Json& j, const LoadOptions& options = {}) {
  return errorOf([&] { loadJson(j, options); });
}

bool hasWarning(const Scene& s, const std::string& needle) {
  for (const std::string& w : s.warnings)
    if (w.find(needle) != std::string::npos) return true;
  return false;
}

// Scratch directory for scenes with external images.
struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/nusselt_tex_XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf '" + path + "'").c_str()); }
  void write(const std::string& name, const Bytes& bytes) const {
    std::ofstream(path + "/" + name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                             std::streamsize(bytes.size()));
  }
};

TEST(GltfTextures, ImagesAreDecodedOnceAndSlotsSayTheirColourSpace) {
  Json j = texturedQuad({"rgba8.png", "grey8.png"});
  j["textures"] = Json::parse(R"([{"source": 0}, {"source": 1}, {"source": 0}])");
  j["materials"][0] = Json::parse(R"({"name": "mat",
    "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1},
                             "baseColorFactor": [0.5, 0.25, 1, 0.75], "metallicFactor": 0.2, "roughnessFactor": 0.7},
    "normalTexture": {"index": 2, "scale": 0.5}, "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1],
    "occlusionTexture": {"index": 1}})");
  Scene s = loadJson(j);
  // rgba8.png serves baseColor (sRGB), normal (linear) and emissive (sRGB): decoded once.
  ASSERT_EQ(s.images.size(), 2u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.baseColorTexture.image, 0);
  EXPECT_EQ(m.normalTexture.image, 0);
  EXPECT_EQ(m.emissiveTexture.image, 0);
  EXPECT_EQ(m.metallicRoughnessTexture.image, 1);
  EXPECT_EQ(m.baseColorTexture.colorSpace, ColorSpace::Srgb);
  EXPECT_EQ(m.emissiveTexture.colorSpace, ColorSpace::Srgb);
  EXPECT_EQ(m.normalTexture.colorSpace, ColorSpace::Linear);
  EXPECT_EQ(m.metallicRoughnessTexture.colorSpace, ColorSpace::Linear);
  EXPECT_FLOAT_EQ(m.normalScale, 0.5f);
  EXPECT_FLOAT_EQ(m.baseColorFactor.w, 0.75f);
  EXPECT_FLOAT_EQ(m.baseColorFactor.y, 0.25f);
  EXPECT_FLOAT_EQ(m.metallicFactor, 0.2f);
  EXPECT_FLOAT_EQ(m.roughnessFactor, 0.7f);
  // The image bytes are the PNG's code values, row 0 first.
  const TextureImage& im = s.images[0];
  EXPECT_EQ(im.width, 5u);
  EXPECT_EQ(im.height, 3u);
  EXPECT_EQ(im.source, 0u);
  ASSERT_EQ(im.rgba.size(), 60u);
  EXPECT_EQ(im.rgba[4 * (2 * 5 + 3) + 0], r8(3, 2));
  EXPECT_EQ(im.rgba[4 * (2 * 5 + 3) + 3], a8(3, 2));
  EXPECT_EQ(s.images[1].rgba[4 * 4], grey8(4, 0));
  EXPECT_TRUE(hasWarning(s, "occlusionTexture is ignored"));
  // baseColor, metallicRoughness, emissive and normal textures render: no warning about them.
  EXPECT_FALSE(hasWarning(s, "read but not rendered yet"));
  // Without a sampler: REPEAT and LINEAR (glTF's "auto" filtering); no transform: identity.
  EXPECT_EQ(m.baseColorTexture.wrapS, WrapMode::Repeat);
  EXPECT_EQ(m.baseColorTexture.minFilter, FilterMode::Linear);
  EXPECT_EQ(m.baseColorTexture.transform, glm::mat3x2(1.0f));
  // Unused slots: no texture.
  EXPECT_FALSE(m.transmissionTexture.present());
}

TEST(GltfTextures, SamplerWrapAndFilterModes) {
  struct Case {
    int wrapS, wrapT, mag, min;
    WrapMode s, t;
    FilterMode fmag, fmin;
  } cases[] = {
      {10497, 33071, 9728, 9728, WrapMode::Repeat, WrapMode::ClampToEdge, FilterMode::Nearest, FilterMode::Nearest},
      {33648, 10497, 9729, 9729, WrapMode::MirroredRepeat, WrapMode::Repeat, FilterMode::Linear, FilterMode::Linear},
      {33071, 33648, 9728, 9984, WrapMode::ClampToEdge, WrapMode::MirroredRepeat, FilterMode::Nearest, FilterMode::Nearest},
      {10497, 10497, 9729, 9985, WrapMode::Repeat, WrapMode::Repeat, FilterMode::Linear, FilterMode::Linear},
      {10497, 10497, 9729, 9986, WrapMode::Repeat, WrapMode::Repeat, FilterMode::Linear, FilterMode::Nearest},
      {10497, 10497, 9728, 9987, WrapMode::Repeat, WrapMode::Repeat, FilterMode::Nearest, FilterMode::Linear},
  };
  for (const Case& c : cases) {
    Json j = texturedQuad();
    j["samplers"] = {{{"wrapS", c.wrapS}, {"wrapT", c.wrapT}, {"magFilter", c.mag}, {"minFilter", c.min}}};
    j["textures"][0]["sampler"] = 0;
    const TextureRef r = loadJson(j).materials[0].baseColorTexture;
    EXPECT_EQ(r.wrapS, c.s) << c.wrapS;
    EXPECT_EQ(r.wrapT, c.t) << c.wrapT;
    EXPECT_EQ(r.magFilter, c.fmag) << c.mag;
    EXPECT_EQ(r.minFilter, c.fmin) << c.min;
  }
  // Defaults of a sampler without fields: REPEAT, LINEAR.
  Json j = texturedQuad();
  j["samplers"] = Json::array({Json::object()});
  j["textures"][0]["sampler"] = 0;
  const TextureRef r = loadJson(j).materials[0].baseColorTexture;
  EXPECT_EQ(r.wrapT, WrapMode::Repeat);
  EXPECT_EQ(r.magFilter, FilterMode::Linear);
  // Bad values name the sampler and the field.
  j["samplers"][0]["wrapS"] = 1234;
  EXPECT_HAS(jsonError(j), "mem.gltf: samplers[0].wrapS: 1234 is not a wrap mode");
  j["samplers"][0] = {{"magFilter", 9984}};
  EXPECT_HAS(jsonError(j), "mem.gltf: samplers[0].magFilter: 9984 is not a filter");
  j["samplers"][0] = {{"minFilter", 7}};
  EXPECT_HAS(jsonError(j), "mem.gltf: samplers[0].minFilter: 7");
  j["textures"][0]["sampler"] = 3;
  EXPECT_HAS(jsonError(j), "mem.gltf: textures[0].sampler: 3 is out of range");
}

glm::vec2 apply(const glm::mat3x2& m, float u, float v) { return m * glm::vec3(u, v, 1.0f); }

TEST(GltfTextures, TextureTransform) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_texture_transform"};
  // The extension's example: the lower-left quadrant of the image, rotated 90 degrees.
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] =
      Json::parse(R"({"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]})");
  Scene s = loadJson(j);
  const glm::mat3x2 m = s.materials[0].baseColorTexture.transform;
  const float eps = 1e-6f;
  glm::vec2 p = apply(m, 0, 0);
  EXPECT_NEAR(p.x, 0.0f, eps);
  EXPECT_NEAR(p.y, 1.0f, eps);
  p = apply(m, 1, 0);
  EXPECT_NEAR(p.x, 0.0f, eps);
  EXPECT_NEAR(p.y, 0.5f, eps);
  p = apply(m, 0, 1);
  EXPECT_NEAR(p.x, 0.5f, eps);
  EXPECT_NEAR(p.y, 1.0f, eps);
  p = apply(m, 1, 1);
  EXPECT_NEAR(p.x, 0.5f, eps);
  EXPECT_NEAR(p.y, 0.5f, eps);
  EXPECT_FALSE(hasWarning(s, "KHR_texture_transform"));
  // Offset and scale alone; texCoord override.
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] =
      Json::parse(R"({"offset": [0.25, -2], "scale": [3, 0.5], "texCoord": 1})");
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 0;
  s = loadJson(j);
  p = apply(s.materials[0].baseColorTexture.transform, 2, 4);
  EXPECT_NEAR(p.x, 6.25f, eps);
  EXPECT_NEAR(p.y, 0.0f, eps);
  EXPECT_EQ(s.materials[0].baseColorTexture.texCoord, 1u);
  // Bad values.
  auto& t = j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"];
  t = Json::parse(R"({"scale": [1]})");
  EXPECT_HAS(jsonError(j), "baseColorTexture.extensions.KHR_texture_transform.scale: expected 2 numbers");
  t = Json::parse(R"({"rotation": "left"})");
  EXPECT_HAS(jsonError(j), "KHR_texture_transform.rotation: must be a number");
  t = Json::parse(R"({"offset": [1e300, 0]})");
  EXPECT_HAS(jsonError(j), "KHR_texture_transform.offset[0]: 1e+300 is not a finite number");
  t = Json::parse(R"({"texCoord": -1})");
  EXPECT_HAS(jsonError(j), "KHR_texture_transform.texCoord: must be a non-negative integer");
  // A texture set beyond TEXCOORD_1: named in a warning, the factor alone.
  t = Json::parse(R"({"texCoord": 2})");
  s = loadJson(j);
  EXPECT_FALSE(s.materials[0].baseColorTexture.present());
  EXPECT_TRUE(hasWarning(s, "uses TEXCOORD_2; only TEXCOORD_0 and TEXCOORD_1 are read"));
}

TEST(GltfTextures, AlphaSidednessTransmissionIorVolume) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"};
  j["materials"][0] = Json::parse(R"({"name": "glass", "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true,
    "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.4]},
    "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.9, "transmissionTexture": {"index": 0, "texCoord": 0}},
                   "KHR_materials_ior": {"ior": 1.33},
                   "KHR_materials_volume": {"thicknessFactor": 0.02, "attenuationDistance": 0.5,
                                            "attenuationColor": [0.9, 0.5, 0.1]}}})");
  Scene s = loadJson(j);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.3f);
  EXPECT_FLOAT_EQ(m.baseColorFactor.w, 0.4f);
  EXPECT_TRUE(m.doubleSided);
  EXPECT_FLOAT_EQ(m.transmissionFactor, 0.9f);
  EXPECT_EQ(m.transmissionTexture.image, 0);
  EXPECT_EQ(m.transmissionTexture.colorSpace, ColorSpace::Linear);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  EXPECT_TRUE(m.hasVolume);
  EXPECT_FLOAT_EQ(m.thicknessFactor, 0.02f);
  EXPECT_FLOAT_EQ(m.attenuationDistance, 0.5f);
  EXPECT_FLOAT_EQ(m.attenuationColor.y, 0.5f);
  // A metal (glTF's default metallicFactor 1) does not transmit: no path gets inside to be attenuated.
  EXPECT_TRUE(hasWarning(s, "read but not rendered yet: KHR_materials_volume attenuation without thicknessFactor > 0 "
                            "and transmission, transmissionTexture ("));
  EXPECT_EQ(m.absorption, glm::vec3(0.0f));
  // glTF's default metallicFactor 1: a metal does not transmit, the material stays gltf_pbr.
  EXPECT_EQ(m.model, MODEL_GLTF_PBR);
  EXPECT_FALSE(m.combined());
  // Defaults.
  Json d = texturedQuad();
  d["materials"][0] = Json::parse(R"({"extensions": {"KHR_materials_volume": {}}})");
  const Material dm = loadJson(d).materials[0];
  EXPECT_EQ(dm.alphaMode, AlphaMode::Opaque);
  EXPECT_FLOAT_EQ(dm.alphaCutoff, 0.5f);
  EXPECT_FALSE(dm.doubleSided);
  EXPECT_FLOAT_EQ(dm.ior, 1.5f);
  EXPECT_TRUE(dm.hasVolume);
  EXPECT_TRUE(std::isinf(dm.attenuationDistance));
  EXPECT_EQ(dm.attenuationColor, glm::vec3(1.0f));
  // Errors name the material and the field.
  auto errorWith = [&](const char* material) {
    Json k = texturedQuad();
    k["materials"][0] = Json::parse(material);
    return jsonError(k);
  };
  EXPECT_HAS(errorWith(R"({"name": "m", "alphaMode": "CLEAR"})"), "mem.gltf: materials[0] \"m\".alphaMode: \"CLEAR\"");
  EXPECT_HAS(errorWith(R"({"alphaCutoff": -1})"), "materials[0].alphaCutoff: -1");
  EXPECT_HAS(errorWith(R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.5}}})"),
             "materials[0] KHR_materials_transmission.transmissionFactor: 1.5 is not in [0, 1]");
  EXPECT_HAS(errorWith(R"({"extensions": {"KHR_materials_ior": {"ior": 0.5}}})"),
             "materials[0] KHR_materials_ior.ior: 0.5 is not in [1, 100]");
  EXPECT_HAS(errorWith(R"({"extensions": {"KHR_materials_volume": {"attenuationDistance": 0}}})"),
             "mem.gltf: materials[0] KHR_materials_volume.attenuationDistance: 0 is not a distance >= 1e-30 (metres)");
  EXPECT_HAS(errorWith(R"({"extensions": {"KHR_materials_volume": {"attenuationColor": [1, 2, 0]}}})"),
             "KHR_materials_volume.attenuationColor[1]: 2 is not in [0, 1]");
  EXPECT_HAS(errorWith(R"({"extensions": {"KHR_materials_transmission": {"transmissionTexture": {"index": 9}}}})"),
             "KHR_materials_transmission.transmissionTexture.index: 9 is out of range");
  EXPECT_HAS(errorWith(R"({"normalTexture": {"index": 0, "scale": 1e300}})"), "normalTexture.scale");
}

// KHR_materials_transmission renders as gltf_pbr with weight 1 - w plus a dielectric of index ior
// with weight w = transmissionFactor x (1 - metallic); w = 1: the dielectric alone. Neither
// extension is then named in the "not rendered" warning. With KHR_materials_volume's thickness the
// dielectric refracts (dielectric; rough_dielectric with alpha = roughness^2 when the material is
// rough); without, the surface is thin-walled (thin_dielectric), as the extension defines.
TEST(GltfTextures, TransmissionBecomesTheDielectric) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"};
  j["materials"][0] = Json::parse(R"({"name": "frosted", "pbrMetallicRoughness": {"metallicFactor": 0.2,
    "roughnessFactor": 0.3}, "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.75},
                                           "KHR_materials_ior": {"ior": 1.33},
                                           "KHR_materials_volume": {"thicknessFactor": 0.1}}})");
  Scene s = loadJson(j);
  const Material& m = s.materials[0];
  ASSERT_EQ(m.components.size(), 2u);
  EXPECT_EQ(m.components[0].model, MODEL_GLTF_PBR);
  EXPECT_FLOAT_EQ(m.components[0].weight, 0.4f);
  EXPECT_FLOAT_EQ(m.components[0].params.v[GLTF_PBR_ROUGHNESS / 4][GLTF_PBR_ROUGHNESS % 4], 0.3f);
  // Rough (0.3) with a volume: rough_dielectric, alpha 0.09.
  EXPECT_EQ(m.components[1].model, MODEL_ROUGH_DIELECTRIC);
  EXPECT_FLOAT_EQ(m.components[1].weight, 0.6f);
  EXPECT_FLOAT_EQ(m.components[1].params.v[ROUGH_DIELECTRIC_ETA / 4][ROUGH_DIELECTRIC_ETA % 4], 1.33f);
  EXPECT_FLOAT_EQ(m.components[1].params.v[ROUGH_DIELECTRIC_ALPHA / 4][ROUGH_DIELECTRIC_ALPHA % 4], 0.09f);
  // The base colour (default white) tints the transmission.
  EXPECT_EQ(shared::brdfParam3(m.components[1].params, ROUGH_DIELECTRIC_TINT), glm::vec3(1.0f));
  EXPECT_FALSE(hasWarning(s, "read but not rendered yet"));
  j["materials"][0] = Json::parse(R"({"name": "glass", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0,
    "baseColorFactor": [0.8, 0.5, 0.2, 1]},
    "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                   "KHR_materials_volume": {"thicknessFactor": 0.1}}})");
  const Material g = loadJson(j).materials[0];
  EXPECT_FALSE(g.combined());
  EXPECT_EQ(g.model, MODEL_DIELECTRIC);
  EXPECT_FLOAT_EQ(g.params.v[DIELECTRIC_ETA / 4][DIELECTRIC_ETA % 4], 1.5f);
  EXPECT_EQ(shared::brdfParam3(g.params, DIELECTRIC_TINT), glm::vec3(0.8f, 0.5f, 0.2f));
  // Thin-walled: no volume, or a volume of thickness 0 (smooth: glTF's default roughness 1 would
  // make it rough_thin_dielectric, ThinWalledRoughTransmissionBecomesRoughThinDielectric).
  for (const char* volume : {"", R"(, "KHR_materials_volume": {"thicknessFactor": 0})"}) {
    j["materials"][0] = Json::parse(std::string(R"({"name": "pane", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}, "KHR_materials_ior": {"ior": 1.7})") +
                                    volume + "}}");
    const Material t = loadJson(j).materials[0];
    ASSERT_EQ(t.components.size(), 2u) << volume;
    EXPECT_EQ(t.components[1].model, MODEL_THIN_DIELECTRIC) << volume;
    EXPECT_FLOAT_EQ(t.components[1].params.v[THIN_DIELECTRIC_ETA / 4][THIN_DIELECTRIC_ETA % 4], 1.7f);
  }
}

// Rough transmission (roughnessFactor r > 0) in a refracting volume (thicknessFactor > 0) with
// w = transmissionFactor x (1 - metallic) = 1 and no transmissionTexture: rough_dielectric alone,
// alpha = r^2, eta = ior (default 1.5; clamped to the model's [1.01, 4] with a warning), the
// volume's absorption as for the smooth dielectric. glTF's default roughnessFactor is 1. The
// smooth case (r = 0) stays the dielectric; partial or textured rough transmission stays smooth
// and is named in a warning (thin-walled: the next test).
TEST(GltfTextures, RoughTransmissionBecomesRoughDielectric) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"};
  auto material = [&](const std::string& pbr, const std::string& extensions) {
    j["materials"][0] = Json::parse(R"({"name": "frosted", "pbrMetallicRoughness": {"metallicFactor": 0)" + pbr +
                                    R"(}, "extensions": {)" + extensions + "}}");
    return loadJson(j);
  };
  const std::string full = R"("KHR_materials_transmission": {"transmissionFactor": 1})";
  const std::string volume = R"(, "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationDistance": 0.5,
                                                            "attenuationColor": [1, 0.5, 0.1]})";
  auto param = [](const Material& m, std::uint32_t i) { return m.params.v[i / 4][i % 4]; };
  Scene s = material(R"(, "roughnessFactor": 0.5)", full + R"(, "KHR_materials_ior": {"ior": 1.33})" + volume);
  const Material& m = s.materials[0];
  EXPECT_FALSE(m.combined());
  EXPECT_EQ(m.model, MODEL_ROUGH_DIELECTRIC);
  EXPECT_FLOAT_EQ(param(m, ROUGH_DIELECTRIC_ALPHA), 0.25f);
  EXPECT_FLOAT_EQ(param(m, ROUGH_DIELECTRIC_ETA), 1.33f);
  EXPECT_FLOAT_EQ(m.absorption.y, float(-std::log(0.5) / 0.5));
  EXPECT_FALSE(hasWarning(s, "rendered as smooth transmission"));
  EXPECT_FALSE(hasWarning(s, "read but not rendered yet"));
  // glTF's default roughness 1 and ior 1.5.
  const Material d = material("", full + volume).materials[0];
  EXPECT_EQ(d.model, MODEL_ROUGH_DIELECTRIC);
  EXPECT_FLOAT_EQ(param(d, ROUGH_DIELECTRIC_ALPHA), 1.0f);
  EXPECT_FLOAT_EQ(param(d, ROUGH_DIELECTRIC_ETA), 1.5f);
  // alpha clamped to 0.001 (r < 0.0316), ior 1 to the model's 1.01 (named).
  Scene c = material(R"(, "roughnessFactor": 0.01)", full + R"(, "KHR_materials_ior": {"ior": 1.0})" + volume);
  EXPECT_FLOAT_EQ(param(c.materials[0], ROUGH_DIELECTRIC_ALPHA), 0.001f);
  EXPECT_FLOAT_EQ(param(c.materials[0], ROUGH_DIELECTRIC_ETA), 1.01f);
  EXPECT_TRUE(hasWarning(c, "KHR_materials_ior 1 of a rough transmitting material is rendered as 1.01"));
  // Smooth: the dielectric, as before.
  const Material g = material(R"(, "roughnessFactor": 0)", full + volume).materials[0];
  EXPECT_EQ(g.model, MODEL_DIELECTRIC);
  // Partial rough transmission: the combination with rough_dielectric (weight w, alpha r^2), no warning.
  Scene p = material(R"(, "roughnessFactor": 0.5)", R"("KHR_materials_transmission": {"transmissionFactor": 0.5})" + volume);
  ASSERT_EQ(p.materials[0].components.size(), 2u);
  EXPECT_EQ(p.materials[0].components[0].model, MODEL_GLTF_PBR);
  EXPECT_FLOAT_EQ(p.materials[0].components[0].weight, 0.5f);
  EXPECT_EQ(p.materials[0].components[1].model, MODEL_ROUGH_DIELECTRIC);
  EXPECT_FLOAT_EQ(p.materials[0].components[1].weight, 0.5f);
  EXPECT_FLOAT_EQ(p.materials[0].components[1].params.v[ROUGH_DIELECTRIC_ALPHA / 4][ROUGH_DIELECTRIC_ALPHA % 4], 0.25f);
  EXPECT_FALSE(hasWarning(p, "rendered as smooth transmission"));
}

// Thin-walled rough transmission (no KHR_materials_volume, or thicknessFactor 0) with w = 1 and no
// transmissionTexture: rough_thin_dielectric alone (issue 18), alpha = r^2, eta = ior (clamped to
// the model's [1.01, 4], named), tint = baseColorFactor, no absorption and no warning. r = 0 stays
// thin_dielectric; partial (w < 1) and textured rough transmission are the combination with
// rough_thin_dielectric (the shade stage shades transmitting components on both sides).
TEST(GltfTextures, ThinWalledRoughTransmissionBecomesRoughThinDielectric) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"};
  auto material = [&](const std::string& pbr, const std::string& extensions) {
    j["materials"][0] = Json::parse(R"({"name": "frosted pane", "pbrMetallicRoughness": {"metallicFactor": 0,
      "baseColorFactor": [0.8, 0.5, 0.2, 1])" + pbr + R"(}, "extensions": {)" + extensions + "}}");
    return loadJson(j);
  };
  auto param = [](const Material& m, std::uint32_t i) { return m.params.v[i / 4][i % 4]; };
  const std::string full = R"("KHR_materials_transmission": {"transmissionFactor": 1})";
  for (const char* volume : {"", R"(, "KHR_materials_volume": {"thicknessFactor": 0})"}) {
    Scene s = material(R"(, "roughnessFactor": 0.5)", full + R"(, "KHR_materials_ior": {"ior": 1.33})" + volume);
    const Material& m = s.materials[0];
    EXPECT_FALSE(m.combined()) << volume;
    EXPECT_EQ(m.model, MODEL_ROUGH_THIN_DIELECTRIC) << volume;
    EXPECT_FLOAT_EQ(param(m, ROUGH_THIN_DIELECTRIC_ALPHA), 0.25f);
    EXPECT_FLOAT_EQ(param(m, ROUGH_THIN_DIELECTRIC_ETA), 1.33f);
    EXPECT_EQ(shared::brdfParam3(m.params, ROUGH_THIN_DIELECTRIC_TINT), glm::vec3(0.8f, 0.5f, 0.2f));
    EXPECT_EQ(m.absorption, glm::vec3(0.0f));
    EXPECT_FALSE(hasWarning(s, "rendered as smooth transmission")) << volume;
    EXPECT_FALSE(hasWarning(s, "read but not rendered yet")) << volume;
  }
  // glTF's default roughness 1; ior 5 clamped to the model's 4 (named).
  Scene c = material("", full + R"(, "KHR_materials_ior": {"ior": 5})");
  EXPECT_EQ(c.materials[0].model, MODEL_ROUGH_THIN_DIELECTRIC);
  EXPECT_FLOAT_EQ(param(c.materials[0], ROUGH_THIN_DIELECTRIC_ALPHA), 1.0f);
  EXPECT_FLOAT_EQ(param(c.materials[0], ROUGH_THIN_DIELECTRIC_ETA), 4.0f);
  EXPECT_TRUE(hasWarning(c, "KHR_materials_ior 5 of a rough transmitting material is rendered as 4 "
                            "(rough_thin_dielectric's eta is in [1.01, 4])"));
  // Smooth (r = 0): thin_dielectric, as before.
  EXPECT_EQ(material(R"(, "roughnessFactor": 0)", full).materials[0].model, MODEL_THIN_DIELECTRIC);
  // Partial and textured: the combination with rough_thin_dielectric (weight w, alpha r^2), no warning.
  Scene p = material(R"(, "roughnessFactor": 0.5)", R"("KHR_materials_transmission": {"transmissionFactor": 0.5})");
  ASSERT_EQ(p.materials[0].components.size(), 2u);
  EXPECT_EQ(p.materials[0].components[1].model, MODEL_ROUGH_THIN_DIELECTRIC);
  EXPECT_FLOAT_EQ(p.materials[0].components[1].weight, 0.5f);
  EXPECT_FALSE(hasWarning(p, "rendered as smooth transmission"));
  Scene t = material(R"(, "roughnessFactor": 0.5)",
                     R"("KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": {"index": 0}})");
  ASSERT_EQ(t.materials[0].components.size(), 2u);
  EXPECT_EQ(t.materials[0].components[1].model, MODEL_ROUGH_THIN_DIELECTRIC);
  EXPECT_TRUE(t.materials[0].transmissionTextured);
  EXPECT_FALSE(hasWarning(t, "rendered as smooth transmission"));
}

// transmissionTexture applies to the transmission combination: the material stays combined
// {gltf_pbr, 1 - w; glass, w} even for w = 1, marked transmissionTextured (the renderer takes
// w x R for the glass); without transmission (w = 0: a metal) it is named as not rendered.
TEST(GltfTextures, TransmissionTextureKeepsTheCombination) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission"};
  j["materials"][0] = Json::parse(R"({"name": "stained", "pbrMetallicRoughness": {"metallicFactor": 0},
    "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1, "transmissionTexture": {"index": 0}}}})");
  Scene s = loadJson(j);
  const Material& m = s.materials[0];
  ASSERT_EQ(m.components.size(), 2u);
  EXPECT_TRUE(m.transmissionTextured);
  EXPECT_EQ(m.components[0].model, MODEL_GLTF_PBR);
  EXPECT_FLOAT_EQ(m.components[0].weight, 0.0f);
  // glTF's default roughness 1: the rough sheet (ThinWalledRoughTransmissionBecomesRoughThinDielectric).
  EXPECT_EQ(m.components[1].model, MODEL_ROUGH_THIN_DIELECTRIC);
  EXPECT_FLOAT_EQ(m.components[1].weight, 1.0f);
  // (Applied, so not named as unrendered.)
  EXPECT_FALSE(hasWarning(s, "not rendered yet: transmissionTexture"));
  j["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 1;
  Scene metal = loadJson(j);
  EXPECT_FALSE(metal.materials[0].transmissionTextured);
  EXPECT_FALSE(metal.materials[0].combined());
  EXPECT_TRUE(hasWarning(metal, "read but not rendered yet: transmissionTexture ("));
}

// KHR_materials_volume's attenuation in a refracting volume (thicknessFactor > 0, transmission):
// Material::absorption = -ln(attenuationColor) / attenuationDistance per channel (volume.h), a
// colour channel of 0 clamped to VOLUME_MAX_ABSORPTION, no attenuationDistance (or one beyond
// 1e30) none; not named in the "not rendered" warning. Bad values are errors naming the file, the
// material and the field.
TEST(GltfTextures, VolumeAttenuationBecomesTheAbsorptionCoefficient) {
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_volume"};
  auto glass = [&](const std::string& volume) {
    j["materials"][0] = Json::parse(R"({"name": "tinted", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
      "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                     "KHR_materials_volume": )" + volume + "}}");
    return j;
  };
  Scene s = loadJson(glass(R"({"thicknessFactor": 0.1, "attenuationDistance": 0.5, "attenuationColor": [1, 0.5, 0.1]})"));
  const Material& m = s.materials[0];
  EXPECT_EQ(m.model, MODEL_DIELECTRIC);
  EXPECT_FLOAT_EQ(m.absorption.x, 0.0f);
  EXPECT_NEAR(m.absorption.y, std::log(2.0) / 0.5, 1e-5);
  EXPECT_NEAR(m.absorption.z, std::log(10.0) / 0.5, 1e-5);
  EXPECT_TRUE(m.absorbs());
  EXPECT_FALSE(hasWarning(s, "read but not rendered yet"));
  // The transmittance over attenuationDistance is attenuationColor.
  const glm::vec3 t = shared::volumeTransmittance(m.absorption, 0.5f);
  EXPECT_NEAR(t.y, 0.5f, 1e-6);
  EXPECT_NEAR(t.z, 0.1f, 1e-6);
  // A black channel absorbs everything, finitely; no distance (or 1e300): no absorption.
  const Material black = loadJson(glass(R"({"thicknessFactor": 0.1, "attenuationDistance": 2, "attenuationColor": [0, 1, 1]})")).materials[0];
  EXPECT_EQ(black.absorption.x, VOLUME_MAX_ABSORPTION);
  EXPECT_EQ(shared::volumeTransmittance(black.absorption, 1e-6f).x, 0.0f);
  EXPECT_EQ(shared::volumeTransmittance(black.absorption, 0.0f).x, 1.0f);
  for (const char* none : {R"({"thicknessFactor": 0.1, "attenuationColor": [0.5, 0.5, 0.5]})",
                           R"({"thicknessFactor": 0.1, "attenuationColor": [0, 0, 0]})",
                           R"({"thicknessFactor": 0.1, "attenuationDistance": 1e300, "attenuationColor": [0.5, 0.5, 0.5]})"}) {
    const Material n = loadJson(glass(none)).materials[0];
    EXPECT_FALSE(n.absorbs()) << none;
  }
  // Thin-walled (thickness 0): nothing travels inside; the attenuation is named as not rendered.
  Scene thin = loadJson(glass(R"({"attenuationDistance": 0.5, "attenuationColor": [1, 0.5, 0.1]})"));
  EXPECT_FALSE(thin.materials[0].absorbs());
  EXPECT_TRUE(hasWarning(thin, "KHR_materials_volume attenuation without thicknessFactor > 0 and transmission"));
  // Bad values.
  const std::string f = "mem.gltf: materials[0] \"tinted\" KHR_materials_volume.";
  EXPECT_HAS(jsonError(glass(R"({"thicknessFactor": 0.1, "attenuationDistance": -1})")),
             f + "attenuationDistance: -1 is not a distance >= 1e-30 (metres)");
  EXPECT_HAS(jsonError(glass(R"({"thicknessFactor": 0.1, "attenuationDistance": 0})")),
             f + "attenuationDistance: 0 is not a distance >= 1e-30");
  EXPECT_HAS(jsonError(glass(R"({"thicknessFactor": 0.1, "attenuationDistance": 1e-40})")),
             f + "attenuationDistance: 1e-40 is not a distance >= 1e-30");
  EXPECT_HAS(jsonError(glass(R"({"attenuationDistance": "far"})")), f + "attenuationDistance: must be a number");
  EXPECT_HAS(jsonError(glass(R"({"attenuationColor": [0.5, -0.1, 0]})")), f + "attenuationColor[1]: -0.1 is not in [0, 1]");
  EXPECT_HAS(jsonError(glass(R"({"attenuationColor": [0.5, 0.5, 1.5]})")), f + "attenuationColor[2]: 1.5 is not in [0, 1]");
  EXPECT_HAS(jsonError(glass(R"({"attenuationColor": [0.5, 0.5]})")), f + "attenuationColor: expected 3 numbers");
  EXPECT_HAS(jsonError(glass(R"({"attenuationColor": [0.5, "red", 0.5]})")), f + "attenuationColor: expected 3 numbers");
  // (JSON has no NaN or infinity; the checks above reject them too: !(d >= 1e-30), !(0 <= c <= 1).)
}

TEST(GltfTextures, ImageSourcesBufferViewDataUriAndExternalFile) {
  // GLB with images in bufferViews (the fuzz seed made by make_test_assets): a PNG and a JPEG.
  Scene glb = loadScene(kSource + "/tests/fuzz/corpus/gltf/textured_bufferview_images.glb");
  ASSERT_EQ(glb.images.size(), 2u);
  EXPECT_EQ(glb.images[0].width, 5u);
  EXPECT_EQ(glb.images[0].rgba[3], a8(0, 0));
  EXPECT_EQ(glb.images[1].width, 16u);
  EXPECT_EQ(glb.materials[0].alphaMode, AlphaMode::Mask);
  EXPECT_TRUE(glb.materials[0].doubleSided);
  // External files inside the scene folder, with URL-encoded names.
  TempDir dir;
  dir.write("my image.png", readBytes(kImages + "rgb8.png"));
  Json j = texturedQuad();
  j["images"][0] = {{"uri", "my%20image.png"}};
  {
    std::string text = j.dump();
    std::ofstream(dir.path + "/scene.gltf") << text;
  }
  Scene s = loadScene(dir.path + "/scene.gltf");
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_EQ(s.images[0].name, "my%20image.png");
  EXPECT_EQ(s.images[0].rgba[4 * 6 + 1], g8(1, 1));
}

TEST(GltfTextures, BadImagesNameTheFileTheImageAndTheSlot) {
  TempDir dir;
  auto sceneError = [&](const Json& j, const LoadOptions& options = {}) {
    std::ofstream(dir.path + "/scene.gltf") << j.dump();
    return errorOf([&] { loadScene(dir.path + "/scene.gltf", options); });
  };
  // Missing file.
  Json j = texturedQuad();
  j["images"][0] = {{"uri", "missing.png"}, {"name", "wood"}};
  std::string e = sceneError(j);
  EXPECT_HAS(e, "scene.gltf: images[0].uri \"missing.png\": No such file or directory (used by materials[0] "
                "\"mat\".pbrMetallicRoughness.baseColorTexture (textures[0]))");
  // Corrupt PNG (flipped IDAT byte), by data URI.
  Bytes png = readBytes(kImages + "rgba8.png");
  for (std::size_t i = 8; i + 4 < png.size(); ++i)
    if (std::memcmp(&png[i], "IDAT", 4) == 0) png[i + 6] ^= 0x55;
  j = texturedQuad();
  j["images"][0] = {{"uri", dataUri(png, "image/png")}, {"name", "wood"}};
  e = jsonError(j);
  EXPECT_HAS(e, "mem.gltf: images[0] \"wood\", used by materials[0] \"mat\".pbrMetallicRoughness.baseColorTexture "
                "(textures[0]): PNG: corrupt");
  // Truncated JPEG, external.
  Bytes jpeg = readBytes(kImages + "rgb444.jpg");
  dir.write("cut.jpg", Bytes(jpeg.begin(), jpeg.begin() + 300));
  j = texturedQuad();
  j["images"][0] = {{"uri", "cut.jpg"}};
  e = sceneError(j);
  EXPECT_HAS(e, "scene.gltf: images[0] (uri \"cut.jpg\"), used by materials[0] \"mat\"");
  EXPECT_HAS(e, "JPEG: corrupt");
  // Too large for the caps: one image, and the scene's total.
  LoadOptions small;
  small.maxImagePixels = 10;
  e = jsonError(texturedQuad(), small);
  EXPECT_HAS(e, "mem.gltf: images[0], used by materials[0] \"mat\"");
  EXPECT_HAS(e, "PNG: 5 x 3 = 15 pixels exceeds the limit of 10 pixels per image");
  small = LoadOptions{};
  small.maxTotalImagePixels = 20;
  Json two = texturedQuad({"rgba8.png", "grey8.png"});
  two["textures"].push_back({{"source", 1}});
  two["materials"][0]["emissiveTexture"] = {{"index", 1}};
  e = jsonError(two, small);
  EXPECT_HAS(e, "images[1]");
  EXPECT_HAS(e, "the scene's images add up to more than the limit of 20 pixels");
  // Not PNG or JPEG.
  const Bytes webp = {'R', 'I', 'F', 'F', 0x10, 0, 0, 0, 'W', 'E', 'B', 'P', 'V', 'P', '8', ' '};
  j = texturedQuad();
  j["images"][0] = {{"uri", dataUri(webp, "image/webp")}};
  e = jsonError(j);
  EXPECT_HAS(e, "images[0], used by");
  EXPECT_HAS(e, "WebP");
  // URIs that leave the folder, and external files of a scene in memory.
  j = texturedQuad();
  j["images"][0] = {{"uri", "../secret.png"}};
  EXPECT_HAS(sceneError(j), "scene.gltf: images[0].uri \"../secret.png\": \"..\" would leave the scene directory");
  EXPECT_HAS(jsonError(j), "external URIs are refused for a scene loaded from memory");
  j["images"][0] = {{"uri", "data:image/png,notbase64"}};
  EXPECT_HAS(jsonError(j), "only base64 data: URIs");
  // Structure errors.
  j["images"][0] = {{"uri", "a.png"}, {"bufferView", 0}};
  EXPECT_HAS(jsonError(j), "mem.gltf: images[0]: needs exactly one of \"uri\" and \"bufferView\"");
  j = texturedQuad();
  j["textures"][0]["source"] = 5;
  EXPECT_HAS(jsonError(j), "mem.gltf: textures[0].source: 5 is out of range (the file has 1 images)");
  j = texturedQuad();
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 4;
  EXPECT_HAS(jsonError(j), "materials[0] \"mat\".pbrMetallicRoughness.baseColorTexture.index: 4 is out of range");
  j = texturedQuad();
  j["images"][0] = {{"bufferView", 7}};
  EXPECT_HAS(jsonError(j), "bufferView: 7 is out of range");
}

TEST(GltfTextures, UnusedImagesAreNotDecoded) {
  // An image no material uses may be anything: it is never read.
  Json j = texturedQuad();
  j["materials"][0] = Json::object();
  j["images"][0] = {{"uri", dataUri({1, 2, 3})}};
  Scene s = loadJson(j);
  EXPECT_TRUE(s.images.empty());
}

TEST(GltfTextures, UnsupportedTextureFormatsWarnOrFail) {
  // A texture with only a KTX2 source: the factor alone, with a warning naming the extension.
  Json j = texturedQuad();
  j["extensionsUsed"] = {"KHR_texture_basisu"};
  j["textures"][0] = Json::parse(R"({"extensions": {"KHR_texture_basisu": {"source": 0}}})");
  Scene s = loadJson(j);
  EXPECT_FALSE(s.materials[0].baseColorTexture.present());
  EXPECT_TRUE(hasWarning(s, "textures[0] has no PNG or JPEG source (only KHR_texture_basisu)"));
  EXPECT_TRUE(hasWarning(s, "extension KHR_texture_basisu is not supported; ignored"));
  // Required: an error naming the extension and why.
  j["extensionsRequired"] = {"KHR_texture_basisu"};
  std::string e = jsonError(j);
  EXPECT_HAS(e, "mem.gltf: extensionsRequired: \"KHR_texture_basisu\" is not supported: KTX2 / Basis Universal");
  j["extensionsRequired"] = {"EXT_texture_webp"};
  EXPECT_HAS(jsonError(j), "\"EXT_texture_webp\" is not supported: WebP textures");
  j["extensionsRequired"] = {"KHR_materials_pbrSpecularGlossiness"};
  EXPECT_HAS(jsonError(j), "specular-glossiness");
}

// ---------------------------------------------------------------------------------------------
// Texture coordinates, tangents, compressed geometry.

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, eps) << what;
  EXPECT_NEAR(a.y, b.y, eps) << what;
  EXPECT_NEAR(a.z, b.z, eps) << what;
}

// tools/make_test_assets.cpp's grid: vertex (i, j) of 5 x 4 at x = i / 2, y = j / 2.
glm::vec2 gridUv0(const glm::vec3& p) { return {p.x / 2.0f, 1.0f - p.y / 1.5f}; }
glm::vec2 gridUv1(const glm::vec3& p) { return {std::round(p.x * 2.0f), std::round(p.y * 2.0f)}; }

TEST(GltfGeometry, TexcoordsAndTangentsPerCorner) {
  Scene s = loadScene(kGltf + "grid_plain.gltf");
  ASSERT_EQ(s.triangleCount(), 24u);
  ASSERT_EQ(s.texcoords0.size(), 72u);
  ASSERT_EQ(s.texcoords1.size(), 72u);
  ASSERT_EQ(s.tangents.size(), 72u);
  for (std::size_t c = 0; c < 72; ++c) {
    const glm::vec3 p = s.positions[c];
    EXPECT_NEAR(s.texcoords0[c].x, gridUv0(p).x, 1e-6f);
    EXPECT_NEAR(s.texcoords0[c].y, gridUv0(p).y, 1e-6f);
    EXPECT_EQ(s.texcoords1[c], gridUv1(p));
    const glm::vec4 t = s.tangents[c];
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(glm::vec3(t), s.normals[c]), 0.0f, 1e-5f);
    EXPECT_GT(t.x, 0.9f);      // along +x, the direction of increasing u
    EXPECT_EQ(t.w, -1.0f);     // v grows against y: bitangent = -cross(n, t)
  }
  EXPECT_TRUE(s.warnings.empty());
  // A scene without the attributes has none.
  Scene box = loadScene(kSource + "/scenes/cornell-box.glb");
  EXPECT_TRUE(box.texcoords0.empty());
  EXPECT_TRUE(box.texcoords1.empty());
  EXPECT_TRUE(box.tangents.empty());
  EXPECT_TRUE(box.images.empty());
}

TEST(GltfGeometry, MirroringTransformFlipsTangentHandedness) {
  Json j = Json::parse(readBytes(kGltf + "grid_plain.gltf"));
  j["nodes"][0]["scale"] = {-1, 1, 1};
  Scene s = loadJson(j);
  ASSERT_EQ(s.tangents.size(), 72u);
  for (std::size_t c = 0; c < 72; ++c) {
    EXPECT_EQ(s.tangents[c].w, 1.0f);
    EXPECT_LT(s.tangents[c].x, -0.9f);  // u still grows along the mirrored +x, i.e. world -x
    // w cross(n, t) still points the way v grows (world -y).
    glm::vec3 b = s.tangents[c].w * glm::cross(s.normals[c], glm::vec3(s.tangents[c]));
    EXPECT_LT(b.y, -0.9f);
  }
}

// Normal-mapped primitives without TANGENT get generated tangents close to the grid's exact ones.
TEST(GltfGeometry, GeneratedTangentsMatchTheSurface) {
  Scene exact = loadScene(kGltf + "grid_plain.gltf");
  Json j = Json::parse(readBytes(kGltf + "grid_plain.gltf"));
  j["meshes"][0]["primitives"][0]["attributes"].erase("TANGENT");
  j["meshes"][0]["primitives"][0]["material"] = 0;
  j["materials"] = Json::parse(R"([{"normalTexture": {"index": 0}}])");
  j["textures"] = Json::parse(R"([{"source": 0}])");
  j["images"] = {{{"uri", dataUri(readBytes(kImages + "rgb8.png"))}}};
  Scene s = loadJson(j);
  ASSERT_EQ(s.tangents.size(), 72u);
  double worst = 0;
  for (std::size_t c = 0; c < 72; ++c) {
    const glm::vec4 t = s.tangents[c];
    EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(glm::vec3(t), s.normals[c]), 0.0f, 1e-5f);
    EXPECT_EQ(t.w, -1.0f);
    worst = std::max(worst, std::acos(std::min(1.0, double(glm::dot(glm::vec3(t), glm::vec3(exact.tangents[c]))))));
  }
  // A triangle's gradient is a one-sided difference over an edge of h = 0.5: its slope along x is
  // off by at most h / 2 max|z_xx| = 0.25 * 0.1 * 1.3^2 = 0.042 rad (and y-slopes do not tilt
  // the u direction); averaging over a vertex's triangles only lowers it.
  EXPECT_LT(worst, 0.05) << "largest angle to the exact tangent (rad)";
  // The normal map reads TEXCOORD_1 (the grid indices: same directions, u along +x, v along +y):
  // w flips.
  j["materials"][0]["normalTexture"]["texCoord"] = 1;
  s = loadJson(j);
  for (const glm::vec4& t : s.tangents) {
    EXPECT_EQ(t.w, 1.0f);
    EXPECT_GT(t.x, 0.9f);
  }
  // Without that texture coordinate set: arbitrary tangents and a warning.
  j["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_1");
  s = loadJson(j);
  EXPECT_TRUE(hasWarning(s, "its material's normal map reads TEXCOORD_1, which the primitive lacks"));
  for (std::size_t c = 0; c < 72; ++c) EXPECT_NEAR(glm::dot(glm::vec3(s.tangents[c]), s.normals[c]), 0.0f, 1e-5f);
}

TEST(GltfGeometry, TangentGeneratorOnHandMadeTriangles) {
  // A flat quad whose texture is rotated by 90 degrees: u grows along +y, v along +x.
  const glm::vec3 p[6] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const glm::vec3 n[6] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  const glm::vec2 uv[6] = {{0, 0}, {0, 1}, {1, 1}, {0, 0}, {1, 1}, {1, 0}};
  const std::uint32_t vertex[6] = {0, 1, 2, 0, 2, 3};
  glm::vec4 t[6];
  EXPECT_EQ(generateTangents(2, p, n, uv, vertex, 4, t), 0u);
  for (const glm::vec4& x : t) {
    expectNear(glm::vec3(x), {0, 1, 0}, 1e-6f, "tangent");
    EXPECT_EQ(x.w, -1.0f);  // bitangent (v) along +x = -cross(+z, +y)
  }
  // Zero-area texture coordinates: arbitrary tangents, counted.
  const glm::vec2 flat[6] = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f}, {0, 0}, {1, 1}, {1, 0}};
  EXPECT_EQ(generateTangents(2, p, n, flat, vertex, 4, t), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(glm::dot(glm::vec3(t[k]), n[k]), 0.0f, 1e-6f);
  // A vertex shared by a mirrored triangle keeps one frame per side.
  const glm::vec2 mirrored[6] = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {-1, 1}, {0, 1}};
  generateTangents(2, p, n, mirrored, vertex, 4, t);
  // First triangle: u along +x, v along +y = cross(n, t): w = +1. Second: u along -x, v along
  // +y = -cross(n, t): w = -1; vertex 0 (corners 0 and 3) gets each side's own frame.
  EXPECT_EQ(t[0].w, 1.0f);
  EXPECT_EQ(t[3].w, -1.0f);
  expectNear(glm::vec3(t[0]), {1, 0, 0}, 1e-6f, "first side");
  expectNear(glm::vec3(t[3]), {-1, 0, 0}, 1e-6f, "mirrored side");
  EXPECT_NEAR(glm::length(perpendicularTo({0, 0, -1})), 1.0f, 1e-6f);
}

TEST(GltfGeometry, NormalizedAndNonFiniteTexcoords) {
  Json j = texturedQuad();
  j["materials"][0] = Json::object();
  // TEXCOORD_1 as normalized unsigned short (core glTF), TEXCOORD_0 with a NaN and a huge value.
  std::vector<std::uint16_t> u16 = {0, 65535, 32768, 1, 65535, 65535, 0, 0, 0, 0, 0, 0};
  Bytes extra(24);
  std::memcpy(extra.data(), u16.data(), 24);
  Bytes uv = floatBytes({0, 1, 1, 1, 1, 0, NAN, 1, 1e20f, 0, 0, 0});
  Bytes buffer = floatBytes({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0});
  buffer.insert(buffer.end(), uv.begin(), uv.end());
  buffer.insert(buffer.end(), extra.begin(), extra.end());
  j["buffers"][0] = {{"byteLength", buffer.size()}, {"uri", dataUri(buffer)}};
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 120}, {"byteLength", 24}});
  j["accessors"].push_back({{"bufferView", 2}, {"componentType", 5123}, {"normalized", true}, {"count", 6}, {"type", "VEC2"}});
  j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = 2;
  Scene s = loadJson(j);
  ASSERT_EQ(s.texcoords1.size(), 6u);
  EXPECT_EQ(s.texcoords1[0], glm::vec2(0.0f, 1.0f));
  EXPECT_FLOAT_EQ(s.texcoords1[1].x, 32768.0f / 65535.0f);
  EXPECT_FLOAT_EQ(s.texcoords1[1].y, 1.0f / 65535.0f);
  EXPECT_EQ(s.texcoords0[3], glm::vec2(0.0f));  // NaN -> 0
  EXPECT_EQ(s.texcoords0[4], glm::vec2(0.0f));  // 1e20 -> 0
  EXPECT_TRUE(hasWarning(s, "2 texture coordinate(s) not finite or beyond 1e+08; replaced by (0, 0)"));
  EXPECT_TRUE(s.tangents.empty());  // no TANGENT, no normal map
  // Integer texture coordinates that are not normalized need KHR_mesh_quantization.
  j["accessors"][2]["normalized"] = false;
  EXPECT_HAS(jsonError(j), "mem.gltf: accessors[2] (TEXCOORD_1 of meshes[0].primitives[0]): componentType 5123 "
                           "(unsigned short) needs the KHR_mesh_quantization extension");
  j["extensionsUsed"] = {"KHR_mesh_quantization"};
  s = loadJson(j);
  EXPECT_EQ(s.texcoords1[1], glm::vec2(32768.0f, 1.0f));
  j["accessors"][2]["componentType"] = 5125;
  EXPECT_HAS(jsonError(j), "componentType 5125 (unsigned int), expected");
}

TEST(GltfGeometry, PrimitivesWithAndWithoutTheAttributes) {
  // Two primitives; only the second has TEXCOORD_0 and TANGENT: the first's corners get (0, 0)
  // and a tangent perpendicular to their normal.
  Json j = Json::parse(readBytes(kGltf + "grid_plain.gltf"));
  Json bare = j["meshes"][0]["primitives"][0];
  bare["attributes"] = {{"POSITION", bare["attributes"]["POSITION"]}};
  j["meshes"][0]["primitives"] = {bare, j["meshes"][0]["primitives"][0]};
  Scene s = loadJson(j);
  ASSERT_EQ(s.triangleCount(), 48u);
  ASSERT_EQ(s.texcoords0.size(), 144u);
  ASSERT_EQ(s.tangents.size(), 144u);
  for (std::size_t c = 0; c < 72; ++c) {
    EXPECT_EQ(s.texcoords0[c], glm::vec2(0.0f));
    EXPECT_NEAR(glm::dot(glm::vec3(s.tangents[c]), s.normals[c]), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(glm::vec3(s.tangents[c])), 1.0f, 1e-5f);
    EXPECT_EQ(s.tangents[c].w, 1.0f);
  }
  for (std::size_t c = 72; c < 144; ++c) EXPECT_EQ(s.tangents[c].w, -1.0f);
}

// A data URI with its payload replaced by zero bytes (same length, padding kept).
std::string zeroPayload(const std::string& uri) {
  std::string out = uri;
  for (std::size_t i = uri.find(',') + 1; i < out.size(); ++i)
    if (out[i] != '=') out[i] = 'A';
  return out;
}

// Each triangle of `a` matched to the triangle of `b` with the nearest centroid, and each corner
// to the nearest corner: compressed geometry may reorder triangles and rotate their corners.
struct Tolerances {
  float position, normal, uv0, uv1, tangent;
};

void expectSameGrid(const Scene& a, const Scene& b, const Tolerances& tol) {
  ASSERT_EQ(a.triangleCount(), b.triangleCount());
  ASSERT_EQ(a.texcoords0.size(), a.positions.size());
  ASSERT_EQ(a.texcoords1.size(), a.positions.size());
  ASSERT_EQ(a.tangents.size(), a.positions.size());
  for (std::size_t t = 0; t < a.triangleCount(); ++t) {
    const glm::vec3 ca = (a.positions[3 * t] + a.positions[3 * t + 1] + a.positions[3 * t + 2]) / 3.0f;
    std::size_t best = 0;
    float bestDistance = INFINITY;
    for (std::size_t u = 0; u < b.triangleCount(); ++u) {
      const glm::vec3 cb = (b.positions[3 * u] + b.positions[3 * u + 1] + b.positions[3 * u + 2]) / 3.0f;
      if (glm::length(ca - cb) < bestDistance) bestDistance = glm::length(ca - cb), best = u;
    }
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * t + std::size_t(k);
      std::size_t j = 3 * best;
      for (int m = 1; m < 3; ++m)
        if (glm::length(b.positions[3 * best + std::size_t(m)] - a.positions[i]) < glm::length(b.positions[j] - a.positions[i]))
          j = 3 * best + std::size_t(m);
      const std::string where = "triangle " + std::to_string(t) + " corner " + std::to_string(k);
      expectNear(a.positions[i], b.positions[j], tol.position, where + " position");
      expectNear(a.normals[i], b.normals[j], tol.normal, where + " normal");
      EXPECT_NEAR(a.texcoords0[i].x, b.texcoords0[j].x, tol.uv0) << where;
      EXPECT_NEAR(a.texcoords0[i].y, b.texcoords0[j].y, tol.uv0) << where;
      EXPECT_NEAR(a.texcoords1[i].x, b.texcoords1[j].x, tol.uv1) << where;
      EXPECT_NEAR(a.texcoords1[i].y, b.texcoords1[j].y, tol.uv1) << where;
      expectNear(glm::vec3(a.tangents[i]), glm::vec3(b.tangents[j]), tol.tangent, where + " tangent");
      EXPECT_EQ(a.tangents[i].w, b.tangents[j].w) << where;
    }
  }
}

TEST(GltfGeometry, QuantizedDracoAndMeshoptDecodeToTheSameGrid) {
  const Scene plain = loadScene(kGltf + "grid_plain.gltf");
  // KHR_mesh_quantization: positions in steps of 1e-4, normals and tangents in 8 bits.
  Scene q = loadScene(kGltf + "grid_quantized.gltf");
  EXPECT_TRUE(q.warnings.empty()) << q.warnings[0];
  expectSameGrid(q, plain, {5e-5f + 1e-6f, 0.01f, 1e-5f, 0.0f, 0.02f});
  // Draco: 14-bit positions over an extent of 2 (error <= 2 / 2^14 / 2 = 6.1e-5), 10-bit
  // normals, 12-bit texture coordinates (uv1 spans 4) and tangents.
  Scene d = loadScene(kGltf + "grid_draco.gltf");
  EXPECT_TRUE(d.warnings.empty()) << d.warnings[0];
  expectSameGrid(d, plain, {1e-4f, 0.01f, 3e-4f, 1e-3f, 0.01f});
  // meshopt: lossless positions, uv0 and tangents (the triangle codec may rotate a triangle's
  // corners); normals through the 8-bit octahedral filter, uv1 through the exponential filter
  // with 16-bit mantissas.
  Scene m = loadScene(kGltf + "grid_meshopt.gltf");
  EXPECT_TRUE(m.warnings.empty()) << m.warnings[0];
  expectSameGrid(m, plain, {0.0f, 0.02f, 0.0f, 1e-4f, 0.02f});
}

TEST(GltfGeometry, BadCompressedGeometry) {
  // Draco: a damaged bitstream, a missing attribute id, a count that disagrees.
  Json d = Json::parse(readBytes(kGltf + "grid_draco.gltf"));
  {
    Json k = d;
    k["buffers"][0]["uri"] = zeroPayload(k["buffers"][0]["uri"]);
    std::string e = jsonError(k);
    EXPECT_HAS(e, "mem.gltf: meshes[0].primitives[0].extensions.KHR_draco_mesh_compression: Draco:");
    EXPECT_TRUE(asciiClean(e)) << e;
  }
  {
    Json k = d;
    k["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 17;
    EXPECT_HAS(jsonError(k), "KHR_draco_mesh_compression.attributes.NORMAL: Draco: the data has no attribute with unique id 17");
  }
  {
    Json k = d;
    k["accessors"][1]["count"] = 3;
    EXPECT_HAS(jsonError(k), "accessors[1] (NORMAL of meshes[0].primitives[0]): count 3 differs from the 20 points");
  }
  {
    Json k = d;
    k["accessors"][2]["componentType"] = 5123;
    k["accessors"][2]["normalized"] = true;
    EXPECT_HAS(jsonError(k), "Draco: attribute id 2 holds float32, the accessor's componentType needs uint16");
  }
  {
    Json k = d;
    k["meshes"][0]["primitives"][0]["mode"] = 5;
    EXPECT_HAS(jsonError(k), "KHR_draco_mesh_compression: Draco primitives must have mode 4");
  }
  // meshopt: damaged data, parameters that break the extension's rules, a placeholder buffer
  // used by a plain bufferView.
  Json m = Json::parse(readBytes(kGltf + "grid_meshopt.gltf"));
  {
    Json k = m;
    k["buffers"][0]["uri"] = zeroPayload(k["buffers"][0]["uri"]);
    EXPECT_HAS(jsonError(k), "mem.gltf: bufferViews[0].extensions.EXT_meshopt_compression: meshopt: the compressed data is invalid");
  }
  {
    Json k = m;
    k["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteStride"] = 6;
    k["bufferViews"][0].erase("byteStride");
    k["bufferViews"][0]["byteLength"] = 120;
    EXPECT_HAS(jsonError(k), "bufferViews[0].extensions.EXT_meshopt_compression: byteStride 6: ATTRIBUTES needs a multiple of 4");
  }
  {
    Json k = m;
    k["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["mode"] = "ZIP";
    EXPECT_HAS(jsonError(k), "EXT_meshopt_compression.mode: \"ZIP\" (expected ATTRIBUTES, TRIANGLES or INDICES)");
  }
  {
    Json k = m;
    k["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION";
    EXPECT_HAS(jsonError(k), "byteStride 4: the QUATERNION filter needs 8");
  }
  {
    Json k = m;
    k["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 21;
    EXPECT_HAS(jsonError(k), "count 21 x byteStride 12 differs from the bufferView's byteLength 240");
  }
  {
    Json k = m;
    k["bufferViews"][0].erase("extensions");
    EXPECT_HAS(jsonError(k), "mem.gltf: bufferViews[0].buffer: buffers[1] is an EXT_meshopt_compression fallback buffer "
                             "without data, but this bufferView is not compressed");
  }
  {
    // Without the extension required or the fallback flag, a .gltf buffer needs a uri.
    Json k = m;
    k["buffers"][1].erase("extensions");
    k["extensionsRequired"] = {"KHR_mesh_quantization"};
    EXPECT_HAS(jsonError(k), "mem.gltf: buffers[1]: no uri");
  }
}

// ---------------------------------------------------------------------------------------------
// Messages never carry raw bytes of the input.

TEST(GltfMessages, RawBytesAreEscapedAndGlbMagicIsChecked) {
  // A .glb of random bytes: says it is not a GLB, shows the first bytes in hex.
  std::uint32_t seed = 99;
  Bytes random(256);
  for (unsigned char& b : random) b = std::uint8_t((seed = seed * 1664525u + 1013904223u) >> 24);
  random[0] = 0x9b;  // a C1 control / ESC-like byte first
  std::string e = errorOf([&] { loadSceneFromMemory(random.data(), random.size(), "random.glb"); });
  EXPECT_HAS(e, "random.glb: not a GLB file: it starts with 9b ");
  EXPECT_HAS(e, "a GLB starts with the magic \"glTF\"");
  EXPECT_TRUE(asciiClean(e)) << e;
  // The same bytes under another name: neither JSON nor GLB.
  e = errorOf([&] { loadSceneFromMemory(random.data(), random.size(), "random.gltf"); });
  EXPECT_HAS(e, "random.gltf: neither glTF JSON");
  EXPECT_TRUE(asciiClean(e)) << e;
  // Malformed JSON with a raw byte right where the parser stops.
  std::string bad = "{\"asset\": \x1b[31m}";
  e = errorOf([&] { loadSceneFromMemory(reinterpret_cast<const unsigned char*>(bad.data()), bad.size(), "esc.gltf"); });
  EXPECT_HAS(e, "esc.gltf: malformed JSON");
  EXPECT_TRUE(asciiClean(e)) << e;
  // Invalid UTF-8 inside a JSON string.
  bad = "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{\"name\": \"\xc3\x28\"}]}";
  e = errorOf([&] { loadSceneFromMemory(reinterpret_cast<const unsigned char*>(bad.data()), bad.size(), "utf.gltf"); });
  EXPECT_TRUE(asciiClean(e)) << e;
  // Escaped control characters in names reach messages as \xNN; valid UTF-8 stays readable.
  Json j = texturedQuad();
  j["materials"][0]["name"] = "K\xc3\xb6rper\x1b[2J";
  j["textures"][0]["source"] = 9;
  j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 9;
  e = jsonError(j);
  EXPECT_HAS(e, "materials[0] \"K\xc3\xb6rper\\x1b[2J\"");
  // A wrong GLB version and a truncated GLB still say so.
  Bytes glb = readBytes(kSource + "/tests/fuzz/corpus/gltf/textured_bufferview_images.glb");
  glb[4] = 1;
  EXPECT_HAS(errorOf([&] { loadSceneFromMemory(glb.data(), glb.size(), "v1.glb"); }), "v1.glb: GLB: version 1");
}

// The textured test scene for the GPU side loads with its three images and generated tangents.
TEST(GltfTextures, TexturedQuadScene) {
  Scene s = loadScene(kSource + "/scenes/tests/textured/textured_quad.gltf");
  ASSERT_EQ(s.triangleCount(), 2u);
  ASSERT_EQ(s.images.size(), 3u);
  const Material& m = s.materials[0];
  EXPECT_TRUE(m.baseColorTexture.present());
  EXPECT_EQ(m.baseColorTexture.magFilter, FilterMode::Nearest);
  EXPECT_EQ(m.normalTexture.wrapS, WrapMode::ClampToEdge);
  EXPECT_EQ(m.normalTexture.minFilter, FilterMode::Linear);  // LINEAR_MIPMAP_LINEAR without mipmaps
  EXPECT_EQ(s.images[size_t(m.baseColorTexture.image)].width, 8u);
  EXPECT_EQ(s.images[size_t(m.normalTexture.image)].width, 32u);
  EXPECT_EQ(s.images[size_t(m.emissiveTexture.image)].width, 16u);
  EXPECT_FLOAT_EQ(apply(m.baseColorTexture.transform, 1, 1).x, 2.0f);
  ASSERT_EQ(s.tangents.size(), 6u);
  for (const glm::vec4& t : s.tangents) {
    expectNear(glm::vec3(t), {1, 0, 0}, 1e-6f, "quad tangent");
    EXPECT_EQ(t.w, -1.0f);
  }
  EXPECT_TRUE(s.hasCamera);
}

}  // namespace
}  // namespace nusselt
