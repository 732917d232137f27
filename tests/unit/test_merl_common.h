// test_merl_common.h: MERL files written at test time from analytic models (tools/make_merl.cpp's
// code path: tabulateMerl + writeMerlFile) and the measured sampler's case matrix, shared by
// tests/unit/test_merl.cpp (CPU) and tests/gpu/test_merl_gpu.cpp (GPU).
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "brdf/merl.h"
#include "brdf/registry.h"
#include "test_quadtree_chi2.h"

namespace nusselt::merltest {

using namespace shared;

// The two tabulated materials of the tests: Lambert rho = 0.5 (the albedo test of issue 20) and
// torrance_sparrow's typical set (kd 0.3, ks 0.7, Beckmann m = 0.2, eta 1.5: a glossy lobe).
struct Source {
  std::string name;   // "lambert05" or "glossy"
  std::string model;  // the analytic model tabulated
  NamedParams params;
};
inline std::vector<Source> sources() {
  const ModelSpec* ts = findModel("torrance_sparrow");
  return {{"lambert05", "lambert", {{"rho", ParamValue::num(0.5)}}}, {"glossy", "torrance_sparrow", typicalParams(*ts)}};
}
// A sharp table: ward's typical set (1992 normalisation, f ~ 1/sqrt(cos) at the horizon), whose
// nodes next to the horizon are up to 1e7 times their neighbours (docs/measured.md, Limits).
inline Source wardSource() { return {"ward", "ward", typicalParams(*findModel("ward"))}; }

// A folder for this process's files (35 MB each), removed at exit.
inline std::string tempDir() {
  struct Dir {
    std::filesystem::path path;
    Dir() : path(std::filesystem::temp_directory_path() / ("nusselt-merl-" + std::to_string(::getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path.string();
}

// The file written from `s` (once per process) and its merl parameter block.
inline std::string fileFor(const Source& s) {
  std::string path = tempDir() + "/" + s.name + ".binary";
  if (!std::filesystem::exists(path)) {
    const ModelSpec* m = findModel(s.model);
    writeMerlFile(path, tabulateMerl(m->id, packParams(*m, s.params, s.name)));
  }
  return path;
}
inline BrdfParams merlParams(const Source& s) { return loadMerl(fileFor(s), s.name); }
inline BrdfParams analyticParams(const Source& s) {
  const ModelSpec* m = findModel(s.model);
  return packParams(*m, s.params, s.name);
}

struct Case {
  Source source;
  double thetaDeg;
  std::string name() const {
    char b[96];
    std::snprintf(b, sizeof b, "merl(%s)/theta=%.1f", source.name.c_str(), thetaDeg);
    return b;
  }
};
// The glossy file at 0, 30, 60, 85 degrees (on tables) and 37.3 (between two); the Lambert file,
// whose trees are alike at every angle, at 0 and 37.3.
inline std::vector<Case> caseMatrix() {
  std::vector<Case> cases;
  for (const Source& s : sources()) {
    std::vector<double> angles = s.name == "glossy" ? std::vector<double>{0.0, 30.0, 60.0, 85.0, 37.3} : std::vector<double>{0.0, 37.3};
    for (double t : angles) cases.push_back({s, t});
  }
  return cases;
}
// Bonferroni: significance 0.01 over the measured cases, CPU and GPU.
inline double suiteAlpha() { return 0.01 / (2.0 * double(caseMatrix().size())); }
inline vec3 knownDirection(double thetaDeg) {
  double th = thetaDeg * M_PI / 180;
  return vec3(float(std::sin(th)), 0.0f, float(std::cos(th)));
}

// The chi-square test of one case for samples drawn on the CPU or the GPU from tables `t`: bins
// from an independent CPU pilot run (seed 99), expected counts from the pdf; the checks of every
// sampler test (no bound violations or trial failures, the bins' probabilities summing to 1, the
// p-value at least the suite's level). Returns the result for the caller's line.
inline qttest::Chi2Result checkChiSquare(const Case& c, const quadtree::SamplerTables& t, const BrdfParams& p,
                                         const quadtree::SampleBatch& samples) {
  const vec3 v = knownDirection(c.thetaDeg);
  quadtree::SampleBatch pilot = quadtree::sampleCpu(t, 0, MODEL_MERL, p, v, qttest::kPilotSamples, 99u);
  qttest::Chi2Result r = qttest::quadChiSquare(t, 0, MODEL_MERL, p, v, pilot.wPdf, samples.wPdf);
  EXPECT_EQ(samples.boundViolations, 0u) << c.name();
  EXPECT_EQ(samples.trialFailures, 0u) << c.name();
  EXPECT_NEAR(r.expectedTotal, 1.0, 2e-4) << c.name();
  EXPECT_GE(r.pValue, suiteAlpha()) << c.name() << "\n" << r.dump;
  return r;
}

}  // namespace nusselt::merltest
