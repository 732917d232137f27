// VEGAS (--integrator vegas, docs/vegas.md) against the path tracer on the Cornell box: the same
// image in expectation with learned (far from uniform) warps, the same image for the same seed bit
// for bit, and with alpha = 1 (uniform tables, no warp) the path tracer's image bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "../support/test_support.h"
#include "cli/cli_common.h"
#include "render/vegas_integrator.h"
#include "util/error.h"

using namespace nusselt;

namespace {

Scene cornell() { return test::defaultScene(); }
RenderSettings base(std::uint32_t seed) { return test::integratorSettings(seed); }

// spp samples in passes of 16 (a table learned after each: 4096 paths per pass); two warped
// bounces (10 axes: more of the warp under test than the default's 5).
RenderSettings vegasSettings(std::uint32_t seed, std::uint32_t spp) {
  RenderSettings s = base(seed);
  s.integrator = IntegratorKind::Vegas;
  s.vegasBounces = 2;
  s.spp = spp;
  s.samplesPerPass = 16;
  return s;
}

// The mean of 8 vegas renders (256 spp: 8 learned tables, then 8 passes of the frozen one, 16 bins per axis) against a
// path-traced reference (8192 spp), per 4 x 4 block and for the image: Student t with the seeds'
// sample variance (later passes depend on earlier ones through the tables: the seeds are the
// independent replicas) plus the reference's, two-sided at 0.001 / tests (Bonferroni). The Cornell
// box's marginals are nearly flat: with 4096 paths per pass the learned densities reach ~1.3 x
// uniform (noise and some structure), enough for a wrong Jacobian to show (a density evaluated 10 %
// high in every other bin failed at t -43; a Jacobian error on an axis where f is flat would not
// show here: the unit tests (VegasWarp.*) check the Jacobian itself). Veach's MIS scene, whose densities reach 3 x,
// is no test scene for a mean: its small lights seen through the pixel jitter (not warped) make
// even the path tracer's image mean heavy-tailed (8 % low at 256 spp at 32 x 32).
void expectVegasMatchesPath(const Scene& scene, int seeds, float minLargest) {
  RenderSettings ps = base(1000);
  ps.spp = 8192;
  test::Rendered ref = test::render(scene, ps);
  std::vector<Image> replicas;
  float largest = 0;
  for (int k = 0; k < seeds; ++k) {
    RenderSettings vs = vegasSettings(10 + k, 256);
    vs.vegasBins = 16;
    Renderer r(test::context(), scene, vs);
    r.render(vs.spp);
    const VegasReport& rep = r.vegas()->report();
    EXPECT_EQ(rep.refinements, 8u);  // the default --vegas-learn: 8 passes learn, 8 sample the frozen table
    for (float d : rep.maxDensity) largest = std::max(largest, d);
    EXPECT_EQ(r.stats().nonFiniteSamples, 0u);
    replicas.push_back(r.image());
  }
  // The test is void if the warps stayed near uniform.
  EXPECT_GT(largest, minLargest);
  char detail[64];
  std::snprintf(detail, sizeof detail, "largest density %.2f", largest);
  test::expectReplicasMatchReference(ref.image, replicas, "vegas 256 spp", detail);
  EXPECT_EQ(test::validationMessages(), 0u);
}

}  // namespace

TEST(Vegas, MatchesThePathTracer) { expectVegasMatchesPath(cornell(), 8, 1.2f); }

TEST(Vegas, SameSeedIsBitIdenticalOtherSeedIsNot) {
  Scene scene = cornell();
  test::Rendered a = test::render(scene, vegasSettings(5, 48));
  test::Rendered b = test::render(scene, vegasSettings(5, 48));
  ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
  EXPECT_EQ(0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  test::Rendered c = test::render(scene, vegasSettings(6, 48));
  EXPECT_NE(0, std::memcmp(a.image.rgb.data(), c.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  // And the warp did move away from uniform (else this is the path tracer's determinism).
  RenderSettings s = vegasSettings(5, 48);
  Renderer r(test::context(), scene, s);
  r.render(s.spp);
  float largest = 0;
  for (float d : r.vegas()->report().maxDensity) largest = std::max(largest, d);
  EXPECT_GT(largest, 1.5f);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// alpha = 1: every table stays uniform, the warp is the identity bit for bit (vegas.h) and every
// weight 1: the path tracer's numbers, paths and sums, so its image bit for bit. Checks that the
// warp kernel hands each slot the path tracer's own numbers (pixel, sample index, dimension).
TEST(Vegas, UniformWarpIsThePathTracer) {
  Scene scene = cornell();
  RenderSettings vs = vegasSettings(7, 32);
  vs.vegasAlpha = 1.0f;
  RenderSettings ps = base(7);
  ps.spp = 32;
  ps.samplesPerPass = 16;
  test::Rendered v = test::render(scene, vs);
  test::Rendered p = test::render(scene, ps);
  ASSERT_EQ(v.image.rgb.size(), p.image.rgb.size());
  EXPECT_EQ(0, std::memcmp(v.image.rgb.data(), p.image.rgb.data(), v.image.rgb.size() * sizeof(float)));
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Vegas, BadOptionsAreRefused) {
  Scene scene = cornell();
  for (auto change : {+[](RenderSettings& s) { s.vegasBins = 0; }, +[](RenderSettings& s) { s.vegasBins = 5000; },
                      +[](RenderSettings& s) { s.vegasBounces = 0; }, +[](RenderSettings& s) { s.vegasBounces = 7; },
                      +[](RenderSettings& s) { s.vegasAlpha = 0.0f; }, +[](RenderSettings& s) { s.guiding = true; }}) {
    RenderSettings s = vegasSettings(1, 1);
    change(s);
    EXPECT_THROW(Renderer(test::context(), scene, s), Error);
  }
}
