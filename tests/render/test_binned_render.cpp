// Binned sampling in renders (issue 18; shaders/shared/bsdf_sampling.h, "Binned sampling"): a
// gltf_pbr floor whose baseColor and metallicRoughness textures vary its colour, metalness and
// roughness per texel (from a near-mirror metal to a rough dielectric), lit by a small lamp above
// it and seen at an angle, so that the glossy texels reflect the lamp.
//   - Under the quadtree strategy the scene builds roughness bins (the summary says so), and light
//     sampling, BSDF sampling and MIS agree: BSDF sampling draws from the binned mixture, MIS
//     weighs both with its exact density (binnedPdf);
//   - the binned MIS render agrees with the cosine-sampled one (`--sampler cosine`): both unbiased;
//   - binned BSDF sampling is less noisy than cosine BSDF sampling on this floor (the reason for it).
// Welch z-tests per 4 x 4 block (cell alpha 0.01, binomial bound at 0.001), as test_mis.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "../support/test_support.h"
#include "brdf/registry.h"

using namespace nusselt;

namespace {

TextureRef nearestTexture(Scene& s, std::uint32_t w, std::uint32_t h, const std::vector<glm::ivec4>& texels, ColorSpace c) {
  TextureImage im;
  im.name = "image" + std::to_string(s.images.size());
  im.width = w;
  im.height = h;
  for (const glm::ivec4& t : texels)
    for (int k = 0; k < 4; ++k) im.rgba.push_back(std::uint8_t(t[k]));
  s.images.push_back(im);
  TextureRef r;
  r.image = int(s.images.size() - 1);
  r.magFilter = r.minFilter = FilterMode::Nearest;
  r.colorSpace = c;
  return r;
}

// The quad [-h, h]^2 at height z0 facing +z (down: facing -z), u = (x / h + 1) / 2, v = (1 - y / h) / 2.
void texturedQuad(Scene& s, float z0, std::uint32_t material, float half, bool down) {
  glm::vec3 a(-half, -half, z0), b(half, -half, z0), c(half, half, z0), d(-half, half, z0);
  if (down) std::swap(b, d);
  test::addQuad(s, a, b, c, d, material);
  for (glm::vec3 p : {a, b, c, a, c, d}) s.texcoords0.push_back(glm::vec2((p.x / half + 1) / 2, (1 - p.y / half) / 2));
}

// The floor: 4 x 2 texels of (roughness G, metallic B) from a near-mirror metal to a rough
// dielectric, with a colour each; a lamp (radiance 6) of half-size 0.25 at height 0.6 facing
// down; the camera above one side, looking down at 36 degrees past the lamp.
Scene texturedFloor() {
  Scene s;
  Material floor = catalogueMaterial("gltf_pbr", {{"metallic", ParamValue::num(1.0)}, {"roughness", ParamValue::num(1.0)}},
                                     "floor");
  floor.baseColorFactor = glm::vec4(1.0f);
  floor.metallicFactor = 1.0f;
  floor.roughnessFactor = 1.0f;
  floor.baseColorTexture = nearestTexture(s, 4, 2,
                                          {{180, 180, 180, 255}, {240, 80, 60, 255}, {60, 200, 90, 255}, {220, 220, 120, 255},
                                           {250, 200, 150, 255}, {230, 230, 230, 255}, {200, 120, 60, 255}, {90, 160, 240, 255}},
                                          ColorSpace::Srgb);
  // (0, G roughness, B metallic): top row (y > 0) glossy and rough dielectrics and a half metal;
  // bottom row (y < 0, where the camera sees the lamp's mirror image) near-mirror, glossy and
  // rough metals.
  floor.metallicRoughnessTexture = nearestTexture(s, 4, 2,
                                                  {{0, 26, 0, 255}, {0, 90, 0, 255}, {0, 255, 0, 255}, {0, 64, 128, 255},
                                                   {0, 13, 255, 255}, {0, 51, 255, 255}, {0, 128, 255, 255}, {0, 230, 255, 255}},
                                                  ColorSpace::Linear);
  s.materials.push_back(floor);
  Material lamp = catalogueMaterial("lambert", {{"rho", ParamValue::num(0.0)}}, "lamp");
  lamp.emission = glm::vec3(6.0f);
  s.materials.push_back(lamp);
  texturedQuad(s, 0.0f, 0, 1.0f, false);
  texturedQuad(s, 0.6f, 1, 0.25f, true);
  s.hasCamera = true;
  s.camera.position = glm::vec3(0.0f, -2.0f, 1.45f);
  s.camera.forward = glm::normalize(glm::vec3(0.0f, 2.0f, -1.45f));
  s.camera.up = glm::normalize(glm::cross(glm::cross(s.camera.forward, glm::vec3(0, 0, 1)), s.camera.forward));
  s.camera.yfov = 0.9f;
  return s;
}

RenderSettings settings(SamplerKind sampler, LightingMode lighting, std::uint32_t spp, std::uint32_t seed) {
  RenderSettings rs;
  rs.width = rs.height = 32;
  rs.maxDepth = 1;
  rs.spp = spp;
  rs.seed = seed;
  rs.sampler = sampler;
  rs.lighting = lighting;
  // The bins' tables along theta: 30 (every 3 degrees) keep the test's first build short; the
  // estimator is unbiased for any tables.
  rs.samplerThetaTables = 30;
  rs.roughnessBins = 6;
  return rs;
}

// Sum of the per-pixel variances of the mean (luminance weights): the image's noise.
double noise(const Image& im) {
  double v = 0;
  for (std::size_t p = 0; p < im.variance.size() / 3; ++p)
    v += 0.2126 * im.variance[3 * p] + 0.7152 * im.variance[3 * p + 1] + 0.0722 * im.variance[3 * p + 2];
  return v;
}

}  // namespace

TEST(BinnedRender, NeeBsdfMisAndCosineAgree) {
  Scene s = texturedFloor();
  test::Rendered mis = test::render(s, settings(SamplerKind::Quadtree, LightingMode::Mis, 64, 51));
  EXPECT_EQ(mis.summary.roughnessBins, 6u) << "the textured gltf_pbr floor must be sampled with the bins";
  test::Rendered nee = test::render(s, settings(SamplerKind::Quadtree, LightingMode::NeeOnly, 64, 52));
  test::Rendered bsdf = test::render(s, settings(SamplerKind::Quadtree, LightingMode::BsdfOnly, 256, 53));
  test::Rendered cosMis = test::render(s, settings(SamplerKind::Cosine, LightingMode::Mis, 64, 54));
  EXPECT_EQ(cosMis.summary.roughnessBins, 0u);
  test::Rendered cosBsdf = test::render(s, settings(SamplerKind::Cosine, LightingMode::BsdfOnly, 256, 55));
  std::string m1 = test::compareImagesStatistically(nee.image, mis.image, 0.01, 0.001, 4);
  EXPECT_TRUE(m1.empty()) << "NEE vs MIS (binned): " << m1;
  std::string m2 = test::compareImagesStatistically(bsdf.image, mis.image, 0.01, 0.001, 4);
  EXPECT_TRUE(m2.empty()) << "BSDF (binned) vs MIS (binned): " << m2;
  std::string m3 = test::compareImagesStatistically(cosMis.image, mis.image, 0.01, 0.001, 4);
  EXPECT_TRUE(m3.empty()) << "MIS (cosine) vs MIS (binned): " << m3;
  std::string m4 = test::compareImagesStatistically(cosBsdf.image, bsdf.image, 0.01, 0.001, 4);
  EXPECT_TRUE(m4.empty()) << "BSDF (cosine) vs BSDF (binned): " << m4;
  // The bins' reason: BSDF sampling of the glossy texels. Not a threshold from statistics but a
  // sanity bound far from the measured ratio (printed): binned must not be noisier than cosine.
  const double ratio = noise(bsdf.image) / noise(cosBsdf.image);
  std::printf("BSDF-sampling noise (sum of variances of the mean), binned / cosine at 256 spp: %.4f\n", ratio);
  EXPECT_LT(ratio, 1.0);
  EXPECT_EQ(bsdf.stats.samplerTrialFailures, 0u);
  EXPECT_EQ(test::validationMessages(), 0u);
}
