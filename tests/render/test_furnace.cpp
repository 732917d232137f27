// White furnace: inside a closed sphere with Lambert albedo rho and uniform emission Le on its
// inside, every pixel converges to Le / (1 - rho) (sum of the Neumann series Le * rho^k).
#include <gtest/gtest.h>

#include <cmath>

#include "../support/test_support.h"

using namespace nusselt;

TEST(Furnace, LambertSphereConvergesToLeOverOneMinusRho) {
  Scene scene = test::loadTestScene("scenes/tests/furnace.gltf");
  ASSERT_EQ(scene.materials.size(), 1u);
  const double rho = scene.materials[0].params.v[0][0];
  const double le = scene.materials[0].emission.x;
  const double expected = le / (1.0 - rho);

  RenderSettings s;
  s.width = 24;
  s.height = 24;
  s.spp = 64;
  // Truncation bias rho^(maxDepth+1) = 0.5^65: far below the statistical resolution.
  s.maxDepth = 64;
  s.seed = 1;
  test::Rendered r = test::render(scene, s);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(r.stats.bvhStackOverflows, 0u);

  const int n = s.width * s.height;
  // Significance 0.01 for the whole test: Bonferroni over 3 channels x (pixels + 1 mean test).
  const double alpha = 0.01 / (3.0 * (n + 1));
  const double zMax = test::normalQuantileUpper(alpha / 2);
  for (int c = 0; c < 3; ++c) {
    double sum = 0, var = 0;
    for (int i = 0; i < n; ++i) {
      double x = r.image.rgb[3 * i + c], v = r.image.variance[3 * i + c];
      ASSERT_GT(v, 0.0) << "pixel " << i;
      double z = (x - expected) / std::sqrt(v);
      EXPECT_LT(std::fabs(z), zMax) << "channel " << c << " pixel " << i << ": " << x << " vs " << expected;
      sum += x;
      var += v;
    }
    double mean = sum / n, se = std::sqrt(var) / n;
    EXPECT_LT(std::fabs(mean - expected) / se, zMax) << "channel " << c << " mean " << mean << " +- " << se
                                                     << " vs " << expected;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
