// The Metropolis mutation kernel (shaders/shared/mlt.h): its proposals stay in [0, 1)^2, a small
// step's displacement is sigma x a standard normal pair (wrapped), and the kernel is symmetric,
// q(x -> y) = q(y -> x), which the acceptance min(1, f(y) / f(x)) assumes. Symmetry is tested as
// detailed balance of the uniform density: with x uniform and y ~ q(x, .), the number of moves
// from cell i to cell j and from j to i have the same expectation (Bowker's test of symmetry of
// a contingency table: sum over pairs (n_ij - n_ji)^2 / (n_ij + n_ji) is chi-square with one
// degree of freedom per pair). The same test must reject a kernel with a drift of sigma / 5.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../../shaders/shared/mlt.h"
#include "test_quadtree_chi2.h"

using namespace nusselt::shared;

namespace {

struct Bowker {
  double chi2 = 0;
  int dof = 0;
  double p() const { return nusselt::qttest::gammaQ(0.5 * dof, 0.5 * chi2); }
};

// x uniform (a hash), y = the small step of x (drift added to the first coordinate's move),
// cells of 1/cells on the first coordinate; moves counted from cell(x) to cell(y).
Bowker symmetryTest(float sigma, float drift, int cells, std::uint32_t n, std::uint32_t seed) {
  std::vector<double> moves(std::size_t(cells) * cells, 0.0);
  for (std::uint32_t i = 0; i < n; ++i) {
    uvec4 h = pcg4d(uvec4(i, seed, 77u, 5u));
    vec2 x(mltUnit(h.x), mltUnit(h.y));
    vec2 y = mltSmallStep(x, mltHash(i, 3u, 9u, seed), sigma);
    if (drift != 0.0f) y.x = mltWrap(y.x + drift);
    int a = std::min(cells - 1, int(x.x * cells)), b = std::min(cells - 1, int(y.x * cells));
    moves[std::size_t(a) * cells + b] += 1;
  }
  Bowker r;
  for (int i = 0; i < cells; ++i)
    for (int j = i + 1; j < cells; ++j) {
      double nij = moves[std::size_t(i) * cells + j], nji = moves[std::size_t(j) * cells + i];
      if (nij + nji < 10) continue;  // pairs that are never neighbours: no information (and chi2 approximation poor)
      r.chi2 += (nij - nji) * (nij - nji) / (nij + nji);
      ++r.dof;
    }
  return r;
}

}  // namespace

TEST(MltMutation, ProposalsStayInTheUnitSquare) {
  // Edges included: 0, the largest float below 1, tiny values that a negative move wraps to just
  // below 1 (where x - floor(x) rounds to 1.0f).
  const float edges[] = {0.0f, std::nextafter(1.0f, 0.0f), 1e-9f, 0.5f, 1.0f - 1e-7f};
  std::uint32_t outside = 0;
  for (std::uint32_t i = 0; i < 400000; ++i) {
    uvec4 h = mltHash(i, i / 7u, i % 11u, 3u);
    vec2 u = i % 2 ? vec2(edges[i % 5], edges[(i / 5) % 5]) : vec2(mltUnit(h.w), mltUnit(h.z));
    for (float sigma : {0.01f, 0.3f, 1.0f})
      for (bool large : {false, true}) {
        vec2 y = mltPropose(u, h, large, sigma);
        outside += !(y.x >= 0.0f && y.x < 1.0f && y.y >= 0.0f && y.y < 1.0f);
      }
  }
  EXPECT_EQ(outside, 0u);
  for (float x : {-1e-12f, -1.0f, 1.0f, 2.5f, -0.25f}) {
    float w = mltWrap(x);
    EXPECT_TRUE(w >= 0.0f && w < 1.0f) << x;
  }
}

TEST(MltMutation, SmallStepIsSigmaTimesANormalPair) {
  // Away from the edges (x in [0.25, 0.75), sigma = 0.01: a wrap needs a 25-sigma move), the
  // displacement's coordinates have mean 0 and variance sigma^2, and are uncorrelated. z-tests at
  // a two-sided 0.001 (|z| < 3.29) with the exact variances of the normal: Var d = s^2,
  // Var d^2 = 2 s^4, Var d_x d_y = s^4.
  const float sigma = 0.01f;
  const std::uint32_t n = 200000;
  double sx = 0, sxx = 0, sy = 0, syy = 0, sxy = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    uvec4 h = pcg4d(uvec4(i, 1u, 2u, 3u));
    vec2 x(0.25f + 0.5f * mltUnit(h.x), 0.25f + 0.5f * mltUnit(h.y));
    vec2 y = mltSmallStep(x, mltHash(i, 0u, 1u, 4u), sigma);
    double dx = double(y.x) - x.x, dy = double(y.y) - x.y;
    sx += dx, sy += dy, sxx += dx * dx, syy += dy * dy, sxy += dx * dy;
  }
  const double s2 = double(sigma) * sigma, zc = 3.29;
  EXPECT_LT(std::abs(sx / n) / std::sqrt(s2 / n), zc);
  EXPECT_LT(std::abs(sy / n) / std::sqrt(s2 / n), zc);
  EXPECT_LT(std::abs(sxx / n - s2) / std::sqrt(2 * s2 * s2 / n), zc);
  EXPECT_LT(std::abs(syy / n - s2) / std::sqrt(2 * s2 * s2 / n), zc);
  EXPECT_LT(std::abs(sxy / n) / std::sqrt(s2 * s2 / n), zc);
}

TEST(MltMutation, SmallStepIsSymmetric) {
  // Cells of 1/20 on the first coordinate; sigma 0.05 and 0.3 make moves between neighbouring
  // and distant cells, and across the wrap (cell 0 <-> cell 19). Significance 0.001 each.
  for (float sigma : {0.05f, 0.3f}) {
    Bowker b = symmetryTest(sigma, 0.0f, 20, 400000, 17u);
    ASSERT_GT(b.dof, 10);
    EXPECT_GT(b.p(), 0.001) << "sigma " << sigma << ": chi2 " << b.chi2 << " with " << b.dof << " dof";
  }
  // Power: a drift of sigma / 5 (an asymmetric kernel) is rejected by the same test.
  Bowker biased = symmetryTest(0.05f, 0.01f, 20, 400000, 17u);
  EXPECT_LT(biased.p(), 0.001) << "the symmetry test cannot see a drift: chi2 " << biased.chi2;
}
