// test_quadtree_gpu.cpp: the generic quadtree sampler on the GPU (stage sample_tool, the same
// shared code as the CPU): chi-square of GPU samples against the pdf, zero bound violations and
// trial failures, and parity with the CPU (same random numbers: same directions and pdfs).
#include <gtest/gtest.h>

#include "../support/test_support.h"
#include "../unit/test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

TEST(QuadtreeGpu, ChiSquareAndParity) {
  vk::Context& ctx = test::context();
  std::vector<qttest::Case> cases = qttest::caseMatrix();
  const double cellAlpha = qttest::suiteAlpha();
  const std::uint32_t n = qttest::kSamples;
  qttest::TableCache tables;
  int failures = 0;
  std::uint64_t violations = 0, trialFailures = 0;
  double gpuSeconds = 0;
  for (const qttest::Case& c : cases) {
    const ModelSpec* m = findModel(c.model);
    BrdfParams p = qttest::caseParams(c);
    const quadtree::SamplerTables& t = tables.get(c.model + (c.hard ? "/hard" : "/typical"), m->id, p);
    vec3 v = qttest::knownDirection(c);
    quadtree::SampleBatch g = quadtree::sampleGpu(ctx, t, 0, m->id, p, v, n, 777u);
    gpuSeconds += g.seconds;
    violations += g.boundViolations;
    trialFailures += g.trialFailures;
    EXPECT_EQ(g.boundViolations, 0u) << c.name();
    EXPECT_EQ(g.trialFailures, 0u) << c.name();
    // The bins from an independent CPU pilot run (another seed).
    quadtree::SampleBatch pilot = quadtree::sampleCpu(t, 0, m->id, p, v, qttest::kPilotSamples, 99u);
    qttest::Chi2Result r = qttest::quadChiSquare(t, 0, m->id, p, v, pilot.wPdf, g.wPdf);
    // Parity: the CPU with the same random numbers draws the same directions (up to float
    // differences of the two compilers, which can flip an acceptance: a small fraction).
    quadtree::SampleBatch cpu = quadtree::sampleCpu(t, 0, m->id, p, v, 2000, 777u);
    int same = qttest::sameSamples(g, cpu, 2000);
    std::printf("%-48s p=%.3g chi2=%.1f dof=%d gpu %.3f s, parity %d/2000\n", c.name().c_str(), r.pValue, r.chi2, r.dof,
                g.seconds, same);
    EXPECT_GE(same, 1980) << c.name();
    EXPECT_NEAR(r.expectedTotal, 1.0, 2e-4) << c.name();
    if (r.pValue < cellAlpha) {
      ++failures;
      ADD_FAILURE() << c.name() << ": chi-square p-value " << r.pValue << " < " << cellAlpha << "\n" << r.dump;
    }
  }
  std::printf("%zu GPU cases of %u samples (Bonferroni level %.3g), %d chi-square failures, bound violations %llu, trial failures %llu, GPU time %.1f s\n",
              cases.size(), n, cellAlpha, failures, static_cast<unsigned long long>(violations),
              static_cast<unsigned long long>(trialFailures), gpuSeconds);
  EXPECT_EQ(test::validationMessages(), 0u);
}
