// One definition of every BRDF: the C++ build of shaders/shared/brdf/*.h and the GLSL build
// running on the Vulkan device evaluate the same function. 10,000 direction pairs per model and
// parameter set, including normal incidence, directions within 1e-4 rad of grazing and the
// mirror configuration.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../support/test_support.h"
#include "brdf/registry.h"

using namespace nusselt;
using shared::vec3;

namespace {

std::vector<std::pair<vec3, vec3>> directionPairs(std::uint32_t seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  auto dir = [&](float theta, float phi) {
    return vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  const float half = float(M_PI) / 2;
  std::vector<float> specialThetas = {0.0f, 1e-4f, 0.3f, 1.0f, half - 1e-2f, half - 1e-3f, half - 1e-4f};
  std::vector<std::pair<vec3, vec3>> pairs;
  for (float ti : specialThetas)
    for (float to : specialThetas) {
      pairs.push_back({dir(ti, 0.0f), dir(to, float(M_PI))});     // plane of incidence, mirror side
      pairs.push_back({dir(ti, 0.3f), dir(to, 0.3f)});             // back-scatter side
      pairs.push_back({dir(ti, 1.0f), dir(to, 1.0f + half)});      // crossed
    }
  // Exact mirror configurations (peaks of most lobes).
  for (int i = 0; i < 200; ++i) {
    float t = half * U(rng), p = 2 * float(M_PI) * U(rng);
    pairs.push_back({dir(t, p), dir(t, p + float(M_PI))});
  }
  while (int(pairs.size()) < n) {
    // Cosine-distributed and uniformly distributed directions, some pushed to grazing.
    float ti = std::acos(std::sqrt(U(rng))), to = std::acos(U(rng));
    if (U(rng) < 0.1f) to = half - 1e-4f * U(rng);
    pairs.push_back({dir(ti, 2 * float(M_PI) * U(rng)), dir(to, 2 * float(M_PI) * U(rng))});
  }
  pairs.resize(n);
  return pairs;
}

}  // namespace

// The bound at each pair: test::BrdfParityKernel (4x the C++ value's change under 4-ulp moves of
// the directions, plus 16 ulps).
TEST(BrdfParity, CpuAndGpuEvaluateTheSameFunction) {
  const int n = 10000;
  test::BrdfParityKernel kernel(directionPairs(1234, n));
  const float ulp = std::ldexp(1.0f, -23);
  int failedSets = 0;
  for (const ModelSpec& model : allModels()) {
    if (model.delta) continue;
    std::vector<std::pair<std::string, NamedParams>> sets = {{"typical", typicalParams(model)}, {"hard", hardParams(model)}};
    for (auto& v : model.variants) sets.push_back(v);
    for (auto& [setName, values] : sets) {
      BrdfParams params = packParams(model, values, model.name + "/" + setName);
      test::BrdfParityKernel::Result r = kernel.run(model.id, params);
      std::printf("[parity] %-18s %-16s worst relative difference %.3g (%.1f ulp), worst |diff|/bound %.3f\n",
                  model.name.c_str(), setName.c_str(), r.worstRel, r.worstRel / ulp, r.worstRatio);
      EXPECT_EQ(r.nonFinite, 0) << model.name << "/" << setName << ": GPU values that are NaN or infinite";
      if (r.outside) {
        ++failedSets;
        vec3 wi = kernel.pairs()[std::size_t(r.worstIndex)].first, wo = kernel.pairs()[std::size_t(r.worstIndex)].second;
        ADD_FAILURE() << model.name << "/" << setName << ": " << r.outside << " of " << n
                      << " pairs outside the bound; worst at pair " << r.worstIndex << " wi (" << wi.x << ", " << wi.y << ", "
                      << wi.z << ") wo (" << wo.x << ", " << wo.y << ", " << wo.z << "): |diff|/bound " << r.worstRatio;
      }
    }
  }
  EXPECT_EQ(failedSets, 0);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The transmitting models (ModelSpec::transmits: rough_dielectric, rough_thin_dielectric) across
// the surface and from the back: the same direction pairs with wi turned below the surface
// (transmission), and with both below (the back side), the bound as above.
TEST(BrdfParity, TransmittingModelsAgreeBelowTheSurface) {
  const int n = 10000;
  std::vector<std::pair<vec3, vec3>> pairs = directionPairs(4321, n);
  for (int k = 0; k < n; ++k) {
    vec3& wi = pairs[std::size_t(k)].first;
    wi.z = -wi.z;
    if (k % 2) pairs[std::size_t(k)].second.z = -pairs[std::size_t(k)].second.z;  // both below
  }
  test::BrdfParityKernel kernel(pairs);
  const float ulp = std::ldexp(1.0f, -23);
  int models = 0;
  for (const ModelSpec& model : allModels()) {
    if (!model.transmits) continue;
    ++models;
    for (auto& [setName, values] : {std::pair{std::string("typical"), typicalParams(model)},
                                    std::pair{std::string("hard"), hardParams(model)}}) {
      BrdfParams params = packParams(model, values, model.name + "/" + setName);
      test::BrdfParityKernel::Result r = kernel.run(model.id, params);
      std::printf("[parity below] %-22s %-8s worst relative difference %.3g (%.1f ulp), worst |diff|/bound %.3f\n",
                  model.name.c_str(), setName.c_str(), r.worstRel, r.worstRel / ulp, r.worstRatio);
      EXPECT_EQ(r.nonFinite, 0) << model.name << "/" << setName;
      EXPECT_EQ(r.outside, 0) << model.name << "/" << setName << ": worst at pair " << r.worstIndex << ", |diff|/bound "
                              << r.worstRatio;
    }
  }
  EXPECT_EQ(models, 2);
  EXPECT_EQ(test::validationMessages(), 0u);
}
