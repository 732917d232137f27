// test_primary_samples.cpp: a sampled direction is a function of the primary numbers the sampler
// receives (issue 15 step 5, for Metropolis, issue 19): the quadtree's rejection trials and its
// descent's fresh numbers come from the stream of u (rng.h, rngStreamKey), not from the pixel or
// sample that produced u. The GPU side: QuadtreeGpu.ChiSquareCpuGpuAndParity compares the GPU tool's
// samples with this CPU code, which sees u only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "brdf/albedo.h"
#include "quadtree/quadtree_build.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

struct Drawn {
  vec3 wi{0.0f};
  vec3 weight{0.0f};
  float pdf = 0.0f;
  float q = 0.0f;
  bool ok = false;
  bool operator==(const Drawn& o) const {
    return std::memcmp(&wi, &o.wi, sizeof wi) == 0 && std::memcmp(&weight, &o.weight, sizeof weight) == 0 &&
           std::memcmp(&pdf, &o.pdf, sizeof pdf) == 0 && std::memcmp(&q, &o.q, sizeof q) == 0 && ok == o.ok;
  }
};

// The shade stage's entry point (bsdfSample), quadtree strategy, on ward's hard parameters: sharp
// lobes, deep trees and leaves whose rejection takes several trials, so both the fresh descent
// numbers and the trial stream are exercised.
struct WardHard {
  const ModelSpec* m = findModel("ward");
  BrdfParams p;
  quadtree::SamplerTables tables;
  WardHard() {
    p = packParams(*m, hardParams(*m), "ward/hard");
    std::vector<std::uint32_t> idx;
    tables = quadtree::buildSamplerTables({{m->id, p}}, qttest::testSettings(), idx);
  }
  Drawn draw(vec3 v, vec2 u) const {
    quadtree::QuadHostScope scope(tables);
    Drawn d;
    d.ok = bsdfSample(SAMPLER_QUADTREE, m->id, 0u, p, v, false, u, d.wi, d.weight, d.pdf, d.q);
    return d;
  }
};

const WardHard& wardHard() {
  static WardHard w;
  return w;
}

vec3 knownDirection(double thetaDeg) {
  double t = thetaDeg * M_PI / 180.0;
  return vec3(float(std::sin(t)), 0.0f, float(std::cos(t)));
}

}  // namespace

// The primary numbers of two different pixel / sample keys, swapped: every sample drawn from the
// numbers that key A produced equals the sample drawn when key B produces the same numbers (here:
// the same draw repeated in another order, after other draws, in a fresh host scope). A sampler
// that keyed any further number on the pixel, the sample index or on state would differ.
TEST(PrimarySamples, QuadtreeSampleIsAFunctionOfItsNumbers) {
  const WardHard& w = wardHard();
  const std::uint32_t n = 20000;
  // On a table, and between tables (the test settings build 37 and 38 degrees: mixture, defensive term).
  for (double theta : {30.0, 37.3}) {
    vec3 v = knownDirection(theta);
    std::vector<vec2> u(n);
    std::vector<Drawn> first(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      u[i] = rng2(i, 0u, RNG_DIM_BSDF, 3u);  // key A: pixel i, sample 0
      first[i] = w.draw(v, u[i]);
    }
    std::uint32_t mismatches = 0, succeeded = 0;
    for (std::uint32_t j = n; j-- > 0;) {  // key B: the numbers of pixel j presented by pixel n - 1 - j
      Drawn again = w.draw(v, u[j]);
      if (!(again == first[j])) ++mismatches;
      if (again.ok) ++succeeded;
    }
    EXPECT_EQ(mismatches, 0u) << "theta " << theta;
    EXPECT_EQ(succeeded, n) << "theta " << theta;
  }
}

// The stream must follow the numbers: the rejection's further numbers are keyed on BOTH of them.
// On a table (one tree, no defensive term) u.y chooses nothing, the descent takes u.x only, so a
// sampler whose trial numbers ignored u.y (or were keyed on a constant) would return the same
// direction for u.y and u.y's neighbouring float. Keyed on u.y's bits, the trials differ and the
// accepted point is a different float pair unless all 48 bits of a trial's (a, b) coincide
// (probability 2^-48 per sample) or a degenerate leaf rounds both points alike; we require
// at least 99 % of the samples to differ (with the stream keyed on u.x only, none would).
TEST(PrimarySamples, QuadtreeStreamFollowsBothNumbers) {
  const WardHard& w = wardHard();
  const std::uint32_t n = 20000;
  vec3 v = knownDirection(30.0);
  std::uint32_t same = 0, compared = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    vec2 u = rng2(i, 0u, RNG_DIM_BSDF, 4u);
    vec2 u2(u.x, u.y >= 0.5f ? u.y - 1.0f / 16777216.0f : u.y + 1.0f / 16777216.0f);
    Drawn a = w.draw(v, u), b = w.draw(v, u2);
    if (!a.ok || !b.ok) continue;
    ++compared;
    if (a.wi == b.wi) ++same;
  }
  EXPECT_EQ(compared, n);
  EXPECT_LE(same, n / 100) << same << " of " << compared << " samples ignored u.y";
}
