// Path guiding (issue 16, docs/guiding.md) in whole renders: the guided estimator is unbiased (its
// image equals the unguided one within their variances: per-block z-tests with a binomial bound,
// and a z-test on the difference of the image means), it is deterministic, and it learned
// something (the test would otherwise compare BSDF sampling with itself); the selection
// probability learned per region (the default, --guide-alpha auto) falls back to BRDF sampling in
// a furnace (its learning where the guide wins: tests/unit/test_guiding.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "../support/test_support.h"
#include "render/environment.h"
#include "render/guide.h"
#include "vk/vk.h"

using namespace nusselt;

namespace {

// z of the difference of two images' means, from the per-pixel variances of the mean the film
// records (pixels independent: the variance of a mean of n pixels is the sum of theirs / n^2).
double meanDifferenceZ(const Image& a, const Image& b) {
  double ma = 0, mb = 0, va = 0, vb = 0;
  const double n = double(a.rgb.size());
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    ma += a.rgb[i];
    mb += b.rgb[i];
    va += a.variance[i];
    vb += b.variance[i];
  }
  return (ma / n - mb / n) / std::sqrt((va + vb) / (n * n));
}

// A guided and an unguided render of `scene` (different seeds: independent estimates) agree;
// alpha: the guided render's --guide-alpha (< 0: auto, learned per region).
// spatialFilterAndFloor: with the spatial splat filter and a floor of 0.1 (off by default), and
// c = 300 (regions to share among).
void expectUnbiased(const Scene& scene, std::uint32_t size, std::uint32_t spp, std::uint32_t depth, int block,
                    float alpha = -1.0f, bool spatialFilterAndFloor = false) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.maxDepth = depth;
  s.seed = 21;
  test::Rendered plain = test::render(scene, s);
  s.seed = 22;
  s.guiding = true;
  s.guideAlpha = alpha;
  if (spatialFilterAndFloor) {
    s.guideSpatialFilter = true;
    s.guideFloor = 0.1;
    s.guideSpatialThreshold = 300;  // many regions for the filter to share among
  }
  Renderer r(test::context(), scene, s);
  r.render(s.spp);
  Image guided = r.image(true);
  ASSERT_NE(r.guide(), nullptr);
  ASSERT_FALSE(r.guide()->reports().empty());
  EXPECT_GT(r.guide()->reports().back().dirNodes, 1u) << "the guide must have learned a distribution";
  if (alpha > 0) EXPECT_GT(r.guide()->reports().back().guidedLeaves, 0u) << "the guide must be sampled";
  std::printf("alpha %s: the guide sampled in %u of %u regions (mean alpha %.3f)\n",
              alpha < 0 ? "auto" : std::to_string(alpha).c_str(), r.guide()->reports().back().guidedLeaves,
              r.guide()->reports().back().leaves, r.guide()->reports().back().meanAlpha);
  EXPECT_EQ(r.stats().nonFiniteSamples, 0u);
  // Per block of block x block pixels: significance 0.01 per block, 0.001 for the binomial bound.
  std::string msg = test::compareImagesStatistically(guided, plain.image, 0.01, 0.001, block);
  EXPECT_TRUE(msg.empty()) << msg;
  // The whole image's mean: two-sided, significance 0.001.
  const double z = meanDifferenceZ(guided, plain.image);
  EXPECT_GT(test::normalPValue(z), 0.001) << "z = " << z;
  double sum = 0;
  for (float v : guided.rgb) sum += v;
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The training records (guiding_layout.h) of a guided render of kRecordPaths pixels, one sample
// each (seed 7, depth kRecordDepth): one pass, iteration 0, whose records stay in the buffer.
// product: what the records carry (RenderSettings::guideProduct).
constexpr std::uint32_t kRecordSide = 16, kRecordPaths = kRecordSide * kRecordSide, kRecordDepth = 5;
std::vector<glm::vec4> firstPassRecords(const Scene& scene, bool product = true) {
  RenderSettings s;
  s.width = s.height = kRecordSide;
  s.spp = 1;
  s.maxDepth = kRecordDepth;
  s.seed = 7;
  s.guiding = true;
  s.guideTrainSpp = 1;
  s.guideProduct = product;
  const std::size_t vec4s = std::size_t(kRecordPaths) * DeviceGuide::recordsPerPath(kRecordDepth) * GUIDE_RECORD_VEC4S;
  Renderer r(test::context(), scene, s);
  r.render(s.spp);
  std::vector<glm::vec4> v(vec4s);
  vk::downloadBuffer(test::context(), r.guide()->records(), v.data(), vec4s * sizeof(glm::vec4));
  return v;
}

}  // namespace

// The Cornell box lit only indirectly (its light faces the ceiling): guiding's home ground.
// With the learned alpha (the default) and with a fixed one (every region that learned something
// samples the guide: the mixture itself is tested even where auto falls back everywhere).
TEST(Guiding, UnbiasedOnIndirectlyLitCornellBox) {
  expectUnbiased(test::loadTestScene("scenes/cornell/cornell-indirect.glb"), 32, 64, 6, 4);
  expectUnbiased(test::loadTestScene("scenes/cornell/cornell-indirect.glb"), 32, 64, 6, 4, 0.5f);
  // The spatial splat filter and the floor (the sampled density and the pdf of MIS and weights
  // then include the uniform share).
  expectUnbiased(test::loadTestScene("scenes/cornell/cornell-indirect.glb"), 32, 64, 6, 4, 0.5f, true);
}

// Combined materials (guided within their non-delta part: a non-delta component chosen is replaced
// by the guide with probability alpha), with mirror and dielectric components (never guided).
// At alpha 0.5 every combined vertex of a trained region samples the mixture; 512 spp, so that a
// missing factor of the mixture's density shows in the image means.
TEST(Guiding, UnbiasedWithCombinedAndDeltaMaterials) {
  expectUnbiased(test::loadTestScene("scenes/tests/combined.gltf"), 24, 32, 5, 4);
  expectUnbiased(test::loadTestScene("scenes/tests/combined.gltf"), 32, 512, 5, 4, 0.5f);
}

// Combined materials' vertices record both densities for the trainer (guiding_layout.h, record
// c), as single-model ones do: every non-delta sample's record has the guide's density (>= 0; -1
// marks a vertex that does not sample the mixture) and a positive BRDF-sampler density, and the
// scene's combined materials (tile, glazed, red_gloss: most of the box) give many of them.
TEST(Guiding, CombinedMaterialsRecordTheMixturesDensities) {
  Scene scene = test::loadTestScene("scenes/tests/combined.gltf");
  std::uint32_t combined = 0;
  for (const Material& m : scene.materials) combined += m.combined() ? 1u : 0u;
  ASSERT_EQ(combined, 3u);
  const std::vector<glm::vec4> v = firstPassRecords(scene);
  std::uint32_t nonDelta = 0, delta = 0;
  for (std::uint32_t p = 0; p < kRecordPaths; ++p)
    for (std::uint32_t k = 0; k + 1 < DeviceGuide::recordsPerPath(kRecordDepth); ++k) {
      const std::size_t i = shared::guideRecordIndex(p, k, kRecordPaths);
      const float b = v[i + 1].w;
      if (b == 0.0f) break;  // the path ended here
      if (b < 0.0f) {        // a delta sample (or one without luminance): not splatted
        ++delta;
        continue;
      }
      ++nonDelta;
      EXPECT_GE(v[i + 2].x, 0.0f) << "path " << p << " vertex " << k << ": no guide density recorded";
      EXPECT_GT(v[i + 2].y, 0.0f) << "path " << p << " vertex " << k;
    }
  std::printf("%u non-delta and %u delta records\n", nonDelta, delta);
  EXPECT_GT(nonDelta, kRecordPaths);
  EXPECT_GT(delta, 0u);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// An environment (the escape stage writes the records of rays that leave the scene), a Lambert
// and a mirror sphere.
TEST(Guiding, UnbiasedUnderAnEnvironment) {
  Scene scene = test::loadTestScene("scenes/tests/environment.gltf");
  scene.environment.kind = EnvironmentKind::Uniform;
  scene.environment.color = glm::vec3(0.8f, 0.9f, 1.0f);
  expectUnbiased(scene, 32, 64, 4, 4);
}

// Guiding lowers the variance where it should: on the indirectly lit box (light reaches the room
// only from the ceiling's bright patch), a guided render's per-pixel variance, at the same spp as an
// unguided one (its 255 training spp included), is lower. Per pixel d = var_unguided - var_guided
// (variances of the mean relative to the pixel's value, summed over the channels; independent seeds,
// so the pixels' d are independent): one-sided z-test of mean(d) > 0, significance 0.001. Measured:
// ratio of the summed variances 1.92, z = 25.7 (MIS against the BRDF sampler's density), 1.86,
// z = 24.6 against the mixture's (the guide learning the product L_i f cos), 1.73, z = 21.6 with
// it learning L_i (with the orientation roots of docs/guiding.md);
// with one root 1.29, z = 10.3, and 1.18, z = 6.9 with the roulette before docs/guiding.md's
// "Russian roulette" (so the test guards the guide as a whole, not one change: the gains show in
// relMSE at equal time, tools/bench_guiding.sh).
TEST(Guiding, LowersTheVarianceOnTheIndirectlyLitBox) {
  Scene scene = test::loadTestScene("scenes/cornell/cornell-indirect.glb");
  RenderSettings s;
  s.width = s.height = 64;
  s.spp = 511;
  s.maxDepth = 8;
  s.seed = 31;
  test::Rendered plain = test::render(scene, s);
  s.seed = 32;
  s.guiding = true;
  s.guideTrainSpp = 255;
  s.guideSpatialThreshold = 1000;  // regions for a 64 x 64 image (12000 is for 1280 x 720)
  test::Rendered guided = test::render(scene, s);
  const std::size_t pixels = std::size_t(s.width) * s.height;
  double sum = 0, sumSq = 0, vu = 0, vg = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    double u = 0, g = 0;
    for (int c = 0; c < 3; ++c) {
      // Relative to the pixel's value (as relMSE: bright pixels lit directly do not dominate),
      // the same for both images: the mean of their two estimates.
      const double m = 0.5 * (plain.image.rgb[3 * i + c] + guided.image.rgb[3 * i + c]);
      u += plain.image.variance[3 * i + c] / (m * m + 0.01);
      g += guided.image.variance[3 * i + c] / (m * m + 0.01);
    }
    sum += u - g;
    sumSq += (u - g) * (u - g);
    vu += u;
    vg += g;
  }
  const double n = double(pixels), mean = sum / n;
  const double se = std::sqrt(std::max(0.0, sumSq / n - mean * mean) / (n - 1.0));
  const double z = mean / se;
  std::printf("variance of the mean, summed: unguided %.4g, guided %.4g (ratio %.3f); z = %.2f\n", vu, vg, vu / vg, z);
  EXPECT_GT(z, test::normalQuantileUpper(0.001)) << "guided variance not significantly lower: ratio " << vu / vg;
  EXPECT_EQ(guided.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The determinism tests' guided render of cornell-indirect: 24 x 20, 16 spp, depth 5, seed 3.
RenderSettings determinismSettings() {
  RenderSettings s;
  s.width = 24;
  s.height = 20;
  s.spp = 16;
  s.maxDepth = 5;
  s.seed = 3;
  s.guiding = true;
  return s;
}

TEST(Guiding, SameSeedIsBitIdentical) {
  Scene scene = test::loadTestScene("scenes/cornell/cornell-indirect.glb");
  RenderSettings s = determinismSettings();
  // The learned alpha (auto, the default) and a fixed one; the fixed one also with the spatial
  // splat filter and a floor (the default splats are box-filtered in direction).
  for (float alpha : {-1.0f, 0.5f, 0.25f}) {
    s.guideAlpha = alpha;
    s.guideSpatialFilter = alpha == 0.25f;
    s.guideFloor = alpha == 0.25f ? 0.1 : 0.0;
    s.guideSpatialThreshold = alpha == 0.25f ? 100 : 12000;
    test::Rendered a = test::render(scene, s);
    test::Rendered b = test::render(scene, s);
    ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
    EXPECT_EQ(0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float))) << alpha;
    EXPECT_EQ(a.stats.rays, b.stats.rays);
    if (alpha < 0) continue;
    // And guiding changed the samples (the same seed unguided gives another image).
    s.guiding = false;
    test::Rendered c = test::render(scene, s);
    s.guiding = true;
    EXPECT_NE(0, std::memcmp(a.image.rgb.data(), c.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The training records need no clearing between passes: the stages write every record the trainer
// reads in the pass that reads it (guiding.h, guideRecordStart and the resets of
// guideRecordSample). Records filled with 1.0f before every training pass (a sample of value 1
// everywhere, what a stale record of an earlier pass could read as) give the same guide and image
// bit for bit: paths that end, leave a scene with and without an environment, and take delta
// samples.
TEST(Guiding, TrainingRecordsNeedNoClearing) {
  for (const char* path : {"scenes/cornell-box.glb", "scenes/cornell/cornell-glass.glb", "scenes/tests/environment.gltf"}) {
    Scene scene = test::loadTestScene(path);
    RenderSettings s = determinismSettings();
    s.guideSpatialThreshold = 100;        // many regions: a stale record's count would split one
    s.sampler = SamplerKind::Analytic;    // no quadtrees to build: the records are the same either way
    s.width = s.height = 32;              // square: the Cornell box's camera sees past its walls
    auto run = [&](bool poison) {
      if (poison) setenv("NUSSELT_TEST_POISON_GUIDE_RECORDS", "1", 1);
      Renderer r(test::context(), scene, s);
      r.render(s.spp);
      unsetenv("NUSSELT_TEST_POISON_GUIDE_RECORDS");
      return std::make_pair(r.image(true), r.guide()->hashText());
    };
    const auto clean = run(false), poisoned = run(true);
    EXPECT_EQ(clean.second, poisoned.second) << path;
    ASSERT_EQ(clean.first.rgb.size(), poisoned.first.rgb.size());
    EXPECT_EQ(0, std::memcmp(clean.first.rgb.data(), poisoned.first.rgb.data(), clean.first.rgb.size() * sizeof(float))) << path;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}

// What the guide learns (--guide-learn, GuideSettings::product). With the same seed, iteration 0's
// paths are the same in both modes (nothing is guided yet), and so are their training records but
// for b.w, the value the arriving radiance is divided by to give the splat (guiding_layout.h):
// lum(throughput) x p for L_i / p (radiance), lum(throughput) / lum(f cos / p) for L_i f cos / p
// (product). On the box's Lambert surfaces, sampled by the cosine, f cos / p = rho, so
// b.w(radiance) / b.w(product) = lum(rho) x p, with p the record's BRDF-sampler density c.y: each
// record's ratio / c.y is lum(rho) of one of the scene's materials, to float rounding (1e-4).
TEST(Guiding, ProductRecordsCarryTheBsdfAndCosine) {
  Scene scene = test::loadTestScene("scenes/cornell/cornell-indirect.glb");
  std::vector<double> rhos;
  for (const Material& m : scene.materials) {
    ASSERT_EQ(m.model, MODEL_LAMBERT);
    rhos.push_back(shared::luminance(shared::brdfParam3(m.params, LAMBERT_RHO)));
  }
  const std::vector<glm::vec4> rad = firstPassRecords(scene, false), prod = firstPassRecords(scene, true);
  std::uint32_t checked = 0;
  for (std::uint32_t p = 0; p < kRecordPaths; ++p) {
    for (std::uint32_t k = 0; k + 1 < DeviceGuide::recordsPerPath(kRecordDepth); ++k) {
      const std::size_t i = shared::guideRecordIndex(p, k, kRecordPaths);
      ASSERT_EQ(0, std::memcmp(&rad[i], &prod[i], sizeof(glm::vec4))) << "path " << p << " vertex " << k;
      ASSERT_EQ(0, std::memcmp(&rad[i + 2], &prod[i + 2], sizeof(glm::vec4))) << "path " << p << " vertex " << k;
      const float bR = rad[i + 1].w, bP = prod[i + 1].w;
      if (bR == 0.0f) break;  // the path ended here
      ASSERT_GT(bR, 0.0f);    // no delta samples in this scene
      ASSERT_GT(bP, 0.0f);
      const double ratio = double(bR) / double(bP) / double(rad[i + 2].y);
      double nearest = rhos[0];
      for (double r : rhos)
        if (std::abs(r - ratio) < std::abs(nearest - ratio)) nearest = r;
      EXPECT_NEAR(ratio, nearest, 1e-4 * nearest) << "path " << p << " vertex " << k;
      ++checked;
    }
  }
  std::printf("%u records checked\n", checked);
  EXPECT_GT(checked, kRecordPaths);  // most paths bounce more than once
  EXPECT_EQ(test::validationMessages(), 0u);
}

// ---- The selection probability learned per region (guide_tree.h, learnAlphas) ----------------------
namespace {

// The regions of a trained guide that learned an alpha (a trained tree and a learning step behind
// their alpha), and how many of them sample the guide (alpha > 0); `keep` selects regions by box.
struct AlphaCount {
  std::uint32_t learned = 0, guided = 0;
  double alphaSum = 0;
};
template <class Keep>
AlphaCount countLearnedAlphas(const guiding::GuideTree& t, Keep keep) {
  AlphaCount c;
  for (std::uint32_t l = 0; l < t.leafCount(); ++l) {
    glm::vec3 lo, hi;
    t.leafBounds(l, lo, hi);
    if (!keep(lo, hi) || !(t.samplingTree(l).total() > 0) || !(t.leafAlphaVertices(l) > 0)) continue;
    ++c.learned;
    if (t.leafAlpha(l) > 0) {
      ++c.guided;
      c.alphaSum += t.leafAlpha(l);
    }
  }
  return c;
}

// The smallest k with P(X > k) <= p for X ~ Binomial(n, q).
std::uint32_t binomialUpper(std::uint32_t n, double q, double p) {
  return static_cast<std::uint32_t>(test::binomialUpperLimit(static_cast<int>(n), q, p));
}

// A region whose guide gains nothing takes alpha > 0 only by a false positive of the z-test of
// learnAlphas: at most (candidates - 1) x its significance (Bonferroni over the candidates).
double falsePositiveBound(const guiding::GuideSettings& gs) {
  return double(guiding::kAlphaCandidates.size() - 1) * test::normalPValue(gs.alphaZ) / 2.0;
}

guiding::GuideSettings defaultGuideSettings() { return guiding::GuideSettings{}; }

}  // namespace

// The white furnace (a closed Lambert sphere, emission 1, rho 0.5): from a point on a sphere,
// light sampling by area has the cosine density, so NEE's MIS weight is 1/2 in every direction,
// and the BSDF sampler's estimate f cos L_i / p_bsdf has the same distribution in every direction:
// no guide can lower its variance, every alpha > 0 raises it. So no region should learn alpha > 0
// but by a false positive of the z-test (rate q <= falsePositiveBound): the guided regions are at
// most the 0.999 quantile of Binomial(regions, q). Small regions (c = 300) give many tests.
TEST(Guiding, LearnedAlphaFallsBackToBsdfSamplingInAFurnace) {
  Scene scene = test::loadTestScene("scenes/tests/furnace.gltf");
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 64;
  s.maxDepth = 8;
  s.seed = 5;
  s.guiding = true;
  s.guideSpatialThreshold = 300;
  Renderer r(test::context(), scene, s);
  r.render(s.spp);
  ASSERT_NE(r.guide(), nullptr);
  const AlphaCount c = countLearnedAlphas(r.guide()->tree(), [](glm::vec3, glm::vec3) { return true; });
  const double q = falsePositiveBound(defaultGuideSettings());
  const std::uint32_t bound = binomialUpper(c.learned, q, 0.001);
  std::printf("furnace: %u regions learned an alpha, %u sample the guide (bound %u, q = %.4f)\n", c.learned,
              c.guided, bound, q);
  EXPECT_GE(c.learned, 10u) << "too few regions learned an alpha for the test to mean anything";
  EXPECT_LE(c.guided, bound) << "regions that sample the guide in a furnace, of " << c.learned;
  EXPECT_EQ(test::validationMessages(), 0u);
}

// ---- The photon pre-pass (--guide-photons; docs/guiding.md, "Photon pre-pass") -----------------------

// Guided renders with photons are unbiased (the guide the first iteration samples comes from the
// photons; the mixture with the BRDF sampler keeps every estimate unbiased), with the learned and
// a fixed alpha; and the photons trained a refined guide (more than one directional node per
// region in their last round).
TEST(Guiding, UnbiasedWithPhotonPrePass) {
  const Scene scene = test::loadTestScene("scenes/cornell/cornell-indirect.glb");
  for (float alpha : {-1.0f, 0.5f}) {
    SCOPED_TRACE(alpha);
    RenderSettings s;
    s.width = s.height = 32;
    s.spp = 64;
    s.maxDepth = 6;
    s.seed = 21;
    test::Rendered plain = test::render(scene, s);
    s.seed = 22;
    s.guiding = true;
    s.guideAlpha = alpha;
    s.guidePhotons = 20000;
    Renderer r(test::context(), scene, s);
    r.render(s.spp);
    Image guided = r.image(true);
    ASSERT_NE(r.guide(), nullptr);
    const auto& reports = r.guide()->reports();
    ASSERT_GT(reports.size(), DeviceGuide::kPhotonRounds);
    const guiding::IterationReport& last = reports[DeviceGuide::kPhotonRounds - 1];
    ASSERT_TRUE(last.photons);
    EXPECT_GT(last.splats, 0u) << "the photons must have arrived somewhere after a bounce";
    EXPECT_GT(last.dirNodes, last.leaves) << "the photons' guide must be refined";
    if (alpha > 0) EXPECT_GT(last.guidedLeaves, 0u) << "the photons' guide must be sampled";
    EXPECT_EQ(r.stats().nonFiniteSamples, 0u);
    // Per block of 4 x 4 pixels: significance 0.01 per block, 0.001 for the binomial bound; the
    // whole image's mean: two-sided, significance 0.001 (as expectUnbiased).
    std::string msg = test::compareImagesStatistically(guided, plain.image, 0.01, 0.001, 4);
    EXPECT_TRUE(msg.empty()) << msg;
    const double z = meanDifferenceZ(guided, plain.image);
    EXPECT_GT(test::normalPValue(z), 0.001) << "z = " << z;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The same seed gives the same image with photons (their splats follow the photons' order, their
// random numbers the seed); and the photons change the image (the first iteration samples their
// guide: alpha fixed at 0.5).
TEST(Guiding, SameSeedIsBitIdenticalWithPhotons) {
  Scene scene = test::loadTestScene("scenes/cornell/cornell-indirect.glb");
  RenderSettings s = determinismSettings();
  s.guideAlpha = 0.5f;
  s.guidePhotons = 5000;
  s.maxPathsPerChunk = 2048;  // the photons in three chunks
  test::Rendered a = test::render(scene, s);
  test::Rendered b = test::render(scene, s);
  ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
  EXPECT_EQ(0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  EXPECT_EQ(a.stats.rays, b.stats.rays);
  s.guidePhotons = 0;
  test::Rendered c = test::render(scene, s);
  EXPECT_NE(0, std::memcmp(a.image.rgb.data(), c.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The photon pre-pass's splats (100000 photons, depth 1, cosine sampler) of `scene` seen from a
// camera at (0, 0.5, -3) looking along +z, 8 x 8, training 1 spp (the pass runs before it).
std::vector<guiding::PhotonSplat> photonSplatsOf(Scene scene, std::uint32_t seed) {
  scene.hasCamera = true;
  scene.camera.position = {0.0f, 0.5f, -3.0f};
  scene.camera.forward = {0.0f, 0.0f, 1.0f};
  scene.camera.up = {0.0f, 1.0f, 0.0f};
  RenderSettings s;
  s.width = s.height = 8;
  s.spp = 2;
  s.maxDepth = 1;
  s.seed = seed;
  s.sampler = SamplerKind::Cosine;
  s.guiding = true;
  s.guidePhotons = 100000;
  Renderer r(test::context(), scene, s);
  if (!r.guide()) {
    ADD_FAILURE() << "a guided render has no guide";
    return {};
  }
  r.guide()->keepPhotonSplats(true);
  r.render(1);
  return r.guide()->photonSplats();
}

// Where the photon records land: a tiny Lambert light (1e-3 square, Le = 2) at height 1 facing
// up, a Lambert ceiling (rho 0.5) at height 2 above it and a floor at 0 (both 200 wide, so
// that under 1e-3 escapes, and the rays' offset, 1/65536 of the scene's radius, is 2e-3 of the
// heights), max depth 1: every photon reaches the ceiling (direct light,
// not recorded), is reflected once, and its only record is its arrival on the floor, the one
// surface lit indirectly. Checked, with the cosine sampler (so that the ceiling reflects with
// exactly the cosine density):
//  - positions: on the floor (y = 0); the light's back, the only other surface below the ceiling,
//    subtends under 1e-5 of the ceiling's cosine-weighted hemisphere: at most the 0.999 quantile
//    of Binomial(n, 1e-5) records elsewhere;
//  - directions, towards where the photon came from: up, with cos^2 = d.y^2 uniform on [0, 1]
//    (Lambert's reflection at the ceiling, reversed);
//  - origins: the ceiling point the direction leads back to lies at horizontal distance r from
//    the light with 1 / (1 + r^2) = cos^2 of the emission angle uniform on [0, 1] (the light's
//    cosine emission from height 1);
//  both chi-square tests on 20 equal bins, significance 0.001 each (critical value 43.82, 19
//  degrees of freedom);
//  - values: each photon carries Le pi A (two triangles of area A / 2, each selected with
//    probability 1/2) times rho (the ceiling's weight under cosine sampling; no roulette before
//    bounce 3): luminance 2 x pi x 1e-6 x 0.5, to 1e-4 relative.
TEST(Guiding, PhotonRecordsLandWhereLightArrivesIndirectly) {
  Scene scene;
  auto lambert = [&](float rho, float le) {
    scene.materials.push_back(catalogueMaterial("lambert", {{"rho", ParamValue::num(rho)}}, "m", glm::vec3(le)));
    return std::uint32_t(scene.materials.size() - 1);
  };
  const std::uint32_t white = lambert(0.5f, 0.0f), lamp = lambert(0.5f, 2.0f);
  const float W = 100.0f, h = 5e-4f;
  test::addQuad(scene, {-W, 0, -W}, {-W, 0, W}, {W, 0, W}, {W, 0, -W}, white);  // floor, normal +y
  test::addQuad(scene, {-W, 2, -W}, {W, 2, -W}, {W, 2, W}, {-W, 2, W}, white);  // ceiling, normal -y
  test::addQuad(scene, {-h, 1, -h}, {-h, 1, h}, {h, 1, h}, {h, 1, -h}, lamp);   // light, normal +y
  const std::vector<guiding::PhotonSplat> splats = photonSplatsOf(scene, 9);
  const std::uint32_t n = static_cast<std::uint32_t>(splats.size());
  ASSERT_GT(n, 90000u) << "nearly every photon must arrive on the floor after its bounce";
  constexpr int kBins = 20;
  constexpr double kCritical = 43.82;  // chi-square, 19 degrees of freedom, significance 0.001
  std::vector<double> dirBins(kBins, 0), originBins(kBins, 0);
  std::uint32_t offFloor = 0, down = 0, offValue = 0;
  const double value = 2.0 * 3.14159265358979 * (2.0 * h) * (2.0 * h) * 0.5;
  for (const guiding::PhotonSplat& p : splats) {
    if (std::fabs(p.x.y) > 1e-3f) {
      ++offFloor;
      continue;
    }
    if (!(p.d.y > 0.0f)) {
      ++down;
      continue;
    }
    const double c2 = double(p.d.y) * p.d.y;
    dirBins[std::min(kBins - 1, int(c2 * kBins))] += 1;
    const glm::dvec3 o = glm::dvec3(p.x) + (2.0 - p.x.y) / p.d.y * glm::dvec3(p.d);
    const double u = 1.0 / (1.0 + o.x * o.x + o.z * o.z);
    originBins[std::min(kBins - 1, int(u * kBins))] += 1;
    if (std::fabs(p.value / value - 1.0) > 1e-4) ++offValue;
  }
  const std::uint32_t offBound = static_cast<std::uint32_t>(test::binomialUpperLimit(int(n), 1e-5, 0.001));
  EXPECT_LE(offFloor, offBound) << "records off the floor";
  EXPECT_EQ(down, 0u) << "records whose direction points away from the ceiling";
  EXPECT_EQ(offValue, 0u) << "records whose value is not the photon's power (expected " << value << ")";
  auto chi2 = [&](const std::vector<double>& bins) {
    double total = 0, x = 0;
    for (double b : bins) total += b;
    for (double b : bins) x += (b - total / kBins) * (b - total / kBins) / (total / kBins);
    return x;
  };
  const double dirChi2 = chi2(dirBins), originChi2 = chi2(originBins);
  std::printf("photon records: %u on the floor of %u (%u off), chi-square directions %.2f, origins %.2f (critical %.2f)\n",
              n - offFloor, n, offFloor, dirChi2, originChi2, kCritical);
  EXPECT_LT(dirChi2, kCritical);
  EXPECT_LT(originChi2, kCritical);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The same for a point light (intensity 1, luminance 1) at height 1 between the floor and the
// ceiling, no other light: photons leave in uniform directions, half of them up to the ceiling and
// half down to the floor (direct light, not recorded); after one bounce the first arrive on the
// floor, the others on the ceiling (half each: a z-test). Every record must lie on one of the two (at most the 0.999
// quantile of Binomial(n, 1e-5) elsewhere: nothing else is there), point towards the other, have
// d.y^2 uniform (the Lambert bounce, reversed), lead back to a point whose horizontal distance r
// from the light has 1 / sqrt(1 + r^2) = |cos| of the emission angle uniform (uniform directions
// from height 1), and carry I 4 pi rho = 2 pi (luminance; one light, selected with probability 1).
// Uniform emission sends 5 % of the photons beyond r = 20, where the planes' edges (100) let a
// share of them or of their bounces escape: both chi-square tests take only the records that lead
// back to r <= 20 (directions: 20 bins; origins: the 19 bins of u in [0.05, 1]), significance 0.001.
TEST(Guiding, PhotonRecordsFromAPointLight) {
  Scene scene;
  scene.materials.push_back(catalogueMaterial("lambert", {{"rho", ParamValue::num(0.5)}}, "white", glm::vec3(0.0f)));
  const float W = 100.0f;
  test::addQuad(scene, {-W, 0, -W}, {-W, 0, W}, {W, 0, W}, {W, 0, -W}, 0);  // floor, normal +y
  test::addQuad(scene, {-W, 2, -W}, {W, 2, -W}, {W, 2, W}, {-W, 2, W}, 0);  // ceiling, normal -y
  PunctualLight point;
  point.type = LightType::Point;
  point.position = {0.0f, 1.0f, 0.0f};
  point.intensity = glm::vec3(1.0f);
  scene.lights.push_back(point);
  const std::vector<guiding::PhotonSplat> splats = photonSplatsOf(scene, 10);
  const std::uint32_t n = static_cast<std::uint32_t>(splats.size());
  ASSERT_GT(n, 90000u) << "nearly every photon must arrive on the floor or the ceiling after its bounce";
  constexpr int kBins = 20;
  constexpr double kCritical = 43.82;  // chi-square, 19 degrees of freedom, significance 0.001
  std::vector<double> dirBins(kBins, 0), originBins(kBins, 0);
  std::uint32_t elsewhere = 0, away = 0, offValue = 0, onFloor = 0, far = 0;
  const double value = 4.0 * 3.14159265358979 * 0.5;
  for (const guiding::PhotonSplat& p : splats) {
    const bool floor = std::fabs(p.x.y) < 1e-3f, ceiling = std::fabs(p.x.y - 2.0f) < 1e-3f;
    if (!floor && !ceiling) {
      ++elsewhere;
      continue;
    }
    onFloor += floor ? 1 : 0;
    if (floor ? !(p.d.y > 0.0f) : !(p.d.y < 0.0f)) {
      ++away;
      continue;
    }
    const double t = (floor ? 2.0 : 0.0) - p.x.y;  // to the other plane
    const glm::dvec3 o = glm::dvec3(p.x) + t / p.d.y * glm::dvec3(p.d);
    const double u = 1.0 / std::sqrt(1.0 + o.x * o.x + o.z * o.z);
    if (u < 0.05) {  // r > 20: bounced where the planes' edges let some escape
      ++far;
      continue;
    }
    const double c2 = double(p.d.y) * p.d.y;
    dirBins[std::min(kBins - 1, int(c2 * kBins))] += 1;
    originBins[std::min(kBins - 1, int(u * kBins))] += 1;
    if (std::fabs(p.value / value - 1.0) > 1e-4) ++offValue;
  }
  EXPECT_LE(elsewhere, static_cast<std::uint32_t>(test::binomialUpperLimit(int(n), 1e-5, 0.001)));
  EXPECT_EQ(away, 0u) << "records whose direction points away from the plane they came from";
  EXPECT_EQ(offValue, 0u) << "records whose value is not the photon's power (expected " << value << ")";
  // Equal bins from bin `first` on (the origins' bin 0, u < 0.05, is left out).
  auto chi2 = [&](const std::vector<double>& bins, int first) {
    double total = 0, x = 0;
    for (int b = first; b < kBins; ++b) total += bins[b];
    const double e = total / (kBins - first);
    for (int b = first; b < kBins; ++b) x += (bins[b] - e) * (bins[b] - e) / e;
    return x;
  };
  constexpr double kCritical18 = 42.31;  // 18 degrees of freedom, significance 0.001
  const double dirChi2 = chi2(dirBins, 0), originChi2 = chi2(originBins, 1);
  std::printf("point-light photon records: %u, %u on the floor, %u elsewhere, %u from r > 20; chi-square directions "
              "%.2f (critical %.2f), origins %.2f (critical %.2f)\n",
              n, onFloor, elsewhere, far, dirChi2, kCritical, originChi2, kCritical18);
  EXPECT_LT(dirChi2, kCritical);
  EXPECT_LT(originChi2, kCritical18);
  // Up and down alike: the floor's share of the records is 1/2 (the geometry is symmetric about
  // the light's plane), two-sided z-test at significance 0.001.
  const double zFloor = (onFloor - 0.5 * n) / (0.5 * std::sqrt(double(n)));
  EXPECT_LT(std::fabs(zFloor), 3.29) << "floor records " << onFloor << " of " << n;
  EXPECT_EQ(test::validationMessages(), 0u);
}
