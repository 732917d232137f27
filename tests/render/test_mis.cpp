// Multiple importance sampling: light sampling alone, BSDF sampling alone and their MIS
// combination are three unbiased estimators of the same image (a small and a large light).
#include <gtest/gtest.h>

#include "../support/test_support.h"

using namespace nusselt;

TEST(Mis, NeeBsdfAndMisAgree) {
  Scene scene = test::loadTestScene("scenes/tests/mis.gltf");
  RenderSettings s;
  s.width = 64;
  s.height = 64;
  s.spp = 128;
  s.maxDepth = 3;
  s.seed = 11;
  s.lighting = LightingMode::Mis;
  test::Rendered mis = test::render(scene, s);
  s.seed = 12;
  s.lighting = LightingMode::NeeOnly;
  test::Rendered nee = test::render(scene, s);
  s.seed = 13;
  s.lighting = LightingMode::BsdfOnly;
  s.spp = 1024;  // the noisiest estimator
  test::Rendered bsdf = test::render(scene, s);
  // Significance 0.001 per comparison; per-cell alpha 0.01 with a binomial bound on failures;
  // cells of 8x8 pixels, since BSDF sampling of the small light is heavy-tailed.
  std::string m1 = test::compareImagesStatistically(nee.image, mis.image, 0.01, 0.001, 8);
  EXPECT_TRUE(m1.empty()) << "NEE vs MIS: " << m1;
  std::string m2 = test::compareImagesStatistically(bsdf.image, mis.image, 0.01, 0.001, 8);
  EXPECT_TRUE(m2.empty()) << "BSDF vs MIS: " << m2;
  // The images are not black: the test would otherwise pass vacuously.
  double sum = 0;
  for (float v : mis.image.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(test::validationMessages(), 0u);
}
