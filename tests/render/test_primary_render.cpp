// test_primary_render.cpp: a path of the wavefront path tracer is a function of its primary sample
// vector (issue 19): with PRIMARY_SAMPLES on, two path slots of one pixel with different sample
// indices (so every hashed number would differ) that read the same vector trace the same path,
// bit for bit; slots with different vectors trace different paths.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <random>

#include "../support/test_support.h"
#include "cli/cli_common.h"
#include "render/path_integrator.h"
#include "../../shaders/shared/layout.h"
#include "../../shaders/shared/mlt.h"

using namespace nusselt;

TEST(PrimaryRender, SameVectorSamePathOtherVectorOtherPath) {
  Scene scene = loadSceneOrDefault("", "");  // the Cornell box: diffuse bounces, an area light
  RenderSettings s;
  s.width = 16;
  s.height = 16;
  s.spp = 2;
  s.samplesPerPass = 2;  // path slot 2p + k: sample k of pixel p, one chunk
  s.maxDepth = 5;
  s.seed = 3;
  s.primarySamples = true;
  Renderer r(test::context(), scene, s);
  PathIntegrator& paths = r.paths();
  const std::uint32_t dims = PathIntegrator::primaryDimsFor(s.maxDepth);
  const std::uint32_t pixels = s.width * s.height, slots = 2 * pixels;
  ASSERT_GE(paths.capacity(), slots);
  // Even pixels: both samples read the same vector; odd pixels: two independent vectors.
  std::mt19937 prng(11);
  // Draw d of slot i at primarySampleIndex(i, d, dims) (layout.h).
  std::vector<glm::vec2> u(std::size_t(shared::primarySampleSlots(paths.capacity())) * dims);
  for (glm::vec2& x : u) x = glm::vec2(float(prng() >> 8), float(prng() >> 8)) * (1.0f / 16777216.0f);
  for (std::uint32_t p = 0; p < pixels; p += 2)
    for (std::uint32_t d = 0; d < dims; ++d)
      u[shared::primarySampleIndex(2 * p + 1, d, dims)] = u[shared::primarySampleIndex(2 * p, d, dims)];
  vk::uploadBuffer(test::context(), paths.primarySamples(), u.data(), u.size() * 8);
  r.renderPass(2);
  std::vector<glm::vec4> L(slots);
  vk::downloadBuffer(test::context(), paths.pathRadiance(), L.data(), slots * 16);

  int sameNonzero = 0, sameDiffer = 0, otherNonzero = 0, otherEqual = 0;
  for (std::uint32_t p = 0; p < pixels; ++p) {
    const bool equal = std::memcmp(&L[2 * p], &L[2 * p + 1], 12) == 0;
    const bool nonzero = L[2 * p] != glm::vec4(0.0f) || L[2 * p + 1] != glm::vec4(0.0f);
    if (p % 2 == 0) {
      sameNonzero += nonzero;
      sameDiffer += !equal;
    } else if (nonzero) {
      ++otherNonzero;
      otherEqual += equal;
    }
  }
  EXPECT_EQ(sameDiffer, 0) << "paths replayed from the same primary vector differ";
  // Most Cornell-box paths carry light (walls lit directly, no escape); the test is void otherwise.
  EXPECT_GE(sameNonzero, int(pixels / 2) * 3 / 4);
  ASSERT_GE(otherNonzero, int(pixels / 2) * 3 / 4);
  // Two independent vectors give equal radiance only when the path sees the light's emission and
  // nothing else it gathers differs (camera rays into the light: a few pixels of 256) or the vectors
  // lead to the same constant value; at most 10 % of the pairs, far above what 16x16 Cornell pixels
  // put on the light (about 2 %).
  EXPECT_LE(otherEqual, otherNonzero / 10) << "different primary vectors gave the same radiance";
  EXPECT_EQ(test::validationMessages(), 0u);
}

// 16 x 16 paths of one sample each (slot i: pixel i) that read their draws from primary sample
// vectors we choose: traced from a set of vectors, their radiance and path info per slot.
struct Replay {
  static RenderSettings settings(std::uint32_t maxDepth, std::uint32_t seed) {
    RenderSettings s;
    s.width = 16;
    s.height = 16;
    s.spp = 1;
    s.samplesPerPass = 1;
    s.maxDepth = maxDepth;
    s.seed = seed;
    s.primarySamples = true;
    return s;
  }
  Replay(const Scene& scene, std::uint32_t maxDepth, std::uint32_t seed, std::uint32_t prngSeed)
      : r(test::context(), scene, settings(maxDepth, seed)), dims(PathIntegrator::primaryDimsFor(maxDepth)), prng(prngSeed) {}
  glm::vec2 fresh() { return glm::vec2(float(prng() >> 8), float(prng() >> 8)) * (1.0f / 16777216.0f); }
  // Every draw of every slot fresh.
  std::vector<glm::vec2> vectors() {
    std::vector<glm::vec2> u(std::size_t(shared::primarySampleSlots(r.paths().capacity())) * dims);
    for (glm::vec2& x : u) x = fresh();
    return u;
  }
  std::size_t at(std::uint32_t slot, std::uint32_t dimension) const { return shared::primarySampleIndex(slot, dimension, dims); }
  void trace(const std::vector<glm::vec2>& v, std::vector<glm::vec4>& L, std::vector<glm::uvec4>& info) {
    PathIntegrator& paths = r.paths();
    vk::uploadBuffer(test::context(), paths.primarySamples(), v.data(), v.size() * 8);
    r.renderPass(1);
    L.resize(slots);
    info.resize(slots);
    vk::downloadBuffer(test::context(), paths.pathRadiance(), L.data(), slots * 16);
    vk::downloadBuffer(test::context(), paths.pathInfo(), info.data(), slots * 16);
  }
  Renderer r;
  const std::uint32_t dims;
  const std::uint32_t slots = 16 * 16;
  std::mt19937 prng;
};

// A Metropolis small step moves only the draws its current path read and draws the others fresh
// (mlt.h, mltExtent of the bounces the shade stage records in pathInfo.z). That is exact only if
// the recorded extent covers every draw the path read: here every draw beyond it is replaced and
// the path must not change, bit for bit; replacing the last shaded bounce's light-point draw (read
// by its light sample) must change most paths, so an extent one bounce short would fail.
TEST(PrimaryRender, DrawsBeyondTheRecordedExtentAreNotRead) {
  Scene scene = loadSceneOrDefault("", "");
  Replay replay(scene, 5, 5, 17);
  const std::uint32_t dims = replay.dims, slots = replay.slots;
  std::vector<glm::vec2> u = replay.vectors();
  std::vector<glm::vec4> L0, L1, L2;
  std::vector<glm::uvec4> info0, info1, info2;
  replay.trace(u, L0, info0);

  std::vector<glm::vec2> beyond = u, lastRead = u;
  int shortPaths = 0, lit = 0;
  for (std::uint32_t i = 0; i < slots; ++i) {
    const std::uint32_t extent = shared::mltExtent(info0[i].z, dims);
    shortPaths += extent < dims;
    for (std::uint32_t d = extent; d < dims; ++d) beyond[replay.at(i, d)] = replay.fresh();
    if (info0[i].z > 0) {
      lastRead[replay.at(i, shared::rngDimension(info0[i].z - 1, RNG_DIM_LIGHT_POINT))] = replay.fresh();
      lit += L0[i] != glm::vec4(0.0f);
    }
  }
  replay.trace(beyond, L1, info1);
  int changed = 0;
  for (std::uint32_t i = 0; i < slots; ++i) changed += std::memcmp(&L0[i], &L1[i], 12) != 0 || info0[i].z != info1[i].z;
  EXPECT_EQ(changed, 0) << "a draw beyond a path's recorded extent changed the path";
  // Not void: many paths end before the last bounce (roulette), so draws beyond them were replaced.
  EXPECT_GE(shortPaths, int(slots) / 4);

  replay.trace(lastRead, L2, info2);
  int changedLast = 0;
  for (std::uint32_t i = 0; i < slots; ++i) changedLast += std::memcmp(&L0[i], &L2[i], 12) != 0;
  // The last vertex's light sample moves with its point: most lit paths change (a point that stays
  // unoccluded with the same contribution, or both occluded, is rare on the Cornell box's light).
  EXPECT_GE(changedLast, lit / 2) << "the last shaded bounce's light-point draw seems unread";
  std::printf("%d of %u paths end before depth %u; replacing the draws beyond their extent changed %d; "
              "replacing the last bounce's light point changed %d of %d lit paths\n",
              shortPaths, slots, replay.r.settings().maxDepth, changed, changedLast, lit);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// Metropolis moves and keeps only the draws an unguided path may read (rng.h, rngReadUnguided:
// the camera's draw 0 and the slots RNG_SLOTS_UNGUIDED of each bounce; mlt.h, mltReadsDraw). Here
// every other draw of every path slot is replaced and the paths must not change, bit for bit, on
// scenes whose paths read each slot: the Cornell box (light sample, cosine sampler, roulette),
// combined materials (the component choice, mirror and glass) and the glossy Cornell box (gltf_pbr's
// quadtree sampler, whose rejection stream is keyed on its primary draws). Not void: replacing the
// first bounce's BSDF draw changes most paths that scatter there.
TEST(PrimaryRender, DrawsOutsideTheReadSlotsAreNotRead) {
  for (const std::string file : {std::string(), std::string("scenes/tests/combined.gltf"),
                                 std::string("scenes/cornell/cornell-glossy.glb")}) {
    SCOPED_TRACE(file.empty() ? "default scene" : file);
    Scene scene = file.empty() ? loadSceneOrDefault("", "") : test::loadTestScene(file);
    Replay replay(scene, 6, 7, 23);
    const std::uint32_t dims = replay.dims, slots = replay.slots;
    std::vector<glm::vec2> u = replay.vectors();
    std::vector<glm::vec4> L0, L1, L2;
    std::vector<glm::uvec4> info0, info1, info2;
    replay.trace(u, L0, info0);
    std::vector<glm::vec2> unread = u, bsdf = u;
    std::uint32_t replaced = 0, scattered = 0, deep = 0;
    for (std::uint32_t i = 0; i < slots; ++i) {
      for (std::uint32_t d = 0; d < dims; ++d)
        if (!shared::mltReadsDraw(d)) {
          unread[replay.at(i, d)] = replay.fresh();
          ++replaced;
        }
      scattered += info0[i].z > 0;
      deep += info0[i].z >= 3;  // past the bounces before the roulette starts
      bsdf[replay.at(i, shared::rngDimension(0, RNG_DIM_BSDF))] = replay.fresh();
    }
    replay.trace(unread, L1, info1);
    int changed = 0;
    for (std::uint32_t i = 0; i < slots; ++i) changed += std::memcmp(&L0[i], &L1[i], 12) != 0 || info0[i].z != info1[i].z;
    EXPECT_EQ(changed, 0) << "a draw outside the read slots changed the path";
    replay.trace(bsdf, L2, info2);
    int changedBsdf = 0;
    for (std::uint32_t i = 0; i < slots; ++i) changedBsdf += std::memcmp(&L0[i], &L2[i], 12) != 0 || info0[i].z != info2[i].z;
    EXPECT_GE(changedBsdf, int(scattered) / 2) << "the first bounce's BSDF draw seems unread";
    // Not void: paths reach the roulette's bounces, so its slot and the later ones are read.
    EXPECT_GE(deep, slots / 8);
    std::printf("%u draws replaced; paths changed: %d; %u of %u paths scatter, %u reach bounce 3; replacing the first "
                "BSDF draw changed %d\n",
                replaced, changed, scattered, slots, deep, changedBsdf);
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
