// test_traversal_render.cpp: renders traced with ray queries estimate the same image as renders
// traced with the GLSL BVH. Their hits differ in the last bits (trace.glsl), so the images are
// not bit-identical; independent seeds make the two estimates independent, and z-tests on the
// means (per 8x8 region, and of the whole image per channel) with variances from the renders' own
// standard errors must not reject.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/test_support.h"
#include "cli/cli_common.h"

using namespace nusselt;

namespace {

void expectSameImage(const Scene& scene, std::uint32_t size, std::uint32_t spp, const char* what) {
  if (!test::context().rayQuery) GTEST_SKIP() << test::context().deviceName << " has no ray queries";
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.seed = 31;
  s.traversal = Traversal::Bvh;
  test::Rendered bvh = test::render(scene, s);
  s.seed = 32;
  s.traversal = Traversal::RayQuery;
  test::Rendered rq = test::render(scene, s);
  EXPECT_EQ(bvh.summary.traversal, Traversal::Bvh);
  EXPECT_EQ(rq.summary.traversal, Traversal::RayQuery);
  EXPECT_EQ(rq.summary.bvhNodes, 0u) << "ray queries need no BVH";
  EXPECT_GT(rq.summary.accelerationBytes, 0u);
  EXPECT_EQ(bvh.stats.nonFiniteSamples + rq.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(bvh.stats.bvhStackOverflows, 0u);

  // Regions: per 8x8 block, two-sided p < 0.01 fails the block; at most the binomial bound of
  // failing blocks at significance 0.001 (test_support.h).
  std::string msg = test::compareImagesStatistically(rq.image, bvh.image, 0.01, 0.001, 8);
  EXPECT_TRUE(msg.empty()) << what << ": " << msg;

  // The whole image per channel: mean over pixels, variance of that mean = sum of the pixels'
  // variances of the mean / pixels^2 (independent pixels). Sidak over the 3 channels at 0.001.
  const double n = double(size) * size;
  const double zLimit = test::normalQuantileUpper(0.5 * (1.0 - std::pow(1.0 - 0.001, 1.0 / 3.0)));
  double total = 0;
  for (int c = 0; c < 3; ++c) {
    double ma = 0, mb = 0, va = 0, vb = 0;
    for (std::size_t i = 0; i < std::size_t(n); ++i) {
      ma += rq.image.rgb[3 * i + c];
      mb += bvh.image.rgb[3 * i + c];
      va += rq.image.variance[3 * i + c];
      vb += bvh.image.variance[3 * i + c];
    }
    ma /= n;
    mb /= n;
    double z = (ma - mb) / std::sqrt((va + vb) / (n * n));
    EXPECT_LT(std::abs(z), zLimit) << what << " channel " << c << ": mean " << ma << " (ray queries) vs " << mb
                                   << " (BVH), z = " << z;
    total += mb;
  }
  EXPECT_GT(total, 0.0) << "black image: the comparison would pass vacuously";
}

}  // namespace

TEST(TraversalRender, CornellBoxRayQueryEqualsBvh) {
  expectSameImage(loadSceneOrDefault("", ""), 64, 64, "Cornell box");
}

TEST(TraversalRender, DragonRayQueryEqualsBvh) {
  expectSameImage(test::loadTestScene("scenes/dragon/dragon.gltf"), 48, 32, "dragon");
}
