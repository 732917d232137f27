// The default Cornell box against a stored high-spp reference (tests/data/refs, made by
// tools/make_references.sh): a per-pixel z-test whose failure count must be consistent with
// the chosen per-pixel significance (binomial bound), not a hand-tuned tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "../support/test_support.h"
#include "cli/cli_common.h"

using namespace nusselt;


namespace {

Scene defaultScene() { return loadSceneOrDefault("", ""); }

// Renders the default scene at the reference's size and depth with 128 spp and compares it with
// the stored reference: per-pixel z-tests (binomial bound on failures, significance 0.001) plus
// the image mean, with the reference's per-sample variance standing in for the test render's.
void expectMatchesReference(RngMode rng, std::uint32_t seed) {
  ImageMetadata meta;
  Image ref = readExr(test::sourcePath("tests/data/refs/cornell-box.exr"), &meta);
  ASSERT_FALSE(ref.variance.empty()) << "the reference must carry its variance channels";
  RenderSettings s;
  s.width = ref.width;
  s.height = ref.height;
  s.spp = 128;
  s.seed = seed;  // the reference used other seeds: the two estimates are independent
  s.rng = rng;
  s.maxDepth = static_cast<std::uint32_t>(findInt(meta, "nusselt/maxDepth").value_or(8));
  test::Rendered r = test::render(defaultScene(), s);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  const double refSpp = double(findInt(meta, "nusselt/spp").value_or(0));
  ASSERT_GT(refSpp, s.spp * 16.0) << "the reference must have many more samples than the test render";
  std::string msg = test::compareImagesStatistically(r.image, ref, 0.01, 0.001, 1, refSpp / s.spp);
  EXPECT_TRUE(msg.empty()) << msg;
  EXPECT_EQ(test::validationMessages(), 0u);
}

}  // namespace

TEST(Cornell, MatchesStoredReference) { expectMatchesReference(RngMode::Pcg, 7); }

TEST(Cornell, SameSeedIsBitIdenticalOtherSeedIsNot) {
  Scene scene = defaultScene();
  RenderSettings s;
  s.width = 20;
  s.height = 16;
  s.spp = 3;
  s.seed = 42;
  test::Rendered a = test::render(scene, s);
  test::Rendered b = test::render(scene, s);
  ASSERT_EQ(a.image.rgb.size(), b.image.rgb.size());
  EXPECT_EQ(0, std::memcmp(a.image.rgb.data(), b.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  s.seed = 43;
  test::Rendered c = test::render(scene, s);
  EXPECT_NE(0, std::memcmp(a.image.rgb.data(), c.image.rgb.data(), a.image.rgb.size() * sizeof(float)));
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Cornell, ChunkedPassesEqualOneChunk) {
  // A frame split into several chunks of paths must give the same image as one chunk.
  Scene scene = defaultScene();
  RenderSettings s;
  s.width = 24;
  s.height = 20;
  s.spp = 2;
  test::Rendered whole = test::render(scene, s);
  s.maxPathsPerChunk = 100;  // 480 pixels in 5 chunks
  test::Rendered chunked = test::render(scene, s);
  EXPECT_EQ(0, std::memcmp(whole.image.rgb.data(), chunked.image.rgb.data(), whole.image.rgb.size() * sizeof(float)));
}

TEST(Cornell, SamplesPerPassDoNotChangeTheImage) {
  // A pass of K samples per pixel sums the same samples in the same order as K passes of one:
  // the image and its variance are bit-identical whatever the grouping, including chunks that
  // split a pixel's samples (97 paths per chunk) and a last pass shorter than K (7 = 3 + 3 + 1).
  Scene scene = defaultScene();
  RenderSettings s;
  s.width = 24;
  s.height = 20;
  s.spp = 7;
  s.samplesPerPass = 1;
  test::Rendered one = test::render(scene, s);
  for (std::uint32_t k : {3u, 7u}) {
    for (std::uint32_t chunk : {1u << 20, 97u}) {
      SCOPED_TRACE("samples per pass " + std::to_string(k) + ", paths per chunk " + std::to_string(chunk));
      s.samplesPerPass = k;
      s.maxPathsPerChunk = chunk;
      test::Rendered grouped = test::render(scene, s);
      ASSERT_EQ(one.image.rgb.size(), grouped.image.rgb.size());
      EXPECT_EQ(0, std::memcmp(one.image.rgb.data(), grouped.image.rgb.data(), one.image.rgb.size() * sizeof(float)));
      ASSERT_EQ(one.image.variance.size(), grouped.image.variance.size());
      EXPECT_EQ(0, std::memcmp(one.image.variance.data(), grouped.image.variance.data(),
                               one.image.variance.size() * sizeof(float)));
      EXPECT_EQ(one.stats.rays, grouped.stats.rays);
    }
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Cornell, StageTimestampsCoverEveryStage) {
  Scene scene = defaultScene();
  RenderSettings s;
  s.width = 16;
  s.height = 16;
  s.spp = 2;
  s.timeStages = true;
  Renderer r(test::context(), scene, s);
  r.render(2);
  std::vector<std::string> names;
  for (auto& [name, seconds] : r.stageSeconds()) {
    names.push_back(name);
    EXPECT_GE(seconds, 0.0) << name;
  }
  // Every stage, and each shade pipeline by its model's name (the Cornell box is all Lambert).
  for (const char* stage : {"camera", "intersect", "shade lambert", "shadow", "accumulate"})
    EXPECT_NE(std::find(names.begin(), names.end(), stage), names.end()) << stage;
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Cornell, QmcConvergesToTheSameImage) {
  // Quasi-Monte Carlo samples are not independent, so their own variance estimate is not used:
  // the reference's per-sample variance (independent PCG samples) stands in, an upper bound on
  // the QMC error, which makes the test conservative, never loose.
  expectMatchesReference(RngMode::Qmc, 8);
}
