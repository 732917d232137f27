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
//
// SampleCommandFollowsItsPdf: `nusselt sample --roughness-bins` (run in-process through runCli, the
// command line's own code) on the GPU and with --cpu: its CSV's directions against binnedPdf
// (chi-square as above, 2^18 samples per run, significance 0.01 with Bonferroni over 2 texels x 2
// devices; failed samples, which the CSV leaves out, form the failure bin), and every printed pdf
// equal to binnedPdf at the printed direction (relative 1e-6 on the CPU, the same code; 1e-3 on the
// GPU, whose pow and atan2 round differently).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "cli/commands.h"
#include "quadtree/roughness_bins.h"

#include "../../shaders/shared/bsdf_sampling.h"
#include "../support/test_support.h"
#include "../unit/test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

TEST(BinnedGpu, ChiSquareAgainstTheCpuPdf) {
  vk::Context& ctx = test::context();
  const RoughnessBins B{0u, 4u, 1.0f, 0u};
  const quadtree::SamplerTables t = quadtree::buildRoughnessBinTables(B, qttest::testSettings());
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

namespace {

// `nusselt sample ARGS -o FILE` through runCli; its CSV rows as (x, y, z, pdf), then one
// (0, 0, 0, 0) per sample missing from the n asked for (failed samples are not written).
std::vector<vec4> runSampleCommand(std::vector<std::string> args, std::uint32_t n, std::vector<float>* printedPdf) {
  const std::filesystem::path csv =
      std::filesystem::temp_directory_path() / ("nusselt-binned-sample-" + std::to_string(::getpid()) + ".csv");
  args.insert(args.begin(), {"nusselt", "sample"});
  args.insert(args.end(), {"-n", std::to_string(n), "-o", csv.string()});
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  EXPECT_EQ(runCli(int(argv.size()), argv.data()), 0);
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "x,y,z,pdf,f");
  std::vector<vec4> out;
  while (std::getline(in, line)) {
    float x, y, z, pdf, f;
    if (std::sscanf(line.c_str(), "%g,%g,%g,%g,%g", &x, &y, &z, &pdf, &f) != 5) {
      ADD_FAILURE() << "bad CSV row: " << line;
      continue;
    }
    out.push_back(vec4(x, y, z, pdf));
  }
  in.close();
  std::filesystem::remove(csv);
  if (printedPdf) {
    printedPdf->clear();
    for (const vec4& s : out) printedPdf->push_back(s.w);
  }
  EXPECT_LE(out.size(), std::size_t(n));
  out.resize(n, vec4(0.0f));
  return out;
}

}  // namespace

TEST(BinnedGpu, SampleCommandFollowsItsPdf) {
  const RoughnessBins B{0u, 4u, 2.0f, 0u};  // r = 0, 1/9, 4/9, 1
  const std::uint32_t n = 1u << 18;
  struct C {
    const char* base;
    const char* metallic;
    const char* roughness;
    const char* theta;
  };
  // A glossy dielectric at grazing incidence between bins 1 and 2, a rough metal between bins 2
  // and 3 and between theta tables.
  const C cases[] = {{"0.8,0.5,0.3", "0", "0.3", "75"}, {"0.95,0.64,0.54", "1", "0.6", "37.3"}};
  const double alpha = 0.01 / 4;
  for (const C& c : cases) {
    BrdfParams p{};
    std::sscanf(c.base, "%g,%g,%g", &p.v[0].x, &p.v[0].y, &p.v[0].z);
    p.v[0].w = std::strtof(c.metallic, nullptr);
    p.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = std::strtof(c.roughness, nullptr);
    const double theta = std::strtod(c.theta, nullptr);
    const vec3 v = qttest::knownDirection(qttest::Case{"gltf_pbr", false, theta, 0});
    // The command's trees: the bins at the theta tables the direction reads (its own settings).
    quadtree::QuadtreeSettings qs;
    qs.onlyThetaTables = quadtree::thetaTablesAround(theta, qs.thetaTables);
    const quadtree::SamplerTables t = quadtree::buildRoughnessBinTables(B, qs);
    std::vector<vec4> pilot(qttest::kPilotSamples);
    {
      quadtree::QuadHostScope scope(t);
      for (std::uint32_t i = 0; i < qttest::kPilotSamples; ++i) {
        vec3 wi, f;
        float pdf;
        pilot[i] = binnedSample(B, p, v, rng2(i, 0u, RNG_DIM_BSDF, 99u), wi, pdf, f) ? vec4(wi, pdf) : vec4(0.0f);
      }
    }
    qttest::Binning bins = qttest::quantileBinning(pilot, 16, 32);
    std::vector<double> prob = qttest::binProbabilities([&](vec3 w) { return double(binnedPdf(B, p, v, w)); }, bins, pilot,
                                                        [&]() { return std::make_shared<quadtree::QuadHostScope>(t); });
    for (bool cpu : {false, true}) {
      std::vector<std::string> args{"--model", "gltf_pbr", "--param", std::string("baseColor=") + c.base, "--param",
                                    std::string("metallic=") + c.metallic, "--param",
                                    std::string("roughness=") + c.roughness, "--theta", c.theta, "--seed", "5",
                                    "--roughness-bins", "4", "--roughness-bin-spacing", "2"};
      if (cpu) args.push_back("--cpu");
      std::vector<float> printed;
      const std::vector<vec4> samples = runSampleCommand(args, n, &printed);
      // The printed pdf is binnedPdf at the printed direction.
      const double tol = cpu ? 1e-6 : 1e-3;
      std::size_t off = 0;
      double worst = 0;
      {
        quadtree::QuadHostScope scope(t);
        for (std::size_t i = 0; i < printed.size(); ++i) {
          const double ref = binnedPdf(B, p, v, vec3(samples[i]));
          const double rel = std::abs(double(printed[i]) - ref) / ref;
          worst = std::max(worst, rel);
          if (!(rel <= tol)) ++off;
        }
      }
      qttest::Chi2Result r = qttest::chiSquare(bins, prob, samples);
      std::printf("%s r %s metallic %s theta %s: chi2 %.1f, dof %d, p %.3g, pdf integral %.6f, failed %.0f; printed pdf "
                  "off binnedPdf by %.3g at most (%zu beyond %.0e)\n",
                  cpu ? "cpu" : "gpu", c.roughness, c.metallic, c.theta, r.chi2, r.dof, r.pValue, r.expectedTotal,
                  r.failedObserved, worst, off, tol);
      EXPECT_GT(r.pValue, alpha) << (cpu ? "cpu " : "gpu ") << c.roughness << "\n" << r.dump;
      EXPECT_NEAR(r.expectedTotal, 1.0 - r.failedObserved / double(n), 2e-3);
      EXPECT_EQ(off, 0u);
    }
  }
  EXPECT_EQ(test::validationMessages(), 0u);
}
