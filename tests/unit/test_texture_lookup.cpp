// test_texture_lookup.cpp: the shared texture lookup (shaders/shared/texture.h) against texel
// values computed by hand: every wrap mode, NEAREST and LINEAR, sRGB decoding, the texture
// transform, the coordinate set and the interpolation of a triangle's coordinates. The texels go
// through the renderer's own packing (render/texture_table.h).
#include <gtest/gtest.h>

#include <cmath>

#include "render/texture_table.h"
#include "../../shaders/shared/texture.h"

namespace nusselt {
namespace {

using shared::GpuTexture;
using shared::GpuTriTexcoords;

// A 3 x 2 image: R = 10 x + 100 y + 20, G = 7 (x + 1), B = 200 - 50 y, A = 255 - 40 x.
TextureImage image3x2() {
  TextureImage im;
  im.name = "test";
  im.width = 3;
  im.height = 2;
  for (std::uint32_t y = 0; y < 2; ++y)
    for (std::uint32_t x = 0; x < 3; ++x)
      im.rgba.insert(im.rgba.end(), {std::uint8_t(10 * x + 100 * y + 20), std::uint8_t(7 * (x + 1)),
                                     std::uint8_t(200 - 50 * y), std::uint8_t(255 - 40 * x)});
  return im;
}
float R(int x, int y) { return float(10 * x + 100 * y + 20) / 255.0f; }

struct Fixture {
  TextureImage im = image3x2();
  std::vector<std::uint32_t> texels = packTexels(im);
  GpuTexture tex(WrapMode s, WrapMode t, FilterMode f, ColorSpace c = ColorSpace::Linear) const {
    TextureRef r;
    r.image = 0;
    r.wrapS = s;
    r.wrapT = t;
    r.magFilter = f;
    r.colorSpace = c;
    return packTexture(r, im, 0);
  }
  glm::vec4 at(const GpuTexture& t, float u, float v) const {
    return shared::textureLookup(texels.data(), t, glm::vec2(u, v));
  }
};

constexpr float kEps = 1e-6f;

TEST(TextureLookup, PackingIsRgba8LowByteRed) {
  Fixture f;
  EXPECT_EQ(f.texels[4], (20u + 10u + 100u) | (14u << 8) | (150u << 16) | (215u << 24));  // texel (1, 1)
}

TEST(TextureLookup, NearestWrapModes) {
  Fixture f;
  const float cx = 1.0f / 3.0f, cy = 0.5f;  // texel size
  GpuTexture rep = f.tex(WrapMode::Repeat, WrapMode::Repeat, FilterMode::Nearest);
  GpuTexture clp = f.tex(WrapMode::ClampToEdge, WrapMode::ClampToEdge, FilterMode::Nearest);
  GpuTexture mir = f.tex(WrapMode::MirroredRepeat, WrapMode::MirroredRepeat, FilterMode::Nearest);
  // Inside: the texel that contains the point (row 0 at the top, v = 0).
  EXPECT_NEAR(f.at(rep, 1.5f * cx, 1.5f * cy).x, R(1, 1), kEps);
  EXPECT_NEAR(f.at(rep, 2.5f * cx, 0.5f * cy).x, R(2, 0), kEps);
  // REPEAT: u = 1 + 0.5/3 is texel 0; u = -0.1 is 0.9 -> x = 2.7 -> texel 2; v = -0.25 -> 0.75 -> row 1.
  EXPECT_NEAR(f.at(rep, 1.0f + 0.5f * cx, 0.25f).x, R(0, 0), kEps);
  EXPECT_NEAR(f.at(rep, -0.1f, -0.25f).x, R(2, 1), kEps);
  EXPECT_NEAR(f.at(rep, 7.9f, 3.3f).x, R(2, 0), kEps);  // 0.9 -> 2, 0.3 -> row 0
  // CLAMP_TO_EDGE: beyond the edges the edge texels.
  EXPECT_NEAR(f.at(clp, 1.7f, -3.0f).x, R(2, 0), kEps);
  EXPECT_NEAR(f.at(clp, -0.01f, 1.01f).x, R(0, 1), kEps);
  // MIRRORED_REPEAT: u = 1.2 reads 0.8 (x 2.4 -> 2); u = -0.2 reads 0.2 (-> 0); v = 1.3 reads 0.7 (row 1),
  // v = 1.8 reads 0.2 (row 0); u = 2.2 reads 0.2 (period 2).
  EXPECT_NEAR(f.at(mir, 1.2f, 0.25f).x, R(2, 0), kEps);
  EXPECT_NEAR(f.at(mir, -0.2f, 0.25f).x, R(0, 0), kEps);
  EXPECT_NEAR(f.at(mir, 0.5f, 1.3f).x, R(1, 1), kEps);
  EXPECT_NEAR(f.at(mir, 0.5f, 1.8f).x, R(1, 0), kEps);
  EXPECT_NEAR(f.at(mir, 2.2f, -1.3f).x, R(0, 1), kEps);  // v -1.3 -> 0.7 -> row 1
  // Mixed: S repeat, T clamp.
  GpuTexture mixed = f.tex(WrapMode::Repeat, WrapMode::ClampToEdge, FilterMode::Nearest);
  EXPECT_NEAR(f.at(mixed, -0.1f, 5.0f).x, R(2, 1), kEps);
  // Non-finite coordinates read as 0.
  EXPECT_NEAR(f.at(rep, NAN, INFINITY).x, R(0, 0), kEps);
}

TEST(TextureLookup, BilinearWrapModes) {
  Fixture f;
  GpuTexture rep = f.tex(WrapMode::Repeat, WrapMode::Repeat, FilterMode::Linear);
  GpuTexture clp = f.tex(WrapMode::ClampToEdge, WrapMode::ClampToEdge, FilterMode::Linear);
  GpuTexture mir = f.tex(WrapMode::MirroredRepeat, WrapMode::MirroredRepeat, FilterMode::Linear);
  // At a texel centre: the texel.
  EXPECT_NEAR(f.at(rep, 1.5f / 3.0f, 0.25f).x, R(1, 0), kEps);
  // Halfway between the centres of (0, 0) and (1, 0).
  EXPECT_NEAR(f.at(rep, 1.0f / 3.0f, 0.25f).x, 0.5f * (R(0, 0) + R(1, 0)), kEps);
  // A quarter of the way from (1, 0) to (2, 0): x = 1.5 + 0.25 = 1.75 texels.
  EXPECT_NEAR(f.at(rep, 1.75f / 3.0f, 0.25f).x, 0.75f * R(1, 0) + 0.25f * R(2, 0), kEps);
  // Between four centres: the mean of the four.
  EXPECT_NEAR(f.at(rep, 1.0f / 3.0f, 0.5f).x, 0.25f * (R(0, 0) + R(1, 0) + R(0, 1) + R(1, 1)), kEps);
  // Left edge u = 0, v at row 0's centre: REPEAT blends the last and the first column, CLAMP
  // and MIRROR repeat the first column.
  EXPECT_NEAR(f.at(rep, 0.0f, 0.25f).x, 0.5f * (R(2, 0) + R(0, 0)), kEps);
  EXPECT_NEAR(f.at(clp, 0.0f, 0.25f).x, R(0, 0), kEps);
  EXPECT_NEAR(f.at(mir, 0.0f, 0.25f).x, R(0, 0), kEps);
  // Top edge v = 0 at column 1's centre: REPEAT blends rows 1 and 0.
  EXPECT_NEAR(f.at(rep, 0.5f, 0.0f).x, 0.5f * (R(1, 1) + R(1, 0)), kEps);
  EXPECT_NEAR(f.at(clp, 0.5f, 0.0f).x, R(1, 0), kEps);
  // Right edge u = 1 (x = 3): REPEAT blends columns 2 and 0; MIRROR columns 2 and 2.
  EXPECT_NEAR(f.at(rep, 1.0f, 0.25f).x, 0.5f * (R(2, 0) + R(0, 0)), kEps);
  EXPECT_NEAR(f.at(mir, 1.0f, 0.25f).x, R(2, 0), kEps);
  // Every channel is filtered: G = 7 (x + 1), A = 255 - 40 x.
  glm::vec4 c = f.at(rep, 1.75f / 3.0f, 0.25f);
  EXPECT_NEAR(c.y, (0.75f * 14.0f + 0.25f * 21.0f) / 255.0f, kEps);
  EXPECT_NEAR(c.w, (0.75f * 215.0f + 0.25f * 175.0f) / 255.0f, kEps);
}

TEST(TextureLookup, SrgbDecodesColourNotAlpha) {
  TextureImage im;
  im.width = 2;
  im.height = 1;
  im.rgba = {128, 10, 255, 128, 0, 64, 200, 10};
  std::vector<std::uint32_t> texels = packTexels(im);
  TextureRef r;
  r.image = 0;
  r.magFilter = FilterMode::Nearest;
  r.colorSpace = ColorSpace::Srgb;
  GpuTexture t = packTexture(r, im, 0);
  glm::vec4 c = shared::textureLookup(texels.data(), t, glm::vec2(0.25f, 0.5f));
  // IEC 61966-2-1: ((c + 0.055) / 1.055)^2.4 above 0.04045, c / 12.92 below.
  EXPECT_NEAR(c.x, std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);  // 0.21586
  EXPECT_NEAR(c.y, 10.0 / 255.0 / 12.92, 1e-7);                            // 0.0030353
  EXPECT_NEAR(c.z, 1.0, 1e-6);
  EXPECT_NEAR(c.w, 128.0 / 255.0, 1e-7);  // alpha stays linear
  // Bilinear filters the decoded values: the mean of 0.21586 and 0 is not the decoded mean code.
  r.magFilter = FilterMode::Linear;
  r.wrapS = WrapMode::ClampToEdge;
  t = packTexture(r, im, 0);
  c = shared::textureLookup(texels.data(), t, glm::vec2(0.5f, 0.5f));
  EXPECT_NEAR(c.x, 0.5 * std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
}

TEST(TextureLookup, TransformAndCoordinateSet) {
  Fixture f;
  TextureRef r;
  r.image = 0;
  r.magFilter = FilterMode::Nearest;
  // u' = 2 u + 0.25, v' = v - 0.5 (columns (2, 0), (0, 1), (0.25, -0.5)).
  r.transform = glm::mat3x2(glm::vec2(2.0f, 0.0f), glm::vec2(0.0f, 1.0f), glm::vec2(0.25f, -0.5f));
  r.texCoord = 1;
  GpuTexture t = packTexture(r, f.im, 0);
  // u = 0.1 -> 0.45 -> x 1.35 -> texel 1; v = 0.2 -> -0.3 -> 0.7 (repeat) -> row 1.
  EXPECT_NEAR(shared::textureLookup(f.texels.data(), t, glm::vec2(0.1f, 0.2f)).x, R(1, 1), kEps);
  // The triangle's set 1 coordinates are used (set 0 is far away), interpolated by barycentrics.
  GpuTriTexcoords c{};
  c.a = glm::vec4(9.0f, 9.0f, 9.0f, 9.0f);              // set 0, corners 0 and 1
  c.b = glm::vec4(9.0f, 9.0f, 0.0f, 0.2f);              // set 0 corner 2; set 1 corner 0 = (0, 0.2)
  c.c = glm::vec4(0.2f, 0.2f, 0.0f, 1.2f);              // set 1 corners 1 = (0.2, 0.2), 2 = (0, 1.2)
  glm::vec2 uv = shared::triangleTexcoord(c, 1, 0.5f, 0.0f);  // halfway from corner 0 to corner 1
  EXPECT_NEAR(uv.x, 0.1f, kEps);
  EXPECT_NEAR(uv.y, 0.2f, kEps);
  EXPECT_NEAR(shared::textureAtHit(f.texels.data(), t, c, 0.5f, 0.0f).x, R(1, 1), kEps);
  glm::vec2 uv0 = shared::triangleTexcoord(c, 0, 0.25f, 0.25f);
  EXPECT_NEAR(uv0.x, 9.0f, 1e-5f);
  // The texel buffer offset: the second image's texels start at firstTexel.
  std::vector<std::uint32_t> two(6, 0u);
  two.insert(two.end(), f.texels.begin(), f.texels.end());
  GpuTexture shifted = packTexture(r, f.im, 6);
  EXPECT_NEAR(shared::textureLookup(two.data(), shifted, glm::vec2(0.1f, 0.2f)).x, R(1, 1), kEps);
}

// The device memory the render's pre-check counts for textures equals what buildTextureData
// packs: each applied image once (one image shared by two materials and slots), the coverage map
// of a material whose base colour is not textured, nothing for a material no triangle uses.
TEST(TextureTable, DeviceBytesMatchThePackedBuffers) {
  Scene s;
  s.images = {image3x2(), image3x2()};
  s.images[1].width = 1;
  s.images[1].height = 1;
  s.images[1].rgba.resize(4);
  TextureRef shared0, other;
  shared0.image = 0;
  other.image = 1;
  Material pbr = catalogueMaterial("gltf_pbr", {}, "pbr");
  pbr.baseColorTexture = shared0;
  pbr.alphaMode = AlphaMode::Mask;  // coverage from the (applied) base-colour texture
  Material lamp = catalogueMaterial("lambert", {}, "lamp", glm::vec3(1.0f));
  lamp.emissiveTexture = shared0;
  lamp.baseColorTexture = other;  // not applied to lambert's colour: a coverage map only
  lamp.alphaMode = AlphaMode::Blend;
  Material unused = catalogueMaterial("gltf_pbr", {}, "unused");
  unused.baseColorTexture = other;
  s.materials = {pbr, lamp, unused};
  for (std::uint32_t m : {0u, 1u}) {
    s.positions.insert(s.positions.end(), {glm::vec3(0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)});
    s.normals.insert(s.normals.end(), 3, glm::vec3(0, 0, 1));
    s.triangleMaterial.push_back(m);
  }
  const TextureData d = buildTextureData(s);
  EXPECT_EQ(d.texels.size(), 7u);    // 3 x 2 + 1 x 1, each once
  EXPECT_EQ(d.textures.size(), 3u);  // pbr base colour, lamp emissive, lamp coverage
  EXPECT_EQ(d.materials[0].alpha.y, d.materials[0].maps.x);
  EXPECT_EQ(d.materials[1].alpha.y, 2u);
  EXPECT_EQ(textureDeviceBytes(s), d.texels.size() * 4 + d.textures.size() * sizeof(GpuTexture) +
                                       d.materials.size() * sizeof(shared::GpuMaterialTextures));
  s.triangleMaterial = {2u, 2u};  // only the unused material's texture... now used, alone
  EXPECT_EQ(textureDeviceBytes(s), 4 + sizeof(GpuTexture) + 3 * sizeof(shared::GpuMaterialTextures));
}

}  // namespace
}  // namespace nusselt
