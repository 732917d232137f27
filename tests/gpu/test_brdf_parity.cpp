// One definition of every BRDF: the C++ build of shaders/shared/brdf/*.h and the GLSL build
// running on the Vulkan device evaluate the same function. 10,000 direction pairs per model and
// parameter set, including normal incidence, directions within 1e-4 rad of grazing and the
// mirror configuration.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
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

TEST(BrdfParity, CpuAndGpuEvaluateTheSameFunction) {
  const int n = 10000;
  auto pairs = directionPairs(1234, n);
  vk::Context& ctx = test::context();
  vk::Buffer pairBuf = vk::createBuffer(ctx, n * 32, 0, true, "pairs");
  vk::Buffer paramBuf = vk::createBuffer(ctx, sizeof(BrdfParams), 0, true, "params");
  vk::Buffer resultBuf = vk::createBuffer(ctx, n * 16, 0, true, "results");
  for (int i = 0; i < n; ++i) {
    float* p = static_cast<float*>(pairBuf.mapped) + 8 * i;
    for (int c = 0; c < 3; ++c) {
      p[c] = pairs[i].first[c];
      p[4 + c] = pairs[i].second[c];
    }
  }
  struct Push {
    std::uint64_t pairs, params, result;
    std::uint32_t count, pad;
    std::uint64_t measured;  // merl's tables (tests/gpu/test_merl_gpu.cpp); none here
  } push{pairBuf.address, paramBuf.address, resultBuf.address, std::uint32_t(n), 0, 0};

  // Tolerance: the two builds round differently (fused multiply-adds, LLVM's vs glibc's exp, pow,
  // sin...), by a few ulps per operation; what that does to f depends on how sensitive f is at
  // the pair (pow(x, 10000) multiplies the relative error of x by 10^4; tan near 90 degrees, a
  // shadowing boundary...). So the bound at each pair is measured on the CPU build itself: the
  // largest change of f when the directions' components move by up to 4 ulps (6 perturbations),
  // and the GPU value must lie within 4x that change plus 16 ulps of f:
  //   |gpu - cpu| <= 4 * sensitivity + 16 ulp * |cpu| + 1e-30.
  const float ulp = std::ldexp(1.0f, -23);
  std::mt19937 prng(99);
  std::uniform_int_distribution<int> step(-4, 4);
  auto perturb = [&](vec3 w) {
    for (int c = 0; c < 3; ++c) w[c] *= 1.0f + step(prng) * ulp;
    return w;
  };
  int failedSets = 0;
  for (const ModelSpec& model : allModels()) {
    if (model.delta) continue;
    std::vector<std::pair<std::string, NamedParams>> sets = {{"typical", typicalParams(model)}, {"hard", hardParams(model)}};
    for (auto& v : model.variants) sets.push_back(v);
    for (auto& [setName, values] : sets) {
      BrdfParams params = packParams(model, values, model.name + "/" + setName);
      std::memcpy(paramBuf.mapped, &params, sizeof params);
      test::runKernel("eval_brdf", {model.id}, &push, sizeof push, n);
      const float* gpu = static_cast<const float*>(resultBuf.mapped);
      double worstRel = 0, worstRatio = 0;
      int worstIndex = -1, outside = 0;
      for (int i = 0; i < n; ++i) {
        vec3 cpu = shared::brdfEval(model.id, params, pairs[i].first, pairs[i].second);
        vec3 sensitivity(0.0f);
        for (int k = 0; k < 6; ++k) {
          vec3 moved = shared::brdfEval(model.id, params, perturb(pairs[i].first), perturb(pairs[i].second));
          for (int c = 0; c < 3; ++c) sensitivity[c] = std::max(sensitivity[c], std::fabs(moved[c] - cpu[c]));
        }
        bool bad = false;
        for (int c = 0; c < 3; ++c) {
          double a = gpu[4 * i + c], b = cpu[c];
          ASSERT_TRUE(std::isfinite(a)) << model.name << "/" << setName << " pair " << i << ": GPU value " << a;
          double bound = 4.0 * sensitivity[c] + 16.0 * ulp * std::fabs(b) + 1e-30;
          double diff = std::fabs(a - b);
          double scale = std::max(std::fabs(a), std::fabs(b));
          if (scale > 1e-30) worstRel = std::max(worstRel, diff / scale);
          if (diff / bound > worstRatio) {
            worstRatio = diff / bound;
            worstIndex = i;
          }
          bad = bad || diff > bound;
        }
        outside += bad;
      }
      std::printf("[parity] %-18s %-16s worst relative difference %.3g (%.1f ulp), worst |diff|/bound %.3f\n",
                  model.name.c_str(), setName.c_str(), worstRel, worstRel / ulp, worstRatio);
      if (outside) {
        ++failedSets;
        vec3 wi = pairs[worstIndex].first, wo = pairs[worstIndex].second;
        ADD_FAILURE() << model.name << "/" << setName << ": " << outside << " of " << n
                      << " pairs outside the bound; worst at pair " << worstIndex << " wi (" << wi.x << ", " << wi.y << ", "
                      << wi.z << ") wo (" << wo.x << ", " << wo.y << ", " << wo.z << "): |diff|/bound " << worstRatio;
      }
    }
  }
  EXPECT_EQ(failedSets, 0);
  vk::destroyBuffer(ctx, pairBuf);
  vk::destroyBuffer(ctx, paramBuf);
  vk::destroyBuffer(ctx, resultBuf);
  EXPECT_EQ(test::validationMessages(), 0u);
}
