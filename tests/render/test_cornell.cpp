// The default Cornell box against a stored high-spp reference (tests/data/refs, made by
// tools/make_references.sh): a per-pixel z-test whose failure count must be consistent with
// the chosen per-pixel significance (binomial bound), not a hand-tuned tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "../support/test_support.h"
#include "scene/gltf_loader.h"

using namespace nusselt;

namespace nusselt {
extern const unsigned char kDefaultSceneBytes[];
extern const std::size_t kDefaultSceneSize;
}  // namespace nusselt

TEST(Cornell, MatchesStoredReference) {
  ImageMetadata meta;
  Image ref = readExr(test::sourcePath("tests/data/refs/cornell-box.exr"), &meta);
  ASSERT_FALSE(ref.variance.empty()) << "the reference must carry its variance channels";
  Scene scene = loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene");
  RenderSettings s;
  s.width = ref.width;
  s.height = ref.height;
  s.spp = 128;
  s.seed = 7;  // the reference used other seeds: the two estimates are independent
  s.maxDepth = static_cast<std::uint32_t>(findInt(meta, "nusselt/maxDepth").value_or(8));
  test::Rendered r = test::render(scene, s);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  const double refSpp = double(findInt(meta, "nusselt/spp").value_or(0));
  ASSERT_GT(refSpp, s.spp * 16.0) << "the reference must have many more samples than the test render";
  std::string msg = test::compareImagesStatistically(r.image, ref, 0.01, 0.001, 1, refSpp / s.spp);
  EXPECT_TRUE(msg.empty()) << msg;
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Cornell, SameSeedIsBitIdenticalOtherSeedIsNot) {
  Scene scene = loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene");
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
  Scene scene = loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene");
  RenderSettings s;
  s.width = 24;
  s.height = 20;
  s.spp = 2;
  test::Rendered whole = test::render(scene, s);
  s.maxPathsPerChunk = 100;  // 480 pixels in 5 chunks
  test::Rendered chunked = test::render(scene, s);
  EXPECT_EQ(0, std::memcmp(whole.image.rgb.data(), chunked.image.rgb.data(), whole.image.rgb.size() * sizeof(float)));
}

TEST(Cornell, StageTimestampsCoverEveryStage) {
  Scene scene = loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene");
  RenderSettings s;
  s.width = 16;
  s.height = 16;
  s.spp = 2;
  s.timeStages = true;
  Renderer r(test::context(), scene, s);
  r.renderPass();
  r.renderPass();
  std::vector<std::string> names;
  for (auto& [name, seconds] : r.stageSeconds()) {
    names.push_back(name);
    EXPECT_GE(seconds, 0.0) << name;
  }
  for (const char* stage : {"camera", "submit", "intersect", "shade", "shadow", "accumulate"})
    EXPECT_NE(std::find(names.begin(), names.end(), stage), names.end()) << stage;
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(Cornell, QmcConvergesToTheSameImage) {
  // Quasi-Monte Carlo samples are not independent, so their own variance estimate is not used:
  // the reference's per-sample variance (independent PCG samples) stands in, an upper bound on
  // the QMC error, which makes the test conservative, never loose.
  ImageMetadata meta;
  Image ref = readExr(test::sourcePath("tests/data/refs/cornell-box.exr"), &meta);
  Scene scene = loadSceneFromMemory(kDefaultSceneBytes, kDefaultSceneSize, "default scene");
  RenderSettings s;
  s.width = ref.width;
  s.height = ref.height;
  s.spp = 128;
  s.seed = 8;
  s.rng = RngMode::Qmc;
  s.maxDepth = static_cast<std::uint32_t>(findInt(meta, "nusselt/maxDepth").value_or(8));
  test::Rendered r = test::render(scene, s);
  const double refSpp = double(findInt(meta, "nusselt/spp").value_or(0));
  std::string msg = test::compareImagesStatistically(r.image, ref, 0.01, 0.001, 1, refSpp / s.spp);
  EXPECT_TRUE(msg.empty()) << msg;
  EXPECT_EQ(test::validationMessages(), 0u);
}
