// test_binned_gpu.cpp: binned sampling of textured gltf_pbr (shaders/shared/bsdf_sampling.h,
// "Binned sampling") on the GPU (the sample tool specialised with BINNED, the same shared code as
// the CPU): chi-square of 2^20 GPU samples against the CPU's binnedPdf (16 x 32 equal-probability
// bins from an independent CPU pilot run, a failure bin; significance 0.01 with Bonferroni over the
// 4 cases; tests/unit/test_quadtree_chi2.h), no trial failures, 4 uniform bins.
// Sample-by-sample parity with the CPU is printed, not required: the component and bin are chosen
// by remapping u.x with c_d and t, which the two compilers round differently (pow, exp, atan2 in
// quadAlbedo), and the quadtree keys its further numbers on the exact bits of the remapped u
// (rngStreamKey), so a last-bit difference gives another, equally distributed, sample (measured:
// 4000/4000 alike for the glossy metal, 599 to 3863 of 4000 for the others).
#include <gtest/gtest.h>

#include <cstdio>

#include "../../shaders/shared/bsdf_sampling.h"
#include "../support/test_support.h"
#include "../unit/test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

TEST(BinnedGpu, ChiSquareAgainstTheCpuPdf) {
  vk::Context& ctx = test::context();
  const RoughnessBins B{0u, 4u, 1.0f, 0u};
  std::vector<std::pair<std::uint32_t, BrdfParams>> list;
  for (std::uint32_t j = 0; j < B.count; ++j) list.push_back({MODEL_GLTF_PBR, binParams(binRoughness(B, j))});
  std::vector<std::uint32_t> idx;
  const quadtree::SamplerTables t = quadtree::buildSamplerTables(list, qttest::testSettings(), idx);
  struct C {
    vec3 base;
    float metallic, roughness;
    double theta;
  };
  const C cases[] = {{vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.8f, 37.3},
                     {vec3(0.95f, 0.64f, 0.54f), 1.0f, 0.2f, 60.0},
                     {vec3(0.9f), 1.0f, 0.06f, 30.0},
                     {vec3(0.6f, 0.7f, 0.2f), 0.5f, binRoughness(B, 1u), 85.0}};
  const double alpha = 0.01 / 4;
  for (const C& c : cases) {
    BrdfParams p{};
    p.v[0] = vec4(c.base, c.metallic);
    p.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = c.roughness;
    const vec3 v = qttest::knownDirection(qttest::Case{"gltf_pbr", false, c.theta, 0});
    quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, INVALID_INDEX, MODEL_GLTF_PBR, p, v, qttest::kSamples, 777u,
                                                  SAMPLER_QUADTREE, nullptr, false, 0, 1u << 20, &B);
    EXPECT_EQ(g.trialFailures, 0u);
    std::vector<vec4> pilot(qttest::kPilotSamples), cpu(4000);
    {
      quadtree::QuadHostScope scope(t);
      for (std::uint32_t i = 0; i < qttest::kPilotSamples; ++i) {
        vec3 wi, f;
        float pdf;
        pilot[i] = binnedSample(B, p, v, rng2(i, 0u, RNG_DIM_BSDF, 99u), wi, pdf, f) ? vec4(wi, pdf) : vec4(0.0f);
        if (i < cpu.size())
          cpu[i] = binnedSample(B, p, v, rng2(i, 0u, RNG_DIM_BSDF, 777u), wi, pdf, f) ? vec4(wi, pdf) : vec4(0.0f);
      }
    }
    qttest::Binning bins = qttest::quantileBinning(pilot, 16, 32);
    std::vector<double> prob = qttest::binProbabilities([&](vec3 w) { return double(binnedPdf(B, p, v, w)); }, bins, pilot,
                                                        [&]() { return std::make_shared<quadtree::QuadHostScope>(t); });
    qttest::Chi2Result r = qttest::chiSquare(bins, prob, g.wPdf);
    quadtree::SampleBatch cpuBatch;
    cpuBatch.wPdf = cpu;
    const int same = qttest::sameSamples(g, cpuBatch, int(cpu.size()));
    std::printf("r %.3f metallic %.1f theta %.1f: chi2 %.1f, dof %d, p %.3g; parity with the CPU %d/%zu\n", c.roughness,
                c.metallic, c.theta, r.chi2, r.dof, r.pValue, same, cpu.size());
    EXPECT_GT(r.pValue, alpha) << r.dump;
    EXPECT_NEAR(r.expectedTotal, 1.0 - r.failedObserved / double(qttest::kSamples), 2e-3);
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
