// The VEGAS warp (shaders/shared/vegas.h) and its learning step (vegasRefine,
// src/render/vegas_integrator.cpp): a uniform table is the identity bit for bit; a learned table
// maps bin edges to bin edges, keeps every bin's density >= alpha, integrates known functions
// exactly through its Jacobian, and its samples follow its density (chi-square).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../../shaders/shared/vegas.h"
#include "render/vegas_integrator.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

float unit(std::uint32_t bits) { return float(bits >> 8) * (1.0f / 16777216.0f); }

// A learned table of n bins: the refinement of a uniform one from bin sums of a lopsided f^2
// (a peak near 0.3, nothing above 0.8), then a second pass from other sums.
std::vector<float> learnedTable(std::uint32_t n, double alpha) {
  std::vector<float> cdf(n + 1);
  vegasUniformCdf(cdf.data(), n);
  std::vector<double> G(n, 0.0), S(n);
  for (std::uint32_t b = 0; b < n; ++b) {
    const double x = (b + 0.5) / n;
    S[b] = x < 0.8 ? 100.0 * std::exp(-60.0 * (x - 0.3) * (x - 0.3)) + 1.0 : 0.0;
  }
  vegasRefine(G, cdf.data(), n, S.data(), 1000.0, alpha);
  for (std::uint32_t b = 0; b < n; ++b) S[b] = b % 7 == 0 ? 40.0 : 2.0;
  vegasRefine(G, cdf.data(), n, S.data(), 1000.0, alpha);
  return cdf;
}

}  // namespace

TEST(VegasWarp, UniformTableIsTheIdentity) {
  for (std::uint32_t n : {1u, 2u, 64u, 128u, 4096u}) {
    std::vector<float> cdf(n + 1);
    vegasUniformCdf(cdf.data(), n);
    for (std::uint32_t k = 0; k < 100000; ++k) {
      const float u = unit(pcg4d(uvec4(k, n, 1u, 2u)).x);
      float pdf;
      uint bin;
      const float x = vegasWarp(cdf.data(), 0u, n, u, pdf, bin);
      ASSERT_EQ(nusselt::shared::floatBitsToUint(x), nusselt::shared::floatBitsToUint(u)) << "n " << n << " u " << u;
      ASSERT_EQ(pdf, 1.0f);
    }
  }
}

TEST(VegasWarp, LearnedTableMapsBinEdgesToBinEdgesWithPositiveDensity) {
  for (double alpha : {0.2, 0.05}) {
    const std::uint32_t n = 64;
    std::vector<float> cdf = learnedTable(n, alpha);
    EXPECT_EQ(cdf[0], 0.0f);
    EXPECT_EQ(cdf[n], 1.0f);
    float top = 0, low = 1e30f;
    for (std::uint32_t b = 0; b < n; ++b) {
      const float p = vegasDensity(cdf.data(), 0u, n, b);
      top = std::max(top, p);
      low = std::min(low, p);
      // The CDF's value at a bin's lower edge maps to that edge (within float rounding of the CDF).
      float pdf;
      uint bin;
      const float x = vegasWarp(cdf.data(), 0u, n, cdf[b], pdf, bin);
      EXPECT_NEAR(x, float(b) / float(n), 2e-6f) << "bin " << b;
      EXPECT_EQ(bin, b);
      EXPECT_EQ(pdf, p);
    }
    // Every bin keeps the uniform share (float rounding of the CDF: 1e-4 relative at 64 bins).
    EXPECT_GE(low, float(alpha) * 0.999f);
    EXPECT_GT(top, 2.0f) << "the test table should be far from uniform";
  }
}

// The integral of f over [0, 1) as the integral over u of f(x(u)) / p(x(u)), by the midpoint rule
// on K points within each bin's u-interval [cdf[b], cdf[b + 1]) (where the warp is linear and
// f / p smooth): exact up to 1 / K^2 and float rounding whatever the table, while a Jacobian off
// by any bin-dependent factor shows at once.
TEST(VegasWarp, JacobianIsExact) {
  const std::uint32_t n = 64, K = 512;
  std::vector<float> cdf = learnedTable(n, 0.2);
  auto f1 = [](double x) { return x * x * x; };                 // 1 / 4
  auto f2 = [](double x) { return std::exp(-4.0 * x); };        // (1 - e^-4) / 4
  auto f3 = [](double x) { return x < 0.3125 ? 2.0 : 0.5; };    // 0.625 + 0.34375 (a bin edge: 20 / 64)
  double s1 = 0, s2 = 0, s3 = 0;
  for (std::uint32_t b = 0; b < n; ++b) {
    const double du = (double(cdf[b + 1]) - double(cdf[b])) / K;
    for (std::uint32_t k = 0; k < K; ++k) {
      const float u = static_cast<float>(double(cdf[b]) + (k + 0.5) * du);
      float pdf;
      uint bin;
      const double x = vegasWarp(cdf.data(), 0u, n, u, pdf, bin);
      ASSERT_GT(pdf, 0.0f);
      s1 += du * f1(x) / pdf;
      s2 += du * f2(x) / pdf;
      s3 += du * f3(x) / pdf;
    }
  }
  EXPECT_NEAR(s1, 0.25, 1e-5);
  EXPECT_NEAR(s2, (1.0 - std::exp(-4.0)) / 4.0, 1e-5);
  EXPECT_NEAR(s3, 0.96875, 1e-5);
}

// Warped uniform samples against the table's bin probabilities, each bin split in 4 (the density is
// constant within a bin, so its quarters are equally likely): chi-square at 0.001.
TEST(VegasWarp, SamplesFollowTheDensity) {
  const std::uint32_t n = 64, cells = 4 * n, N = 400000;
  std::vector<float> cdf = learnedTable(n, 0.2);
  std::vector<double> count(cells, 0.0);
  for (std::uint32_t k = 0; k < N; ++k) {
    const float u = unit(pcg4d(uvec4(k, 7u, 3u, 5u)).y);
    float pdf;
    uint bin;
    const float x = vegasWarp(cdf.data(), 0u, n, u, pdf, bin);
    count[std::min<std::uint32_t>(std::uint32_t(x * cells), cells - 1)] += 1;
  }
  double chi2 = 0;
  for (std::uint32_t c = 0; c < cells; ++c) {
    const double e = N * (double(cdf[c / 4 + 1]) - double(cdf[c / 4])) / 4.0;
    chi2 += (count[c] - e) * (count[c] - e) / e;
  }
  const double p = qttest::gammaQ(0.5 * (cells - 1), 0.5 * chi2);
  EXPECT_GT(p, 0.001) << "chi2 " << chi2 << " over " << cells - 1 << " dof";
}

TEST(VegasWarp, RefineKeepsUniformWithoutSignalAndFollowsSqrtOfG) {
  const std::uint32_t n = 8;
  std::vector<float> cdf(n + 1);
  vegasUniformCdf(cdf.data(), n);
  std::vector<double> G(n, 0.0), S(n, 0.0);
  vegasRefine(G, cdf.data(), n, S.data(), 100.0, 0.2);
  for (std::uint32_t i = 0; i <= n; ++i) EXPECT_EQ(cdf[i], float(i) / float(n));
  // Sums 4 : 1 in two halves under the uniform density: G = S / 100; smoothed over neighbours
  // (the two bins at the step mix), square roots, normalised, mixed with alpha = 0.2.
  for (std::uint32_t b = 0; b < n; ++b) S[b] = b < n / 2 ? 4.0 : 1.0;
  vegasRefine(G, cdf.data(), n, S.data(), 100.0, 0.2);
  const double q[8] = {2, 2, 2, std::sqrt(3.0), std::sqrt(2.0), 1, 1, 1};
  double mean = 0;
  for (double v : q) mean += v / 8;
  for (std::uint32_t b = 0; b < n; ++b)
    EXPECT_NEAR(vegasDensity(cdf.data(), 0u, n, b), 0.8 * q[b] / mean + 0.2, 1e-5) << "bin " << b;
}

TEST(VegasWarp, AxesAreTheFirstBouncesLightAndBsdfDraws) {
  // Bounce 0: light choice x, light point x y, BSDF x y; then bounce 1.
  EXPECT_EQ(vegasAxisDimension(0), rngDimension(0, RNG_DIM_LIGHT_SELECT));
  EXPECT_EQ(vegasAxisDimension(2), rngDimension(0, RNG_DIM_LIGHT_POINT));
  EXPECT_EQ(vegasAxisComponent(2), 1u);
  EXPECT_EQ(vegasAxisDimension(4), rngDimension(0, RNG_DIM_BSDF));
  EXPECT_EQ(vegasAxisDimension(5), rngDimension(1, RNG_DIM_LIGHT_SELECT));
  for (uint a = 0; a < 3 * VEGAS_AXES_PER_BOUNCE; ++a)
    EXPECT_EQ(vegasAxisOf(vegasAxisDimension(a), vegasAxisComponent(a), 3u), a);
  EXPECT_EQ(vegasAxisOf(rngDimension(0, RNG_DIM_LIGHT_SELECT), 1u, 3u), 0xffffffffu);
  EXPECT_EQ(vegasAxisOf(rngDimension(0, RNG_DIM_ROULETTE), 0u, 3u), 0xffffffffu);
  EXPECT_EQ(vegasAxisOf(rngDimension(3, RNG_DIM_BSDF), 0u, 3u), 0xffffffffu);
  EXPECT_EQ(vegasAxisOf(0u, 0u, 3u), 0xffffffffu);
  EXPECT_EQ(vegasPrimaryDims(2), rngDimension(1, RNG_DIM_BSDF) + 1u);
}
