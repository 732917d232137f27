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
  s.spp = 256;
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
    // Every pixel of the furnace estimates the same quantity with the same distribution, so the
    // variance pooled over all pixels is the precise one to use (a per-pixel estimate from few
    // samples of a skewed distribution is low exactly when the mean is low).
    double sum = 0, var = 0;
    for (int i = 0; i < n; ++i) {
      sum += r.image.rgb[3 * i + c];
      var += r.image.variance[3 * i + c];
    }
    ASSERT_GT(var, 0.0);
    const double pooled = var / n;
    for (int i = 0; i < n; ++i) {
      double x = r.image.rgb[3 * i + c];
      double z = (x - expected) / std::sqrt(pooled);
      EXPECT_LT(std::fabs(z), zMax) << "channel " << c << " pixel " << i << ": " << x << " vs " << expected;
    }
    double mean = sum / n, se = std::sqrt(var) / n;
    EXPECT_LT(std::fabs(mean - expected) / se, zMax) << "channel " << c << " mean " << mean << " +- " << se
                                                     << " vs " << expected;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
