// test_merl_gpu.cpp: the measured model on the GPU: the GLSL interpolation against the C++ one
// (the table as float in a buffer), and the quadtree sampler over the table (chi-square, no
// bound violations or trial failures, CPU/GPU parity), with tabulated files written at test time.
#include <gtest/gtest.h>

#include <random>

#include "../support/test_support.h"
#include "../unit/test_merl_common.h"

using namespace nusselt;
using namespace nusselt::shared;

// GLSL (eval_brdf, the table in a storage buffer read through its device address) against C++ at
// 10,000 direction pairs, a quarter on the specular peak and a fifth of the rest near grazing:
// the same float operations on both sides, so the bound is that of the catalogue's parity test
// (test::BrdfParityKernel).
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
  vk::Buffer tableBuf = vk::createBuffer(ctx, MERL_TABLE_FLOATS * sizeof(float), 0, false, "measured table");
  {
    test::BrdfParityKernel kernel(pairs, tableBuf.address);
    const float ulp = std::ldexp(1.0f, -23);
    for (const merltest::Source& s : merltest::sources()) {
      BrdfParams params = merltest::merlParams(s);
      vk::uploadBuffer(ctx, tableBuf, merlTable(params).rgb.data(), MERL_TABLE_FLOATS * sizeof(float));
      BrdfParams gpuParams = params;
      gpuParams.v[0][MERL_SLOT] = 0.0f;  // table 0 of the buffer
      test::BrdfParityKernel::Result r = kernel.run(MODEL_MERL, gpuParams, params);
      std::printf("[parity] merl(%s) worst relative difference %.3g (%.1f ulp), %d outside the bound\n", s.name.c_str(), r.worstRel,
                  r.worstRel / ulp, r.outside);
      EXPECT_EQ(r.nonFinite, 0) << s.name;
      EXPECT_EQ(r.outside, 0) << s.name;
    }
  }
  vk::destroyBuffer(ctx, tableBuf);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The quadtree sampler over the table on the GPU: chi-square against quadPdf (bins from a CPU
// pilot run), no bound violations or trial failures, the same directions as the CPU.
TEST(MerlGpu, ChiSquareAndParity) {
  vk::Context& ctx = test::context();
  qttest::TableCache tables;
  for (const merltest::Case& c : merltest::caseMatrix()) {
    BrdfParams p = merltest::merlParams(c.source);
    const quadtree::SamplerTables& t = tables.get(c.source.name, MODEL_MERL, p);
    vec3 v = merltest::knownDirection(c.thetaDeg);
    quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, 0, MODEL_MERL, p, v, qttest::kSamples, 777u);
    qttest::Chi2Result r = merltest::checkChiSquare(c, t, p, g);
    quadtree::SampleBatch cpu = quadtree::sampleCpu(t, 0, MODEL_MERL, p, v, 2000, 777u);
    int same = qttest::sameSamples(g, cpu, 2000);
    std::printf("%-32s p=%.3g chi2=%.1f dof=%d gpu %.3f s, parity %d/2000\n", c.name().c_str(), r.pValue, r.chi2, r.dof, g.seconds,
                same);
    EXPECT_GE(same, 1980) << c.name();
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
