// make_test_assets.cpp: writes the generated test data of issue 18 (textures, images, compressed
// geometry). Run through tools/make_test_assets.sh, once; the outputs are committed:
//   tests/data/images/       PNGs of every colour type and bit depth and JPEGs, whose texel
//                            values follow the formulas below (test_textures.cpp checks them)
//   tests/data/gltf/grid_*.gltf  one small curved grid as plain floats, KHR_mesh_quantization,
//                            KHR_draco_mesh_compression and EXT_meshopt_compression
//   scenes/tests/textured/   a quad with a checker base colour, a normal map and an emissive
//                            texture (for the GPU side of issue 18)
//   tests/fuzz/corpus/image, tests/fuzz/corpus/gltf: copies as fuzzing seeds, plus a GLB with
//                            images in bufferViews
// Everything comes from Debian's encoders: libpng, libjpeg-turbo, Draco, meshoptimizer.
#include <draco/compression/encode.h>
#include <draco/compression/decode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>
#include <png.h>
#include <turbojpeg.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

using Json = nlohmann::json;
using Bytes = std::vector<unsigned char>;

namespace {

std::string root;

void writeFile(const std::string& rel, const Bytes& data) {
  std::ofstream f(root + "/" + rel, std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + rel);
  f.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
}

void writeText(const std::string& rel, const std::string& text) { writeFile(rel, Bytes(text.begin(), text.end())); }

std::string base64(const Bytes& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    unsigned v = unsigned(in[i]) << 16;
    if (i + 1 < in.size()) v |= unsigned(in[i + 1]) << 8;
    if (i + 2 < in.size()) v |= in[i + 2];
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? t[v & 63] : '=';
  }
  return out;
}

// ---- PNG ----

void pngWrite(png_structp png, png_bytep data, png_size_t n) {
  Bytes* out = static_cast<Bytes*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + n);
}
void pngFlush(png_structp) {}

struct PngSpec {
  int width, height, colorType, bitDepth;
  bool interlaced = false;
  std::vector<png_color> palette;
  std::vector<png_byte> trnsAlpha;  // palette tRNS
  bool trnsColour = false;          // RGB colour key (value of pixel (0, 0))
  png_color_16 trnsValue{};
  double gamma = 0;                 // write a gAMA chunk when > 0
};

// rows: packed samples as the PNG stores them (big-endian 16-bit).
Bytes encodePng(const PngSpec& s, const std::vector<Bytes>& rows) {
  Bytes out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) throw std::runtime_error("libpng write failed");
  png_set_write_fn(png, &out, &pngWrite, &pngFlush);
  png_set_IHDR(png, info, png_uint_32(s.width), png_uint_32(s.height), s.bitDepth, s.colorType,
               s.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (!s.palette.empty()) png_set_PLTE(png, info, s.palette.data(), int(s.palette.size()));
  if (!s.trnsAlpha.empty()) png_set_tRNS(png, info, s.trnsAlpha.data(), int(s.trnsAlpha.size()), nullptr);
  if (s.trnsColour) {
    png_color_16 v = s.trnsValue;
    png_set_tRNS(png, info, nullptr, 0, &v);
  }
  if (s.gamma > 0) png_set_gAMA(png, info, s.gamma);
  std::vector<png_bytep> pointers;
  for (const Bytes& r : rows) pointers.push_back(const_cast<png_bytep>(r.data()));
  png_set_rows(png, info, pointers.data());
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

// The test images' formulas (tests/unit/test_textures.cpp has the same ones). 5 x 3 pixels.
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

void put16(Bytes& row, int v) {
  row.push_back(png_byte(v >> 8));
  row.push_back(png_byte(v & 255));
}

// Packs sub-byte samples, most significant bits first.
Bytes packRow(const std::vector<int>& samples, int bits) {
  Bytes row((samples.size() * std::size_t(bits) + 7) / 8, 0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    std::size_t bit = i * std::size_t(bits);
    row[bit / 8] |= png_byte(samples[i] << (8 - bits - int(bit % 8)));
  }
  return row;
}

std::vector<std::pair<std::string, Bytes>> makePngs() {
  std::vector<std::pair<std::string, Bytes>> out;
  auto rowsOf = [](auto fn) {
    std::vector<Bytes> rows;
    for (int y = 0; y < H; ++y) {
      Bytes r;
      for (int x = 0; x < W; ++x) fn(r, x, y);
      rows.push_back(r);
    }
    return rows;
  };
  auto subByte = [](int bits, auto value) {
    std::vector<Bytes> rows;
    for (int y = 0; y < H; ++y) {
      std::vector<int> samples;
      for (int x = 0; x < W; ++x) samples.push_back(value(x, y));
      rows.push_back(packRow(samples, bits));
    }
    return rows;
  };
  out.push_back({"grey1.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY, 1}, subByte(1, [](int x, int y) { return (x + y) % 2; }))});
  out.push_back({"grey4.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY, 4}, subByte(4, [](int x, int y) { return (x + 5 * y) % 16; }))});
  out.push_back({"grey8.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY, 8},
                                        rowsOf([](Bytes& r, int x, int y) { r.push_back(png_byte(grey8(x, y))); }))});
  out.push_back({"grey16.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY, 16},
                                         rowsOf([](Bytes& r, int x, int y) { put16(r, grey16(x, y)); }))});
  out.push_back({"greyalpha8.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY_ALPHA, 8}, rowsOf([](Bytes& r, int x, int y) {
                                               r.push_back(png_byte(grey8(x, y)));
                                               r.push_back(png_byte(a8(x, y)));
                                             }))});
  out.push_back({"greyalpha16.png", encodePng({W, H, PNG_COLOR_TYPE_GRAY_ALPHA, 16}, rowsOf([](Bytes& r, int x, int y) {
                                                put16(r, grey16(x, y));
                                                put16(r, a16(x, y));
                                              }))});
  {
    PngSpec s{W, H, PNG_COLOR_TYPE_PALETTE, 2};
    s.palette = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {10, 20, 30}};
    s.trnsAlpha = {128, 0};
    out.push_back({"palette2_trns.png", encodePng(s, subByte(2, [](int x, int y) { return (x + y) % 4; }))});
  }
  {
    PngSpec s{W, H, PNG_COLOR_TYPE_PALETTE, 8};
    for (int i = 0; i < 15; ++i) s.palette.push_back({png_byte(i * 17), png_byte(255 - i * 17), png_byte(i * 5)});
    out.push_back({"palette8.png", encodePng(s, rowsOf([](Bytes& r, int x, int y) { r.push_back(png_byte(x + W * y)); }))});
  }
  auto rgb8 = [](Bytes& r, int x, int y) {
    r.push_back(png_byte(r8(x, y)));
    r.push_back(png_byte(g8(x, y)));
    r.push_back(png_byte(b8(x, y)));
  };
  auto rgba8 = [&](Bytes& r, int x, int y) {
    rgb8(r, x, y);
    r.push_back(png_byte(a8(x, y)));
  };
  auto rgb16 = [](Bytes& r, int x, int y) {
    put16(r, r16(x, y));
    put16(r, g16(x, y));
    put16(r, b16(x, y));
  };
  out.push_back({"rgb8.png", encodePng({W, H, PNG_COLOR_TYPE_RGB, 8}, rowsOf(rgb8))});
  out.push_back({"rgb16.png", encodePng({W, H, PNG_COLOR_TYPE_RGB, 16}, rowsOf(rgb16))});
  out.push_back({"rgba8.png", encodePng({W, H, PNG_COLOR_TYPE_RGBA, 8}, rowsOf(rgba8))});
  out.push_back({"rgba16.png", encodePng({W, H, PNG_COLOR_TYPE_RGBA, 16}, rowsOf([&](Bytes& r, int x, int y) {
                                           rgb16(r, x, y);
                                           put16(r, a16(x, y));
                                         }))});
  {
    PngSpec s{W, H, PNG_COLOR_TYPE_RGBA, 8};
    s.interlaced = true;
    out.push_back({"rgba8_interlaced.png", encodePng(s, rowsOf(rgba8))});
  }
  {
    PngSpec s{W, H, PNG_COLOR_TYPE_RGB, 8};
    s.trnsColour = true;
    s.trnsValue.red = png_uint_16(r8(0, 0));
    s.trnsValue.green = png_uint_16(g8(0, 0));
    s.trnsValue.blue = png_uint_16(b8(0, 0));
    out.push_back({"rgb8_trns.png", encodePng(s, rowsOf(rgb8))});
  }
  {
    // A gAMA chunk of 1.0 (linear data): glTF says to ignore it; the values must not change.
    PngSpec s{W, H, PNG_COLOR_TYPE_RGB, 8};
    s.gamma = 1.0;
    out.push_back({"rgb8_gamma1.png", encodePng(s, rowsOf(rgb8))});
  }
  return out;
}

// ---- JPEG ----

// 16 x 16, four flat 8 x 8 blocks (JPEG reproduces flat blocks to within a code value or two).
const unsigned char kBlockColours[4][3] = {{200, 30, 40}, {20, 180, 60}, {40, 50, 220}, {250, 250, 250}};

Bytes encodeJpeg(bool grey, bool progressive, int subsamp) {
  const int n = 16;
  Bytes pixels;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const unsigned char* c = kBlockColours[(y / 8) * 2 + x / 8];
      if (grey) pixels.push_back(c[0]);
      else pixels.insert(pixels.end(), c, c + 3);
    }
  tjhandle tj = tjInitCompress();
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  int flags = TJFLAG_ACCURATEDCT | (progressive ? TJFLAG_PROGRESSIVE : 0);
  if (tjCompress2(tj, pixels.data(), n, 0, n, grey ? TJPF_GRAY : TJPF_RGB, &jpeg, &size, grey ? TJSAMP_GRAY : subsamp,
                  95, flags) != 0)
    throw std::runtime_error(std::string("tjCompress2: ") + tjGetErrorStr2(tj));
  Bytes out(jpeg, jpeg + size);
  tjFree(jpeg);
  tjDestroy(tj);
  return out;
}

// ---- the grid mesh ----

// NX x NY vertices over x in [0, 2], y in [0, 1.5], z = 0.1 sin(1.3 x) cos(2 y), two triangles
// per cell, counter-clockwise seen from +z.
const int NX = 5, NY = 4;

struct Grid {
  std::vector<float> positions, normals, uv0, uv1, tangents;  // 3, 3, 2, 2, 4 per vertex
  std::vector<unsigned> indices;
};

Grid makeGrid() {
  Grid g;
  for (int j = 0; j < NY; ++j)
    for (int i = 0; i < NX; ++i) {
      const double x = 2.0 * i / (NX - 1), y = 1.5 * j / (NY - 1);
      const double z = 0.1 * std::sin(1.3 * x) * std::cos(2 * y);
      const double dzdx = 0.13 * std::cos(1.3 * x) * std::cos(2 * y), dzdy = -0.2 * std::sin(1.3 * x) * std::sin(2 * y);
      double n[3] = {-dzdx, -dzdy, 1}, l = std::sqrt(n[0] * n[0] + n[1] * n[1] + 1);
      double t[3] = {1, 0, dzdx}, lt = std::sqrt(1 + dzdx * dzdx);
      g.positions.insert(g.positions.end(), {float(x), float(y), float(z)});
      g.normals.insert(g.normals.end(), {float(n[0] / l), float(n[1] / l), float(n[2] / l)});
      // u grows with x, v grows downwards in the image, i.e. against y.
      g.uv0.insert(g.uv0.end(), {float(x / 2), float(1 - y / 1.5)});
      g.uv1.insert(g.uv1.end(), {float(i), float(j)});
      // dP/du (u = x / 2), orthogonalised against n; bitangent dP/dv = -dP/dy: w = -1 with
      // B = w cross(n, t), since cross(n, t) points along +y.
      double tn = (t[0] * n[0] + t[1] * n[1] + t[2] * n[2]) / (l * l);
      double o[3] = {t[0] - tn * n[0], t[1] - tn * n[1], t[2] - tn * n[2]};
      double lo = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
      (void)lt;
      g.tangents.insert(g.tangents.end(), {float(o[0] / lo), float(o[1] / lo), float(o[2] / lo), -1.0f});
    }
  for (int j = 0; j + 1 < NY; ++j)
    for (int i = 0; i + 1 < NX; ++i) {
      unsigned a = unsigned(j * NX + i), b = a + 1, c = a + NX + 1, d = a + NX;
      g.indices.insert(g.indices.end(), {a, b, c, a, c, d});
    }
  return g;
}

template <typename T>
Bytes raw(const std::vector<T>& v) {
  Bytes out(v.size() * sizeof(T));
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

void pad4(Bytes& b) {
  while (b.size() % 4) b.push_back(0);
}

// Appends `data` to `buffer` as a new bufferView; returns its index.
int addView(Json& g, Bytes& buffer, const Bytes& data, int stride = 0, int target = 0) {
  pad4(buffer);
  Json v = {{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", data.size()}};
  if (stride) v["byteStride"] = stride;
  if (target) v["target"] = target;
  buffer.insert(buffer.end(), data.begin(), data.end());
  g["bufferViews"].push_back(v);
  return int(g["bufferViews"].size()) - 1;
}

int addAccessor(Json& g, int view, int componentType, int count, const char* type, bool normalized = false) {
  Json a = {{"componentType", componentType}, {"count", count}, {"type", type}};
  if (view >= 0) a["bufferView"] = view;
  if (normalized) a["normalized"] = true;
  g["accessors"].push_back(a);
  return int(g["accessors"].size()) - 1;
}

Json gridDocument(const char* generator) {
  return Json{{"asset", {{"version", "2.0"}, {"generator", generator}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}}}},
              {"meshes", {{{"primitives", {{{"attributes", Json::object()}, {"mode", 4}}}}}}},
              {"accessors", Json::array()},
              {"bufferViews", Json::array()},
              {"buffers", Json::array()}};
}

std::string finish(Json& g, Bytes& buffer) {
  pad4(buffer);
  g["buffers"].push_back({{"byteLength", buffer.size()}, {"uri", "data:application/octet-stream;base64," + base64(buffer)}});
  return g.dump(1) + "\n";
}

std::string gridPlain(const Grid& m) {
  Json g = gridDocument("nusselt tools/make_test_assets.cpp: plain floats");
  Bytes buf;
  const int n = int(m.positions.size() / 3);
  Json& attr = g["meshes"][0]["primitives"][0]["attributes"];
  attr["POSITION"] = addAccessor(g, addView(g, buf, raw(m.positions)), 5126, n, "VEC3");
  attr["NORMAL"] = addAccessor(g, addView(g, buf, raw(m.normals)), 5126, n, "VEC3");
  attr["TEXCOORD_0"] = addAccessor(g, addView(g, buf, raw(m.uv0)), 5126, n, "VEC2");
  attr["TEXCOORD_1"] = addAccessor(g, addView(g, buf, raw(m.uv1)), 5126, n, "VEC2");
  attr["TANGENT"] = addAccessor(g, addView(g, buf, raw(m.tangents)), 5126, n, "VEC4");
  std::vector<unsigned short> idx(m.indices.begin(), m.indices.end());
  g["meshes"][0]["primitives"][0]["indices"] = addAccessor(g, addView(g, buf, raw(idx)), 5123, int(idx.size()), "SCALAR");
  return finish(g, buf);
}

// KHR_mesh_quantization: POSITION int16 (units of 1e-4, the node scales back), NORMAL and
// TANGENT int8 normalized, TEXCOORD_0 uint16 normalized, TEXCOORD_1 uint8 integers; each
// element padded to 4 bytes as glTF requires.
std::string gridQuantized(const Grid& m) {
  Json g = gridDocument("nusselt tools/make_test_assets.cpp: KHR_mesh_quantization");
  g["extensionsUsed"] = {"KHR_mesh_quantization"};
  g["extensionsRequired"] = {"KHR_mesh_quantization"};
  g["nodes"][0]["scale"] = {1e-4, 1e-4, 1e-4};
  Bytes buf;
  const int n = int(m.positions.size() / 3);
  std::vector<short> pos;
  std::vector<signed char> nrm, tan;
  std::vector<unsigned short> uv0;
  std::vector<unsigned char> uv1;
  for (int v = 0; v < n; ++v) {
    for (int k = 0; k < 3; ++k) pos.push_back(short(std::lround(m.positions[3 * v + k] * 1e4)));
    pos.push_back(0);
    for (int k = 0; k < 3; ++k) nrm.push_back((signed char)std::lround(m.normals[3 * v + k] * 127));
    nrm.push_back(0);
    for (int k = 0; k < 4; ++k) tan.push_back((signed char)std::lround(m.tangents[4 * v + k] * 127));
    for (int k = 0; k < 2; ++k) uv0.push_back((unsigned short)std::lround(m.uv0[2 * v + k] * 65535));
    for (int k = 0; k < 2; ++k) uv1.push_back((unsigned char)std::lround(m.uv1[2 * v + k]));
    uv1.push_back(0);
    uv1.push_back(0);
  }
  Json& attr = g["meshes"][0]["primitives"][0]["attributes"];
  attr["POSITION"] = addAccessor(g, addView(g, buf, raw(pos), 8), 5122, n, "VEC3");
  attr["NORMAL"] = addAccessor(g, addView(g, buf, raw(nrm), 4), 5120, n, "VEC3", true);
  attr["TANGENT"] = addAccessor(g, addView(g, buf, raw(tan)), 5120, n, "VEC4", true);
  attr["TEXCOORD_0"] = addAccessor(g, addView(g, buf, raw(uv0)), 5123, n, "VEC2", true);
  attr["TEXCOORD_1"] = addAccessor(g, addView(g, buf, raw(uv1), 4), 5121, n, "VEC2");
  std::vector<unsigned char> idx(m.indices.begin(), m.indices.end());
  g["meshes"][0]["primitives"][0]["indices"] = addAccessor(g, addView(g, buf, raw(idx)), 5121, int(idx.size()), "SCALAR");
  return finish(g, buf);
}

// KHR_draco_mesh_compression: every attribute in the Draco data (TANGENT as a generic one).
std::string gridDraco(const Grid& m) {
  const int faces = int(m.indices.size() / 3);
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(faces);
  const int aPos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int aNrm = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  const int aUv0 = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  const int aUv1 = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  const int aTan = builder.AddAttribute(draco::GeometryAttribute::GENERIC, 4, draco::DT_FLOAT32);
  for (int f = 0; f < faces; ++f) {
    const unsigned* c = &m.indices[3 * std::size_t(f)];
    draco::FaceIndex fi(f);
    builder.SetAttributeValuesForFace(aPos, fi, &m.positions[3 * c[0]], &m.positions[3 * c[1]], &m.positions[3 * c[2]]);
    builder.SetAttributeValuesForFace(aNrm, fi, &m.normals[3 * c[0]], &m.normals[3 * c[1]], &m.normals[3 * c[2]]);
    builder.SetAttributeValuesForFace(aUv0, fi, &m.uv0[2 * c[0]], &m.uv0[2 * c[1]], &m.uv0[2 * c[2]]);
    builder.SetAttributeValuesForFace(aUv1, fi, &m.uv1[2 * c[0]], &m.uv1[2 * c[1]], &m.uv1[2 * c[2]]);
    builder.SetAttributeValuesForFace(aTan, fi, &m.tangents[4 * c[0]], &m.tangents[4 * c[1]], &m.tangents[4 * c[2]]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 10);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 12);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, 12);
  draco::EncoderBuffer encoded;
  draco::Status status = encoder.EncodeMeshToBuffer(*mesh, &encoded);
  if (!status.ok()) throw std::runtime_error("Draco: " + status.error_msg_string());
  Bytes data(encoded.data(), encoded.data() + encoded.size());
  // The accessors' counts are those of the decoded mesh.
  draco::DecoderBuffer in;
  in.Init(encoded.data(), encoded.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) throw std::runtime_error("Draco: " + decoded.status().error_msg_string());
  const int points = int(decoded.value()->num_points()), decodedFaces = int(decoded.value()->num_faces());

  Json g = gridDocument("nusselt tools/make_test_assets.cpp: KHR_draco_mesh_compression");
  g["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  g["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  Bytes buf;
  Json& prim = g["meshes"][0]["primitives"][0];
  Json& attr = prim["attributes"];
  attr["POSITION"] = addAccessor(g, -1, 5126, points, "VEC3");
  attr["NORMAL"] = addAccessor(g, -1, 5126, points, "VEC3");
  attr["TEXCOORD_0"] = addAccessor(g, -1, 5126, points, "VEC2");
  attr["TEXCOORD_1"] = addAccessor(g, -1, 5126, points, "VEC2");
  attr["TANGENT"] = addAccessor(g, -1, 5126, points, "VEC4");
  prim["indices"] = addAccessor(g, -1, 5123, 3 * decodedFaces, "SCALAR");
  prim["extensions"]["KHR_draco_mesh_compression"] = {
      {"bufferView", addView(g, buf, data)},
      {"attributes",
       {{"POSITION", mesh->attribute(aPos)->unique_id()},
        {"NORMAL", mesh->attribute(aNrm)->unique_id()},
        {"TEXCOORD_0", mesh->attribute(aUv0)->unique_id()},
        {"TEXCOORD_1", mesh->attribute(aUv1)->unique_id()},
        {"TANGENT", mesh->attribute(aTan)->unique_id()}}}};
  return finish(g, buf);
}

// EXT_meshopt_compression with a placeholder fallback buffer: POSITION float (no filter),
// NORMAL int8 normalized by the OCTAHEDRAL filter (with KHR_mesh_quantization), TEXCOORD_0 float
// (no filter), TEXCOORD_1 float by the EXPONENTIAL filter, TANGENT float, indices by TRIANGLES.
std::string gridMeshopt(const Grid& m) {
  Json g = gridDocument("nusselt tools/make_test_assets.cpp: EXT_meshopt_compression");
  g["extensionsUsed"] = {"EXT_meshopt_compression", "KHR_mesh_quantization"};
  g["extensionsRequired"] = {"EXT_meshopt_compression", "KHR_mesh_quantization"};
  const std::size_t n = m.positions.size() / 3;
  Bytes compressed;
  std::size_t fallbackSize = 0;
  auto view = [&](const void* elements, std::size_t count, std::size_t stride, const char* mode, const char* filter,
                  int target) {
    Bytes enc;
    if (std::string(mode) == "ATTRIBUTES") {
      enc.resize(meshopt_encodeVertexBufferBound(count, stride));
      enc.resize(meshopt_encodeVertexBuffer(enc.data(), enc.size(), elements, count, stride));
    } else {
      enc.resize(meshopt_encodeIndexBufferBound(count, n));
      enc.resize(meshopt_encodeIndexBuffer(enc.data(), enc.size(), static_cast<const unsigned*>(elements), count));
    }
    pad4(compressed);
    Json ext = {{"buffer", 0}, {"byteOffset", compressed.size()}, {"byteLength", enc.size()}, {"byteStride", stride},
                {"count", count}, {"mode", mode}};
    if (std::string(filter) != "NONE") ext["filter"] = filter;
    compressed.insert(compressed.end(), enc.begin(), enc.end());
    while (fallbackSize % 4) ++fallbackSize;
    Json v = {{"buffer", 1}, {"byteOffset", fallbackSize}, {"byteLength", count * stride},
              {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (target == 34962) v["byteStride"] = stride;
    if (target) v["target"] = target;
    fallbackSize += count * stride;
    g["bufferViews"].push_back(v);
    return int(g["bufferViews"].size()) - 1;
  };
  Json& prim = g["meshes"][0]["primitives"][0];
  Json& attr = prim["attributes"];
  attr["POSITION"] = addAccessor(g, view(m.positions.data(), n, 12, "ATTRIBUTES", "NONE", 34962), 5126, int(n), "VEC3");
  std::vector<float> n4;
  for (std::size_t v = 0; v < n; ++v) n4.insert(n4.end(), {m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2], 0});
  Bytes oct(n * 4);
  meshopt_encodeFilterOct(oct.data(), n, 4, 8, n4.data());
  attr["NORMAL"] = addAccessor(g, view(oct.data(), n, 4, "ATTRIBUTES", "OCTAHEDRAL", 34962), 5120, int(n), "VEC3", true);
  attr["TEXCOORD_0"] = addAccessor(g, view(m.uv0.data(), n, 8, "ATTRIBUTES", "NONE", 34962), 5126, int(n), "VEC2");
  Bytes expo(n * 8);
  meshopt_encodeFilterExp(expo.data(), n, 8, 16, m.uv1.data());
  attr["TEXCOORD_1"] = addAccessor(g, view(expo.data(), n, 8, "ATTRIBUTES", "EXPONENTIAL", 34962), 5126, int(n), "VEC2");
  attr["TANGENT"] = addAccessor(g, view(m.tangents.data(), n, 16, "ATTRIBUTES", "NONE", 34962), 5126, int(n), "VEC4");
  prim["indices"] = addAccessor(g, view(m.indices.data(), m.indices.size(), 4, "TRIANGLES", "NONE", 34963), 5125,
                                int(m.indices.size()), "SCALAR");
  pad4(compressed);
  g["buffers"].push_back({{"byteLength", compressed.size()},
                          {"uri", "data:application/octet-stream;base64," + base64(compressed)}});
  g["buffers"].push_back({{"byteLength", fallbackSize}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  return g.dump(1) + "\n";
}

// ---- the textured quad scene ----

// 8 x 8 checker (sRGB colours), a normal map of a constant tilt towards +u (tangent-space
// normal (sin 20 deg, 0, cos 20 deg)) with a raised ring, and an emissive glyph.
void texturedScene() {
  std::vector<Bytes> checker, normal, rows;
  for (int y = 0; y < 8; ++y) {
    Bytes r;
    for (int x = 0; x < 8; ++x) {
      bool dark = (x + y) % 2;
      r.insert(r.end(), {png_byte(dark ? 40 : 230), png_byte(dark ? 60 : 200), png_byte(dark ? 140 : 90)});
    }
    checker.push_back(r);
  }
  const int N = 32;
  for (int y = 0; y < N; ++y) {
    Bytes r;
    for (int x = 0; x < N; ++x) {
      double nx = std::sin(20 * M_PI / 180), ny = 0, nz = std::cos(20 * M_PI / 180);
      double dx = x + 0.5 - N / 2.0, dy = y + 0.5 - N / 2.0, d = std::sqrt(dx * dx + dy * dy);
      if (d > 8 && d < 11) {  // a ring whose normals lean outwards
        nx = 0.5 * dx / d, ny = -0.5 * dy / d, nz = std::sqrt(1 - 0.25);
      }
      auto code = [](double v) { return png_byte(std::lround((v * 0.5 + 0.5) * 255)); };
      r.insert(r.end(), {code(nx), code(ny), code(nz)});
    }
    normal.push_back(r);
  }
  writeFile("scenes/tests/textured/checker.png", encodePng({8, 8, PNG_COLOR_TYPE_RGB, 8}, checker));
  writeFile("scenes/tests/textured/normal.png", encodePng({N, N, PNG_COLOR_TYPE_RGB, 8}, normal));
  // Emissive: a 16 x 16 JPEG of flat 8 x 8 blocks (one lit block per quadrant colour).
  writeFile("scenes/tests/textured/emissive.jpg", encodeJpeg(false, false, TJSAMP_444));

  // Quad in the xy plane (2 x 2, centred), facing +z; uv (0, 0) at the top-left corner.
  const float positions[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const unsigned short idx[] = {0, 1, 2, 0, 2, 3};
  Json g = gridDocument("nusselt tools/make_test_assets.cpp: textured quad");
  g["extensionsUsed"] = {"KHR_texture_transform"};
  Bytes buf;
  Json& prim = g["meshes"][0]["primitives"][0];
  Json& attr = prim["attributes"];
  attr["POSITION"] = addAccessor(g, addView(g, buf, Bytes((const unsigned char*)positions, (const unsigned char*)positions + sizeof positions)), 5126, 4, "VEC3");
  g["accessors"][0]["min"] = {-1, -1, 0};
  g["accessors"][0]["max"] = {1, 1, 0};
  attr["NORMAL"] = addAccessor(g, addView(g, buf, Bytes((const unsigned char*)normals, (const unsigned char*)normals + sizeof normals)), 5126, 4, "VEC3");
  attr["TEXCOORD_0"] = addAccessor(g, addView(g, buf, Bytes((const unsigned char*)uv, (const unsigned char*)uv + sizeof uv)), 5126, 4, "VEC2");
  prim["indices"] = addAccessor(g, addView(g, buf, Bytes((const unsigned char*)idx, (const unsigned char*)idx + sizeof idx)), 5123, 6, "SCALAR");
  prim["material"] = 0;
  g["images"] = {{{"uri", "checker.png"}}, {{"uri", "normal.png"}}, {{"uri", "emissive.jpg"}}};
  g["samplers"] = {{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 10497}, {"wrapT", 10497}},
                   {{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 33071}, {"wrapT", 33071}}};
  g["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}, {"sampler", 1}}, {{"source", 2}, {"sampler", 1}}};
  g["materials"] = {{{"name", "textured"},
                     {"pbrMetallicRoughness",
                      {{"baseColorTexture", {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"scale", {2, 2}}}}}}}},
                       {"metallicFactor", 0},
                       {"roughnessFactor", 0.6}}},
                     {"normalTexture", {{"index", 1}, {"scale", 1}}},
                     {"emissiveTexture", {{"index", 2}}},
                     {"emissiveFactor", {1, 1, 1}}}};
  g["nodes"] = {{{"mesh", 0}}, {{"camera", 0}, {"translation", {0, 0, 3.5}}}};
  g["scenes"][0]["nodes"] = {0, 1};
  g["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.01}, {"aspectRatio", 1.0}}}}};
  pad4(buf);
  writeFile("scenes/tests/textured/quad.bin", buf);
  g["buffers"].push_back({{"byteLength", buf.size()}, {"uri", "quad.bin"}});
  writeText("scenes/tests/textured/textured_quad.gltf", g.dump(1) + "\n");
}

// A GLB whose images are bufferViews: a triangle with base colour (PNG) and emissive (JPEG).
Bytes texturedGlb(const Bytes& png, const Bytes& jpeg) {
  const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float uv[] = {0, 1, 1, 1, 0, 0};
  Json g = gridDocument("nusselt tools/make_test_assets.cpp: GLB with bufferView images");
  Bytes bin;
  Json& attr = g["meshes"][0]["primitives"][0]["attributes"];
  attr["POSITION"] = addAccessor(g, addView(g, bin, Bytes((const unsigned char*)positions, (const unsigned char*)positions + sizeof positions)), 5126, 3, "VEC3");
  attr["TEXCOORD_0"] = addAccessor(g, addView(g, bin, Bytes((const unsigned char*)uv, (const unsigned char*)uv + sizeof uv)), 5126, 3, "VEC2");
  g["meshes"][0]["primitives"][0]["material"] = 0;
  g["images"] = {{{"bufferView", addView(g, bin, png)}, {"mimeType", "image/png"}},
                 {{"bufferView", addView(g, bin, jpeg)}, {"mimeType", "image/jpeg"}}};
  g["textures"] = {{{"source", 0}}, {{"source", 1}}};
  g["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                     {"emissiveTexture", {{"index", 1}}},
                     {"emissiveFactor", {1, 1, 1}},
                     {"alphaMode", "MASK"},
                     {"doubleSided", true}}};
  pad4(bin);
  g["buffers"].push_back({{"byteLength", bin.size()}});
  std::string js = g.dump();
  while (js.size() % 4) js += ' ';
  Bytes out = {'g', 'l', 'T', 'F'};
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back((unsigned char)(v >> (8 * i)));
  };
  u32(2);
  u32(std::uint32_t(12 + 8 + js.size() + 8 + bin.size()));
  u32(std::uint32_t(js.size()));
  u32(0x4E4F534Au);
  out.insert(out.end(), js.begin(), js.end());
  u32(std::uint32_t(bin.size()));
  u32(0x004E4942u);
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_test_assets REPOSITORY_ROOT\n");
    return 2;
  }
  root = argv[1];
  try {
    for (const auto& [name, bytes] : makePngs()) {
      writeFile("tests/data/images/" + name, bytes);
      writeFile("tests/fuzz/corpus/image/" + name, bytes);
    }
    const Bytes jpegs[] = {encodeJpeg(false, false, TJSAMP_444), encodeJpeg(true, false, TJSAMP_GRAY),
                           encodeJpeg(false, true, TJSAMP_420)};
    const char* jpegNames[] = {"rgb444.jpg", "grey.jpg", "progressive420.jpg"};
    for (int i = 0; i < 3; ++i) {
      writeFile(std::string("tests/data/images/") + jpegNames[i], jpegs[i]);
      writeFile(std::string("tests/fuzz/corpus/image/") + jpegNames[i], jpegs[i]);
    }
    const Grid grid = makeGrid();
    const std::pair<const char*, std::string> grids[] = {{"grid_plain.gltf", gridPlain(grid)},
                                                         {"grid_quantized.gltf", gridQuantized(grid)},
                                                         {"grid_draco.gltf", gridDraco(grid)},
                                                         {"grid_meshopt.gltf", gridMeshopt(grid)}};
    for (const auto& [name, text] : grids) {
      writeText(std::string("tests/data/gltf/") + name, text);
      writeText(std::string("tests/fuzz/corpus/gltf/") + name, text);
    }
    texturedScene();
    Bytes rgba;
    {
      std::ifstream f(root + "/tests/data/images/rgba8.png", std::ios::binary);
      rgba.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    writeFile("tests/fuzz/corpus/gltf/textured_bufferview_images.glb", texturedGlb(rgba, jpegs[1]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_test_assets: %s\n", e.what());
    return 1;
  }
  std::printf("make_test_assets: wrote tests/data/images, tests/data/gltf/grid_*.gltf, scenes/tests/textured, "
              "fuzz seeds\n");
  return 0;
}
