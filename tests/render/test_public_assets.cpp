// A textured model from a public glTF collection (issue 18's goal): Khronos's "BoxTextured"
// (scenes/khronos/, CC BY 4.0, Draco-compressed; a gltf_pbr box, metallic 0, roughness 1, whose
// base colour is the 256 x 256 Cesium logo, laid out along u in [0, 6] with REPEAT, sampled
// LINEAR_MIPMAP_LINEAR). Loaded through the whole loader (Draco decode, PNG decode, samplers),
// each face seen straight on under a uniform white sky must converge, per 4 x 4 pixel block, to
// the albedo that its texels predict, and the logo must stand where the asset's texture
// coordinates put it (checked against figures taken from the asset with an independent decoder).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "../support/test_support.h"
#include "../../shaders/shared/brdf/dispatch.h"
#include "../../shaders/shared/texture.h"
#include "render/texture_table.h"

using namespace nusselt;

namespace {

constexpr int kSize = 32;  // image side, pixels
constexpr int kSub = 16;   // footprint quadrature points per pixel side (2 per texel side)

// Orthographic view of the face of the unit box [-0.5, 0.5]^3 whose outward normal is `normal`,
// filling the image.
void faceOn(Scene& s, glm::vec3 normal) {
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.forward = -normal;
  s.camera.position = 2.0f * normal;
  s.camera.up = glm::vec3(0, 1, 0);
  s.camera.xmag = s.camera.ymag = 0.5f;
}

// The closest triangle that the ray o + t d hits (Moeller-Trumbore, double), its barycentrics
// (b1, b2) of corners 1 and 2; false when it misses everything.
bool closestHit(const Scene& s, glm::dvec3 o, glm::dvec3 d, std::uint32_t& tri, double& b1, double& b2) {
  double best = INFINITY;
  for (std::uint32_t t = 0; t < s.positions.size() / 3; ++t) {
    glm::dvec3 p0(s.positions[3 * t]), e1 = glm::dvec3(s.positions[3 * t + 1]) - p0,
        e2 = glm::dvec3(s.positions[3 * t + 2]) - p0;
    glm::dvec3 pv = glm::cross(d, e2);
    double det = glm::dot(e1, pv);
    if (std::fabs(det) < 1e-12) continue;
    glm::dvec3 tv = o - p0;
    double u = glm::dot(tv, pv) / det;
    glm::dvec3 qv = glm::cross(tv, e1);
    double v = glm::dot(d, qv) / det, dist = glm::dot(e2, qv) / det;
    if (u < 0 || v < 0 || u + v > 1 || !(dist > 0) || dist >= best) continue;
    best = dist;
    tri = t;
    b1 = u;
    b2 = v;
  }
  return std::isfinite(best);
}

struct Expected {
  std::vector<double> fine, coarse;  // per pixel and channel: kSub^2 and (kSub / 2)^2 points
};

// The image the face converges to: per pixel, the mean over its footprint of the albedo at normal
// incidence of the texel's base colour c (the texture as the renderer samples it, texture.h's
// lookup on the packed texels): a0 + c (a1 - a0), the box's BRDF being linear in the base colour
// at metallic 0 (f0 = 0.04 whatever c: only the diffuse part scales with it).
Expected expectedFace(const Scene& s, glm::dvec3 a0, glm::dvec3 a1) {
  const Material& m = s.materials.at(s.triangleMaterial.at(0));
  const TextureImage& image = s.images.at(std::size_t(m.baseColorTexture.image));
  const std::vector<std::uint32_t> texels = packTexels(image);
  const shared::GpuTexture tex = packTexture(m.baseColorTexture, image, 0);
  const glm::dvec3 f(s.camera.forward), up(s.camera.up), right = glm::normalize(glm::cross(f, up));
  Expected e;
  e.fine.assign(3 * kSize * kSize, 0.0);
  e.coarse.assign(3 * kSize * kSize, 0.0);
  for (int py = 0; py < kSize; ++py)
    for (int px = 0; px < kSize; ++px)
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) {
          const double x = 2.0 * s.camera.xmag * ((px + (i + 0.5) / kSub) / kSize - 0.5);
          const double y = 2.0 * s.camera.ymag * (0.5 - (py + (j + 0.5) / kSub) / kSize);
          std::uint32_t tri = 0;
          double b1 = 0, b2 = 0;
          if (!closestHit(s, glm::dvec3(s.camera.position) + x * right + y * up, f, tri, b1, b2)) {
            ADD_FAILURE() << "pixel (" << px << ", " << py << ") misses the box";
            return e;
          }
          const glm::dvec2 uv = (1.0 - b1 - b2) * glm::dvec2(s.texcoords0[3 * tri]) +
                                b1 * glm::dvec2(s.texcoords0[3 * tri + 1]) + b2 * glm::dvec2(s.texcoords0[3 * tri + 2]);
          const glm::vec4 c = shared::textureLookup(texels.data(), tex, glm::vec2(uv));
          const bool coarse = i % 2 == 0 && j % 2 == 0;
          for (int k = 0; k < 3; ++k) {
            const double a = a0[k] + double(c[k]) * double(m.baseColorFactor[k]) * (a1[k] - a0[k]);
            e.fine[3 * (py * kSize + px) + k] += a / (kSub * kSub);
            if (coarse) e.coarse[3 * (py * kSize + px) + k] += a / ((kSub / 2) * (kSub / 2));
          }
        }
  return e;
}

// The face's block means against the prediction: z per 4 x 4 block and channel with the block's
// variance of the mean (per-pixel variances), two-sided, 0.001 with Sidak over the 192 tests,
// plus the quadrature's allowance (its 16^2-point value against its 8^2-point one).
void expectFaceConverges(const test::Rendered& r, const Expected& e, const char* face) {
  const int blocks = kSize / 4, tests = blocks * blocks * 3;
  const double zMax = test::normalQuantileUpper(0.5 * (1.0 - std::pow(1.0 - 0.001, 1.0 / tests)));
  double worst = 0;
  for (int by = 0; by < blocks; ++by)
    for (int bx = 0; bx < blocks; ++bx)
      for (int k = 0; k < 3; ++k) {
        double sum = 0, var = 0, fine = 0, coarse = 0;
        for (int py = 4 * by; py < 4 * by + 4; ++py)
          for (int px = 4 * bx; px < 4 * bx + 4; ++px) {
            const std::size_t i = std::size_t(3 * (py * kSize + px) + k);
            sum += r.image.rgb[i];
            var += r.image.variance[i];
            fine += e.fine[i];
            coarse += e.coarse[i];
          }
        const double mean = sum / 16, se = std::sqrt(var) / 16, want = fine / 16, allowance = std::fabs(fine - coarse) / 16;
        const double z = std::max(0.0, std::fabs(mean - want) - allowance) / se;
        worst = std::max(worst, z);
        EXPECT_LT(z, zMax) << face << " face, block (" << bx << ", " << by << ") channel " << k << ": " << mean
                           << " vs predicted " << want << " (se " << se << ", quadrature allowance " << allowance << ")";
      }
  std::printf("[ BoxTextured ] %s face: largest block |z| %.2f (limit %.2f)\n", face, worst, zMax);
}

// Mean of channel k over the pixels of the square [x0, x1) x [y0, y1).
double squareMean(const Image& im, int x0, int x1, int y0, int y1, int k) {
  double sum = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) sum += im.rgb[std::size_t(3 * (y * kSize + x) + k)];
  return sum / ((x1 - x0) * (y1 - y0));
}

TEST(PublicAssets, BoxTexturedShowsItsTextureWhereItsTexcoordsPutIt) {
  Scene s = test::loadTestScene("scenes/khronos/BoxTextured.glb");
  ASSERT_EQ(s.positions.size(), 36u);
  ASSERT_EQ(s.images.size(), 1u);
  ASSERT_EQ(s.images[0].width, 256u);
  const Material& m = s.materials.at(s.triangleMaterial.at(0));
  ASSERT_EQ(m.model, MODEL_GLTF_PBR);
  ASSERT_EQ(m.baseColorTexture.colorSpace, ColorSpace::Srgb);
  s.background = glm::vec3(1.0f);  // a uniform white sky; the box is convex: max depth 1 is exact

  // The albedo at normal incidence of the box's BRDF with base colour 0 and 1.
  shared::BrdfParams p0 = m.params, p1 = m.params;
  for (int k = 0; k < 3; ++k) {
    p0.v[(GLTF_PBR_BASE_COLOR + k) / 4u][(GLTF_PBR_BASE_COLOR + k) % 4u] = 0.0f;
    p1.v[(GLTF_PBR_BASE_COLOR + k) / 4u][(GLTF_PBR_BASE_COLOR + k) % 4u] = 1.0f;
  }
  const glm::dvec3 a0 = test::albedoAtNormalIncidence(MODEL_GLTF_PBR, p0), a1 = test::albedoAtNormalIncidence(MODEL_GLTF_PBR, p1);

  RenderSettings rs;
  rs.width = rs.height = kSize;
  rs.spp = 256;
  rs.maxDepth = 1;
  rs.seed = 18;
  struct Face {
    const char* name;
    glm::vec3 normal;
    bool mirrored;  // the logo mirrored left to right as seen from outside
  };
  // From the asset with an independent decoder (DracoPy, numpy): the uv frame of the +z and +x
  // faces has the opposite handedness to their outward normal, that of the -z face the same.
  for (const Face& face : {Face{"+z", glm::vec3(0, 0, 1), true}, Face{"-z", glm::vec3(0, 0, -1), false}}) {
    faceOn(s, face.normal);
    test::Rendered r = test::render(s, rs);
    Expected e = expectedFace(s, a0, a1);
    if (HasFailure()) return;
    expectFaceConverges(r, e, face.name);
    // The logo's sun, a white disc 23 texels across centred at texel (167, 72) of 256 (upper
    // right of the image; measured with PIL), covers texels [160, 168) x [64, 72), pixel (20, 8)
    // here, or its mirror image (11, 8); the other of the two is sky blue (texel (88, 72):
    // sRGB 91, 156, 215).
    const int sx = 20, sy = 8;
    const int x = face.mirrored ? kSize - 1 - sx : sx, other = kSize - 1 - x;
    const double sunR = squareMean(r.image, x, x + 1, sy, sy + 1, 0),
                 skyR = squareMean(r.image, other, other + 1, sy, sy + 1, 0),
                 skyB = squareMean(r.image, other, other + 1, sy, sy + 1, 2);
    EXPECT_GT(sunR, 0.8) << face.name << " face: no white sun at pixel (" << x << ", " << sy << ")";
    EXPECT_LT(skyR, 0.5 * skyB) << face.name << " face: no blue sky at pixel (" << other << ", " << sy << ")";
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}


// Normal maps visible on a public asset: Khronos's "DamagedHelmet" (scenes/khronos/, CC BY 4.0; a
// three.js re-export with JPEG textures, no TANGENT: the loader generates the tangents), a close-up
// of its side (a narrow field of view from +x, so that a pixel covers a few texels of the 2048 x
// 2048 normal map; at the default framing a pixel averages hundreds of texels and the map's detail
// averages out of any block mean) under a directional sun and a dim uniform sky, its emission
// removed (it does not depend on the normal and would only add noise), rendered with its normal
// map and with the map removed (the interpolated normal), 32 x 32, max depth 2, 1024 spp each.
// Per 4 x 4 block, Welch z of the two luminance means; a block differs when |z| exceeds the
// two-sided 0.001 level with Sidak over the 64 blocks. Were the map ignored, the expected count of
// differing blocks would be 0.001 and 5 or more would have probability below 1e-8 (binomial): the test asks
// for at least 5 (9 measured).
TEST(PublicAssets, DamagedHelmetNormalMapChangesTheShading) {
  Scene withMap = test::loadTestScene("scenes/khronos/DamagedHelmet.glb");
  ASSERT_EQ(withMap.materials.size(), 1u);
  ASSERT_TRUE(withMap.materials[0].normalMapped());
  // A sun and a dim sky: under a uniform sky alone the shading of a convex object hardly depends
  // on its normals (a furnace), so the map would not show.
  PunctualLight sun;
  sun.type = LightType::Directional;
  sun.name = "sun";
  sun.direction = glm::normalize(glm::vec3(-1.0f, -1.0f, -1.0f));
  sun.intensity = glm::vec3(3.0f);
  withMap.lights.push_back(sun);
  withMap.background = glm::vec3(0.2f);
  // The close-up: the scene's bounds seen from +x through a field of view of 0.1 rad.
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : withMap.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  const float extent = glm::length(hi - lo);
  withMap.hasCamera = true;
  withMap.camera = Camera{};
  withMap.camera.position = centre + glm::vec3(2.0f * extent, 0.0f, 0.0f);
  withMap.camera.forward = glm::vec3(-1.0f, 0.0f, 0.0f);
  withMap.camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  withMap.camera.yfov = 0.1f;
  withMap.materials[0].emission = glm::vec3(0.0f);
  withMap.materials[0].emissiveTexture = TextureRef{};
  Scene without = withMap;
  without.materials[0].normalTexture = TextureRef{};
  RenderSettings rs;
  rs.width = rs.height = kSize;
  rs.spp = 1024;
  rs.maxDepth = 2;
  rs.seed = 81;
  const test::Rendered a = test::render(withMap, rs);
  rs.seed = 82;
  const test::Rendered b = test::render(without, rs);
  std::vector<double> ma, va, mb, vb;
  test::blockMeans(a.image, ma, &va);
  test::blockMeans(b.image, mb, &vb);
  const int blocks = (kSize / 4) * (kSize / 4);
  const double zMax = test::normalQuantileUpper(0.5 * (1.0 - std::pow(1.0 - 0.001, 1.0 / blocks)));
  int differ = 0;
  for (int i = 0; i < blocks; ++i) {
    const double se = std::sqrt(va[std::size_t(i)] + vb[std::size_t(i)]);
    if (se > 0 && std::fabs(ma[std::size_t(i)] - mb[std::size_t(i)]) / se > zMax) ++differ;
  }
  std::printf("[ DamagedHelmet ] %d of %d blocks differ with the normal map (|z| > %.2f)\n", differ, blocks, zMax);
  EXPECT_GE(differ, 5) << "the normal map does not change the shading visibly";
  EXPECT_EQ(a.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(test::validationMessages(), 0u);
}

}  // namespace
