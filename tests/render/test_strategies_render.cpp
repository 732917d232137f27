// The five BSDF sampling strategies render the same image: tabulated (piecewise-constant tables,
// inverse-CDF sampling), analytic (the model's own importance sampling), cosine, uniform and the
// quadtree are unbiased estimators of one integral, so their renders of a glossy scene agree
// within their statistical error. Per block of 8x8 pixels a Welch z-test (the renders' own
// variances), cell alpha 0.01 with a binomial bound on failing blocks at alpha 0.001 per
// comparison (test_mis.cpp's test), fixed seeds; thresholds come from the statistics, never tuned.
#include <gtest/gtest.h>

#include <cstring>

#include "../support/test_support.h"
#include "brdf/registry.h"

using namespace nusselt;

namespace {

MaterialComponent component(const std::string& model, float weight) {
  return catalogueComponent(model, typicalParams(*findModel(model)), weight);
}

// The MIS test scene (a floor under a large dim and a small bright light) with a glossy floor:
// one model, or a combination (exercises the tables of combined materials' components).
Scene glossyScene(const std::vector<MaterialComponent>& components) {
  Scene scene = test::loadTestScene("scenes/tests/mis.gltf");
  Material& floor = scene.materials[0];
  if (components.size() > 1) setComponents(floor, components);
  else floor.model = components[0].model, floor.params = components[0].params;
  return scene;
}

void expectStrategiesAgree(const Scene& scene) {
  RenderSettings s;
  s.width = 32;  // 8 x 8 blocks of 4 x 4 pixels, 2048 samples per block and strategy
  s.height = 32;
  s.spp = 128;
  s.maxDepth = 3;
  s.sampler = SamplerKind::Tabulated;
  s.seed = 21;
  test::Rendered tab = test::render(scene, s);
  EXPECT_EQ(tab.stats.nonFiniteSamples, 0u);
  double sum = 0;
  for (float v : tab.image.rgb) sum += v;
  EXPECT_GT(sum, 0.0);  // not black: the comparison would pass vacuously
  std::uint32_t seed = 22;
  for (SamplerKind k : {SamplerKind::Analytic, SamplerKind::Cosine, SamplerKind::Quadtree}) {
    s.sampler = k;
    s.seed = seed++;
    test::Rendered other = test::render(scene, s);
    EXPECT_EQ(other.stats.nonFiniteSamples, 0u);
    std::string m = test::compareImagesStatistically(other.image, tab.image, 0.01, 0.001, 8);
    EXPECT_TRUE(m.empty()) << samplerName(k) << " vs tabulated: " << m;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}

}  // namespace

TEST(StrategiesRender, TabulatedAnalyticCosineQuadtreeAgree) { expectStrategiesAgree(glossyScene({component("blinn", 1.0f)})); }

TEST(StrategiesRender, CombinedMaterialAgrees) {
  expectStrategiesAgree(glossyScene({component("lambert", 0.5f), component("phong", 0.5f)}));
}

// A BRDF that does not depend on the sampled direction (lambert) gets no quadtree: its tree would
// be the uniform disc, which cosine sampling draws exactly (quadtree::constantInSampledDirection).
// So the quadtree's render of a lambert floor is the cosine render, bit for bit, with the same
// seed; and the summary counts the material.
TEST(StrategiesRender, ConstantBrdfUnderTheQuadtreeIsCosineSampled) {
  Scene scene = glossyScene({component("lambert", 1.0f)});
  RenderSettings s;
  s.width = 16;
  s.height = 16;
  s.spp = 8;
  s.maxDepth = 3;
  s.seed = 5;
  s.sampler = SamplerKind::Quadtree;
  test::Rendered quad = test::render(scene, s);
  s.sampler = SamplerKind::Cosine;
  test::Rendered cosine = test::render(scene, s);
  EXPECT_GE(quad.summary.constantBrdfs, 1u);
  EXPECT_EQ(cosine.summary.constantBrdfs, 0u);
  ASSERT_EQ(quad.image.rgb.size(), cosine.image.rgb.size());
  double sum = 0;
  for (float v : quad.image.rgb) sum += v;
  EXPECT_GT(sum, 0.0);  // not black
  EXPECT_EQ(std::memcmp(quad.image.rgb.data(), cosine.image.rgb.data(), quad.image.rgb.size() * sizeof(float)), 0);
  EXPECT_EQ(test::validationMessages(), 0u);
}
