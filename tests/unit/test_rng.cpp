// Random numbers: the PCG hash stays in [0, 1); the QMC sampler's first 2^m samples of every
// (pixel, dimension) form a (0, m, 2)-net: each elementary interval of area 2^-m holds exactly
// one point (Sobol's (0,2)-sequence property survives Owen scrambling and the index shuffle).
#include <gtest/gtest.h>

#include <vector>

#include "../../shaders/shared/rng.h"

using namespace nusselt::shared;

TEST(Rng, PcgInUnitInterval) {
  for (uint i = 0; i < 100000; ++i) {
    vec2 u = rng2(i, i * 7u, i % 13u, 42u);
    ASSERT_GE(u.x, 0.0f);
    ASSERT_LT(u.x, 1.0f);
    ASSERT_GE(u.y, 0.0f);
    ASSERT_LT(u.y, 1.0f);
  }
}

// The second Sobol dimension by its generator rows (v0 = 2^31, v(k+1) = v(k) ^ (v(k) >> 1)), one
// row per set bit of the index: what rngSobol1Reversed computes in five steps, bit-reversed.
static uint sobol1Rows(uint index) {
  uint r = 0u, v = 0x80000000u;
  for (int k = 0; k < 32; ++k, v ^= v >> 1u)
    if ((index >> k) & 1u) r ^= v;
  return r;
}

TEST(Rng, Sobol1MatchesItsRows) {
  std::vector<uint> indices;
  for (uint i = 0; i < 70000; ++i) indices.push_back(i);
  for (uint i = 0; i < 200000; ++i) indices.push_back(pcg4d(uvec4(i, 1u, 2u, 3u)).x);
  for (int k = 0; k < 32; ++k) indices.push_back(1u << k), indices.push_back(~(1u << k));
  indices.push_back(0xffffffffu);
  for (uint i : indices) ASSERT_EQ(rngReverseBits(rngSobol1Reversed(i)), sobol1Rows(i)) << "index " << i;
}

TEST(Rng, QmcIsA02NetForEveryPowerOfTwo) {
  for (uint dim : {0u, 1u, 5u, 123u})
    for (uint pixel : {0u, 77u, 4095u}) {
      const int m = 8, n = 1 << m;
      std::vector<vec2> pts;
      for (int i = 0; i < n; ++i) {
        vec2 u = sample2(RNG_QMC, pixel, uint(i), dim, 9u);
        ASSERT_GE(u.x, 0.0f);
        ASSERT_LT(u.x, 1.0f);
        ASSERT_GE(u.y, 0.0f);
        ASSERT_LT(u.y, 1.0f);
        pts.push_back(u);
      }
      // Every elementary interval shape 2^-a x 2^-(m-a), a = 0..m, holds exactly one point.
      for (int a = 0; a <= m; ++a) {
        const int nx = 1 << a, ny = 1 << (m - a);
        std::vector<int> count(nx * ny, 0);
        for (vec2 u : pts) ++count[int(u.y * ny) * nx + int(u.x * nx)];
        for (int c : count) ASSERT_EQ(c, 1) << "dim " << dim << " pixel " << pixel << " intervals " << nx << "x" << ny;
      }
    }
}

TEST(Rng, QmcDimensionsAndPixelsAreDecorrelated) {
  // Two dimensions of one pixel must not repeat the same points (independent scrambles).
  int same = 0;
  for (uint i = 0; i < 64; ++i) {
    vec2 a = sample2(RNG_QMC, 3u, i, 2u, 1u), b = sample2(RNG_QMC, 3u, i, 3u, 1u);
    if (a.x == b.x && a.y == b.y) ++same;
  }
  EXPECT_EQ(same, 0);
}
