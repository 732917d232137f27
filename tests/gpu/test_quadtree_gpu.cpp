// test_quadtree_gpu.cpp: the generic quadtree sampler on the CPU and on the GPU (stage sample_tool;
// both run the shared code of shaders/shared/quadtree.h): chi-square of CPU and of GPU samples
// against the pdf, zero bound violations and trial failures, weights and acceptance, and parity of
// the GPU with the CPU (same random numbers: same directions and pdfs).
#include <gtest/gtest.h>

#include <chrono>

#include "../support/test_support.h"
#include "../unit/test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// The whole case matrix, each case's 2^20 CPU samples and 2^20 GPU samples against the sampler's
// pdf, in one test: the tables, the bins (equal-probability bins of an independent CPU pilot run)
// and their expected counts (the quadrature of quadPdf) depend on the case and the pilot alone, so
// one computation serves both chi-squares. (As two tests, Quadtree.ChiSquareCpu and
// QuadtreeGpu.ChiSquareAndParity, two processes computed the same numbers: 38 % and 48 % of their
// time, of which tables 10 % / 13 %, quadrature 26 % / 32 %.) Per CPU batch also:
// on tables the weight f cos / pdf is the tabulated albedo; every leaf accepts at least 1/n_max of
// its evaluations; no bound violations, no trial failures. Per GPU batch: no bound violations, no
// trial failures, and parity with CPU samples drawn from the same random numbers.
TEST(QuadtreeGpu, ChiSquareCpuGpuAndParity) {
  vk::Context& ctx = test::context();
  std::vector<qttest::Case> cases = qttest::caseMatrix();
  const double cellAlpha = qttest::suiteAlpha();
  const std::uint32_t n = qttest::kSamples;
  qttest::TableCache tables;
  int cpuFailures = 0, gpuFailures = 0;
  std::uint64_t cpuViolations = 0, cpuTrialFailures = 0, gpuViolations = 0, gpuTrialFailures = 0;
  int totalLowLeaves = 0;
  double spreadLo = 1e30, spreadHi = 0;
  double gpuSeconds = 0, tTables = 0, tBins = 0, tCpu = 0, tGpu = 0, tChecks = 0;
  for (const qttest::Case& c : cases) {
    const ModelSpec* m = findModel(c.model);
    BrdfParams p = qttest::caseParams(c);
    vec3 v = qttest::knownDirection(c);
    auto t0 = std::chrono::steady_clock::now();
    const quadtree::SamplerTables& t = tables.get(c.model + (c.hard ? "/hard" : "/typical"), m->id, p);
    tTables += secondsSince(t0);

    // The bins from an independent CPU pilot run (another seed) and their probabilities, once.
    t0 = std::chrono::steady_clock::now();
    quadtree::SampleBatch pilot = quadtree::sampleCpu(t, 0, m->id, p, v, qttest::kPilotSamples, 99u);
    qttest::QuadBins bins = qttest::quadBins(t, 0, m->id, p, v, pilot.wPdf);
    double sumPdf = 0;
    for (double q : bins.prob) sumPdf += q;
    EXPECT_NEAR(sumPdf, 1.0, 2e-4) << c.name();
    tBins += secondsSince(t0);

    // CPU samples.
    t0 = std::chrono::steady_clock::now();
    quadtree::SampleBatch b = quadtree::sampleCpu(t, 0, m->id, p, v, n, 1234u);
    tCpu += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    cpuViolations += b.boundViolations;
    cpuTrialFailures += b.trialFailures;
    EXPECT_EQ(b.boundViolations, 0u) << "CPU " << c.name();
    EXPECT_EQ(b.trialFailures, 0u) << "CPU " << c.name();
    qttest::Chi2Result r = qttest::quadChiSquare(bins, b.wPdf);
    // Weights f cos / pdf relative to the tabulated albedo.
    float albedo;
    bool onTable = std::fmod(c.thetaDeg, 1.0) == 0.0 && c.phiDeg == 0.0;
    {
      quadtree::QuadHostScope scope(t);
      albedo = quadAlbedo(0, v.z, float(c.phiDeg * M_PI / 180));
    }
    double lo = 1e30, hi = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (b.fOk[i].w <= 0) continue;
      double wgt = luminance(vec3(b.fOk[i])) * std::abs(b.wPdf[i].z) / b.wPdf[i].w / albedo;  // (|cos|: transmitting sets)
      lo = std::min(lo, wgt);
      hi = std::max(hi, wgt);
    }
    if (onTable) {
      EXPECT_NEAR(lo, 1.0, 2e-3) << c.name();
      EXPECT_NEAR(hi, 1.0, 2e-3) << c.name();
    } else {
      spreadLo = std::min(spreadLo, lo);
      spreadHi = std::max(spreadHi, hi);
    }
    double trialsPerSample = double(b.trials) / n, evalsPerSample = double(b.evaluations) / n;
    // Every leaf's measured acceptance (accepted / evaluations of f) against 1 / n_max: a
    // one-sided binomial test, z < -5.3 (p = 5.8e-8: 0.01 Bonferroni-corrected over up to 170k
    // leaves tested in the suite; normal approximation, leaves with >= 100 evaluations).
    int leavesTested = 0, leavesLow = 0;
    double worstZ = 0;
    for (std::size_t l = 0; l < b.leafEvaluations.size(); ++l) {
      double e = double(b.leafEvaluations[l]);
      if (e < 100) continue;
      ++leavesTested;
      double p0 = 0.5, acc = double(b.leafAccepted[l]) / e;
      double z = (acc - p0) / std::sqrt(p0 * (1 - p0) / e);
      if (z < worstZ) worstZ = z;
      if (z < -5.3) ++leavesLow;
    }
    totalLowLeaves += leavesLow;
    std::printf("CPU %-44s p=%.3g chi2=%.1f dof=%d sum(pdf)=%.5f weight/a in [%.6f, %.6f] trials/sample=%.3f evals/sample=%.3f nodes/sample=%.2f "
                "leaves=%d worst z=%.2f\n",
                c.name().c_str(), r.pValue, r.chi2, r.dof, r.expectedTotal, lo, hi, trialsPerSample, evalsPerSample, double(b.nodeReads) / n,
                leavesTested, worstZ);
    EXPECT_EQ(leavesLow, 0) << c.name() << ": leaves accepting below 1/n_max";
    if (r.pValue < cellAlpha) {
      ++cpuFailures;
      ADD_FAILURE() << "CPU " << c.name() << ": chi-square p-value " << r.pValue << " < " << cellAlpha << "\n" << r.dump;
    }
    tChecks += secondsSince(t0);

    // GPU samples.
    t0 = std::chrono::steady_clock::now();
    quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, 0, m->id, p, v, n, 777u);
    tGpu += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    gpuSeconds += g.seconds;
    gpuViolations += g.boundViolations;
    gpuTrialFailures += g.trialFailures;
    EXPECT_EQ(g.boundViolations, 0u) << "GPU " << c.name();
    EXPECT_EQ(g.trialFailures, 0u) << "GPU " << c.name();
    r = qttest::quadChiSquare(bins, g.wPdf);
    // Parity: the CPU with the same random numbers draws the same directions (up to float
    // differences of the two compilers, which can flip an acceptance: a small fraction).
    quadtree::SampleBatch cpu = quadtree::sampleCpu(t, 0, m->id, p, v, 2000, 777u);
    int same = qttest::sameSamples(g, cpu, 2000);
    std::printf("GPU %-44s p=%.3g chi2=%.1f dof=%d gpu %.3f s, parity %d/2000\n", c.name().c_str(), r.pValue, r.chi2, r.dof,
                g.seconds, same);
    EXPECT_GE(same, 1980) << c.name();
    if (r.pValue < cellAlpha) {
      ++gpuFailures;
      ADD_FAILURE() << "GPU " << c.name() << ": chi-square p-value " << r.pValue << " < " << cellAlpha << "\n" << r.dump;
    }
    tChecks += secondsSince(t0);
  }
  std::printf("%zu cases of %u CPU and %u GPU samples (Bonferroni level %.3g over both): chi-square failures CPU %d, GPU %d; "
              "%d leaves accepting below 1/n_max; bound violations CPU %llu, GPU %llu; trial failures CPU %llu, GPU %llu; "
              "between tables weight/albedo in [%.4f, %.4f]\n",
              cases.size(), n, n, cellAlpha, cpuFailures, gpuFailures, totalLowLeaves,
              static_cast<unsigned long long>(cpuViolations), static_cast<unsigned long long>(gpuViolations),
              static_cast<unsigned long long>(cpuTrialFailures), static_cast<unsigned long long>(gpuTrialFailures), spreadLo,
              spreadHi);
  std::printf("time: tables %.1f s, pilot and bin probabilities %.1f s, CPU sampling %.1f s, GPU sampling %.1f s (dispatches %.1f s), "
              "checks (chi-square, weights, leaves, parity) %.1f s\n",
              tTables, tBins, tCpu, tGpu, gpuSeconds, tChecks);
  EXPECT_EQ(test::validationMessages(), 0u);
}

// The shared trials of costly models (quadtree.h, quadLeafSampleShared) deal the trials of the
// open samples over the subgroup's lanes and must still return each sample's first accepted trial:
// the CPU's serial loop with the same numbers. The chi-square test above draws with full
// subgroups; the shade stages run with lanes idle (paths that ended, other materials). Here lanes
// 1, 4 and 6 of every subgroup draw nothing, and the other lanes' samples must be the CPU's, with
// or without a table under the known direction (37.3 degrees: the mixture of two trees).
TEST(QuadtreeGpu, SharedTrialsWithIdleLanesAreTheSerialSamples) {
  vk::Context& ctx = test::context();
  qttest::TableCache tables;
  const std::uint32_t idle = (1u << 1) | (1u << 4) | (1u << 6);
  const std::uint32_t n = 4000;
  for (const char* model : {"htsg", "poulin_fournier"}) {
    for (bool hard : {false, true}) {
      for (double theta : {30.0, 37.3}) {
        qttest::Case c{model, hard, theta, 0.0};
        const ModelSpec* m = findModel(c.model);
        ASSERT_TRUE(m);
        BrdfParams p = qttest::caseParams(c);
        vec3 v = qttest::knownDirection(c);
        const quadtree::SamplerTables& t = tables.get(c.model + (hard ? "/hard" : "/typical"), m->id, p);
        quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, 0, m->id, p, v, n, 4242u, SAMPLER_QUADTREE, nullptr,
                                                      false, 0, 1u << 20, nullptr, idle);
        quadtree::SampleBatch cpu = quadtree::sampleCpu(t, 0, m->id, p, v, n, 4242u);
        int idled = 0, drawn = 0, same = 0;
        for (std::uint32_t i = 0; i < n; ++i) {
          if (g.fOk[i].w < 0.0f) {
            ++idled;
            continue;
          }
          ++drawn;
          vec3 a(g.wPdf[i]), b(cpu.wPdf[i]);
          if (length(a - b) < 1e-4f && std::abs(g.wPdf[i].w - cpu.wPdf[i].w) <= 1e-3f * cpu.wPdf[i].w + 1e-6f) ++same;
        }
        std::printf("%s: %d of %u lanes idle, %d of %d drawn samples equal to the CPU's\n", c.name().c_str(), idled, n,
                    same, drawn);
        // 3 lanes of every subgroup of 8 (lavapipe), 3 of 32 on most GPUs: some, and under half.
        EXPECT_GT(idled, 0) << c.name();
        EXPECT_LT(idled, int(n / 2)) << c.name();
        EXPECT_EQ(g.trialFailures, 0u) << c.name();
        // As in the parity check above: float differences of the two compilers may flip an
        // acceptance now and then (there 0 or 1 in 2000).
        EXPECT_GE(same, drawn - drawn / 200) << c.name();
      }
    }
  }
}
