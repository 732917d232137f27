// test_merl_gpu.cpp: the measured model on the GPU: the GLSL interpolation against the C++ one
// (the table as float in a buffer), and the quadtree sampler over the table (chi-square, no
// bound violations or trial failures, CPU/GPU parity), with tabulated files written at test time.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "../support/test_support.h"
#include "../unit/test_merl_common.h"

using namespace nusselt;
using namespace nusselt::shared;

// GLSL (eval_brdf, the table in a storage buffer read through its device address) against C++ at
// 10,000 direction pairs: the same float operations on both sides, so the bound is that of the
// catalogue's parity test: |gpu - cpu| <= 4 * (change of the C++ value under 4-ulp moves of the
// directions) + 16 ulp.
TEST(MerlGpu, ParityWithCpu) {
  const int n = 10000;
  vk::Context& ctx = test::context();
  std::mt19937 rng(4321);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  auto dir = [&]() {
    float z = U(rng), phi = 2 * float(M_PI) * U(rng);
    if (U(rng) < 0.2f) z *= 0.02f;  // some near grazing
    float r = std::sqrt(std::max(0.0f, 1 - z * z));
    return vec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  std::vector<std::pair<vec3, vec3>> pairs;
  for (int i = 0; i < n; ++i) {
    vec3 wi = dir(), wo = dir();
    if (i % 4 == 0) wo = vec3(-wi.x, -wi.y, wi.z);  // on the specular peak
    pairs.push_back({wi, wo});
  }
  vk::Buffer pairBuf = vk::createBuffer(ctx, n * 32, 0, true, "pairs");
  vk::Buffer paramBuf = vk::createBuffer(ctx, sizeof(BrdfParams), 0, true, "params");
  vk::Buffer resultBuf = vk::createBuffer(ctx, n * 16, 0, true, "results");
  vk::Buffer tableBuf = vk::createBuffer(ctx, MERL_TABLE_FLOATS * sizeof(float), 0, false, "measured table");
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
    std::uint64_t measured;
  } push{pairBuf.address, paramBuf.address, resultBuf.address, std::uint32_t(n), 0, tableBuf.address};
  const float ulp = std::ldexp(1.0f, -23);
  std::mt19937 prng(99);
  std::uniform_int_distribution<int> step(-4, 4);
  auto perturb = [&](vec3 w) {
    for (int c = 0; c < 3; ++c) w[c] *= 1.0f + step(prng) * ulp;
    return w;
  };
  for (const merltest::Source& s : merltest::sources()) {
    BrdfParams params = merltest::merlParams(s);
    vk::uploadBuffer(ctx, tableBuf, merlTable(params).rgb.data(), MERL_TABLE_FLOATS * sizeof(float));
    BrdfParams gpuParams = params;
    gpuParams.v[0][MERL_SLOT] = 0.0f;  // table 0 of the buffer
    std::memcpy(paramBuf.mapped, &gpuParams, sizeof gpuParams);
    test::runKernel("eval_brdf", {MODEL_MERL}, &push, sizeof push, n);
    const float* gpu = static_cast<const float*>(resultBuf.mapped);
    int outside = 0;
    double worstRel = 0;
    for (int i = 0; i < n; ++i) {
      vec3 cpu = brdfEval(MODEL_MERL, params, pairs[i].first, pairs[i].second);
      vec3 sens(0.0f);
      for (int k = 0; k < 6; ++k) {
        vec3 moved = brdfEval(MODEL_MERL, params, perturb(pairs[i].first), perturb(pairs[i].second));
        for (int c = 0; c < 3; ++c) sens[c] = std::max(sens[c], std::fabs(moved[c] - cpu[c]));
      }
      for (int c = 0; c < 3; ++c) {
        double a = gpu[4 * i + c], b = cpu[c];
        ASSERT_TRUE(std::isfinite(a)) << s.name << " pair " << i;
        double bound = 4.0 * sens[c] + 16.0 * ulp * std::fabs(b) + 1e-30;
        if (std::max(std::fabs(a), std::fabs(b)) > 1e-30) worstRel = std::max(worstRel, std::fabs(a - b) / std::max(std::fabs(a), std::fabs(b)));
        if (std::fabs(a - b) > bound) {
          if (outside < 3)
            ADD_FAILURE() << s.name << " pair " << i << " channel " << c << ": gpu " << a << " cpu " << b << " bound " << bound;
          ++outside;
        }
      }
    }
    std::printf("[parity] merl(%s) worst relative difference %.3g (%.1f ulp), %d outside the bound\n", s.name.c_str(), worstRel,
                worstRel / ulp, outside);
    EXPECT_EQ(outside, 0) << s.name;
  }
  for (vk::Buffer* b : {&pairBuf, &paramBuf, &resultBuf, &tableBuf}) vk::destroyBuffer(ctx, *b);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The quadtree sampler over the table on the GPU: chi-square against quadPdf (bins from a CPU
// pilot run), no bound violations or trial failures, the same directions as the CPU.
TEST(MerlGpu, ChiSquareAndParity) {
  vk::Context& ctx = test::context();
  const double alpha = merltest::suiteAlpha();
  std::map<std::string, quadtree::SamplerTables> built;
  for (const merltest::Case& c : merltest::caseMatrix()) {
    BrdfParams p = merltest::merlParams(c.source);
    std::vector<std::uint32_t> idx;
    if (!built.count(c.source.name))
      built[c.source.name] = quadtree::buildSamplerTables({{MODEL_MERL, p}}, qttest::testSettings(), idx);
    const quadtree::SamplerTables& t = built[c.source.name];
    vec3 v = merltest::knownDirection(c.thetaDeg);
    quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, 0, MODEL_MERL, p, v, qttest::kSamples, 777u);
    quadtree::SampleBatch pilot = quadtree::sampleCpu(t, 0, MODEL_MERL, p, v, qttest::kPilotSamples, 99u);
    qttest::Chi2Result r = qttest::quadChiSquare(t, 0, MODEL_MERL, p, v, pilot.wPdf, g.wPdf);
    quadtree::SampleBatch cpu = quadtree::sampleCpu(t, 0, MODEL_MERL, p, v, 2000, 777u);
    int same = 0;
    for (int i = 0; i < 2000; ++i) {
      vec3 a(g.wPdf[i]), b(cpu.wPdf[i]);
      if (length(a - b) < 1e-4f && std::abs(g.wPdf[i].w - cpu.wPdf[i].w) <= 1e-3f * cpu.wPdf[i].w + 1e-6f) ++same;
    }
    std::printf("%-32s p=%.3g chi2=%.1f dof=%d gpu %.3f s, parity %d/2000\n", c.name().c_str(), r.pValue, r.chi2, r.dof, g.seconds,
                same);
    EXPECT_EQ(g.boundViolations, 0u) << c.name();
    EXPECT_EQ(g.trialFailures, 0u) << c.name();
    EXPECT_GE(same, 1980) << c.name();
    EXPECT_NEAR(r.expectedTotal, 1.0, 2e-4) << c.name();
    EXPECT_GE(r.pValue, alpha) << c.name() << "\n" << r.dump;
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
