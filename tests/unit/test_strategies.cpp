// test_strategies.cpp: the `analytic` and `tabulated` BSDF sampling strategies on the CPU (the shared
// code of shaders/shared/analytic_sampling.h and tabulated.h):
//   - chi-square goodness of fit of the samples against the strategy's own pdf (tests/unit/
//     test_quadtree_chi2.h: analytic with equal-probability bins from an independent pilot run,
//     tabulated with the fixed equal-area bins whose probabilities are exact for its cells; one
//     more bin for failed samples: a lobe sample below the surface fails, and the pdf's missing
//     mass must match the failure rate), fixed seed, significance 0.01 with Bonferroni over the cases;
//   - unbiasedness: for every strategy the mean of luminance(f) cos / pdf (failures count 0) agrees
//     with directionalAlbedo within 5 standard errors (sample variance; > the Bonferroni z of 0.01
//     over the cases) plus 2e-4 relative (the quadrature's and float's error).
#include <gtest/gtest.h>

#include "render/settings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <vector>

#include "brdf/albedo.h"
#include "quadtree/sample_run.h"
#include "sampling/tabulated.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

constexpr int kRings = 16, kSectors = 32;

// The chi-square suite's case (model, set, angles) with the accessors this file uses.
struct SCase : qttest::Case {
  SCase(std::string m, bool h, double t, double p = 0) : qttest::Case{std::move(m), h, t, p} {}
  vec3 v() const { return qttest::knownDirection(*this); }
  BrdfParams params() const { return qttest::caseParams(*this); }
  std::uint32_t id() const { return findModel(model)->id; }
};

// Exact bin probabilities of a tabulated table: the disc density is constant on the table's cells
// (rectangles in (u, phi), as the bins are), so each bin is a sum of overlaps.
std::vector<double> tabBinProbabilities(const sampling::TabulatedTables& t, std::uint32_t set, vec3 v) {
  const TabSet& S = t.sets[set];
  vec4 fr = quadFrame((S.info.w & TB_SET_ANISOTROPIC) != 0u, v);
  const TabTable& T = t.tables[tabTableIndex(S, quadToCanonical(fr, v))];
  // The bins are in the local frame, the cells in the canonical frame: compare through the pdf
  // at the cells (canonical) mapped back. For isotropic sets the frame is a rotation by phi_v and
  // for anisotropic ones reflections: both keep u and map phi affinely, so integrate over the
  // canonical cells and map each cell to the local frame's phi range.
  const std::uint32_t nu = S.grid.x, np = S.grid.y;
  float eps = T.info.y == 0u ? 1.0f : S.data.x;
  std::vector<double> e(kRings * kSectors, 0.0);
  double phiV = std::atan2(double(fr.y), double(fr.x));  // rotation (isotropic) or 0
  for (std::uint32_t i = 0; i < nu; ++i)
    for (std::uint32_t j = 0; j < np; ++j) {
      double prob = (1 - eps) * (T.info.y ? double(tabCellProbability(S, T, i, j)) : 0.0) +
                    eps / (double(nu) * np);  // the cosine part is uniform on the disc
      // Cell in the canonical frame: u in [i/nu, (i+1)/nu), phi_c in [2 pi j/np, 2 pi (j+1)/np).
      // Local phi = S(R(phi_v) phi_c): rotation adds phi_v; reflections negate / mirror.
      double a0 = 2 * M_PI * j / np, a1 = 2 * M_PI * (j + 1) / np;
      double b0, b1;
      if (fr.z > 0 && fr.w > 0) { b0 = a0 + phiV; b1 = a1 + phiV; }
      else if (fr.z < 0 && fr.w > 0) { b0 = M_PI - a1; b1 = M_PI - a0; }
      else if (fr.z > 0 && fr.w < 0) { b0 = -a1; b1 = -a0; }
      else { b0 = M_PI + a0; b1 = M_PI + a1; }
      double cu0 = double(i) / nu, cu1 = double(i + 1) / nu;
      for (int ri = std::max(0, int(cu0 * kRings)); ri < kRings && double(ri) / kRings < cu1; ++ri) {
        double ou = std::min(cu1, double(ri + 1) / kRings) - std::max(cu0, double(ri) / kRings);
        if (ou <= 0) continue;
        for (int wrap = -1; wrap <= 1; ++wrap)
          for (int sj = 0; sj < kSectors; ++sj) {
            double s0 = 2 * M_PI * sj / kSectors + wrap * 2 * M_PI, s1 = s0 + 2 * M_PI / kSectors;
            double op = std::min(b1, s1) - std::max(b0, s0);
            if (op <= 0) continue;
            e[ri * kSectors + sj] += prob * (ou * nu) * (op / (a1 - a0));
          }
      }
    }
  // Rings above are in u = r^2; qttest::uniformBinning orders them by ascending cos theta.
  std::vector<double> byC(e.size());
  for (int ri = 0; ri < kRings; ++ri)
    for (int sj = 0; sj < kSectors; ++sj) byC[(kRings - 1 - ri) * kSectors + sj] = e[ri * kSectors + sj];
  return byC;
}

// alpha / cases, and the run's bookkeeping.
struct Matrix {
  double alpha = 0.01;
  std::size_t cases = 1;
  double cellAlpha() const { return alpha / double(cases); }
};

std::vector<SCase> analyticCases() {
  std::vector<SCase> cases;
  for (const ModelSpec& m : allModels()) {
    if (m.delta || !analyticHasSampler(m.id)) continue;
    for (int hard = 0; hard < 2; ++hard) {
      for (double t : {0.0, 30.0, 60.0, 85.0}) cases.push_back({m.name, hard != 0, t, 0});
      if (hard && (m.id == MODEL_WARD || m.id == MODEL_ASHIKHMIN_SHIRLEY || m.id == MODEL_LAFORTUNE))
        cases.push_back({m.name, true, 37.3, 20});  // anisotropic: wo off the axes
    }
  }
  return cases;
}

constexpr std::uint32_t kChi2Samples = 100000;
constexpr std::uint32_t kPilot = 50000;  // the analytic test's bins: quantiles of an independent run
constexpr std::uint32_t kSeed = 12345;

TEST(Strategies, AnalyticChiSquare) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<SCase> cases = analyticCases();
  Matrix mx;
  mx.cases = cases.size();
  for (const SCase& c : cases) {
    BrdfParams p = c.params();
    vec3 v = c.v();
    std::uint32_t id = c.id();
    quadtree::SampleBatch b = quadtree::sampleCpuStrategy(SAMPLER_ANALYTIC, nullptr, 0, id, p, v, kChi2Samples, kSeed, 1);
    quadtree::SampleBatch pilot = quadtree::sampleCpuStrategy(SAMPLER_ANALYTIC, nullptr, 0, id, p, v, kPilot, kSeed + 1, 1);
    qttest::Binning bins = qttest::quantileBinning(pilot.wPdf, kRings, kSectors);
    std::vector<double> prob =
        qttest::binProbabilities([&](vec3 w) { return double(analyticPdf(id, p, v, w)); }, bins, pilot.wPdf);
    qttest::Chi2Result r = qttest::chiSquare(bins, prob, b.wPdf);
    // The returned pdf is the strategy's pdf at the returned direction.
    double worst = 0;
    for (const vec4& s : b.wPdf)
      if (s.w > 0) worst = std::max(worst, std::abs(double(analyticPdf(id, p, v, vec3(s))) / s.w - 1));
    std::printf("analytic %-42s p=%.3g chi2=%.1f dof=%d mass=%.5f failed=%.0f\n", c.name().c_str(), r.pValue, r.chi2,
                r.dof, r.expectedTotal, r.failedObserved);
    EXPECT_LT(worst, 1e-5) << c.name();
    EXPECT_LE(r.expectedTotal, 1.0 + 2e-3) << c.name() << ": the pdf integrates to more than 1";
    if (r.pValue < mx.cellAlpha()) ADD_FAILURE() << c.name() << ": p = " << r.pValue << "\n" << r.dump;
  }
  std::printf("analytic chi-square: %zu cases, alpha %.3g per case, %.1f s\n", cases.size(), mx.cellAlpha(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

sampling::TabulatedSettings tabTestSettings() {
  sampling::TabulatedSettings s;
  s.thetaTables = 18;  // 5 degree steps (0, 30, 60, 85 tabulated; 37.3 uses the 35 degree table)
  s.phiTables = 4;
  s.threads = 1;
  s.onlyThetaTables = {0, 6, 7, 12, 17};
  return s;
}

const sampling::TabulatedTables& tabTablesFor(const SCase& c) {
  static std::map<std::string, sampling::TabulatedTables> cache;
  std::string key = c.model + (c.hard ? "/hard" : "/typical");
  auto it = cache.find(key);
  if (it == cache.end()) {
    std::vector<std::uint32_t> idx;
    it = cache.emplace(key, sampling::buildTabulatedTables({{c.id(), c.params()}}, tabTestSettings(), idx)).first;
  }
  return it->second;
}

std::vector<SCase> tabulatedCases() {
  std::vector<SCase> cases;
  for (const char* m : {"lambert", "phong", "blinn", "ward", "oren_nayar", "strauss", "lafortune", "torrance_sparrow"})
    for (int hard = 0; hard < 2; ++hard)
      for (double t : {0.0, 37.3, 60.0, 85.0}) cases.push_back({m, hard != 0, t, std::string(m) == "ward" ? 20.0 : 0.0});
  return cases;
}

TEST(Strategies, TabulatedChiSquare) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<SCase> cases = tabulatedCases();
  Matrix mx;
  mx.cases = cases.size();
  for (const SCase& c : cases) {
    const sampling::TabulatedTables& t = tabTablesFor(c);
    sampling::TabHostScope scope(t);
    BrdfParams p = c.params();
    vec3 v = c.v();
    quadtree::SampleBatch b = quadtree::sampleCpuStrategy(SAMPLER_TABULATED, &t, 0, c.id(), p, v, kChi2Samples, kSeed, 1);
    qttest::Chi2Result r = qttest::chiSquare(qttest::uniformBinning(kRings, kSectors), tabBinProbabilities(t, 0, v), b.wPdf);
    double worst = 0;
    for (const vec4& s : b.wPdf)
      if (s.w > 0) worst = std::max(worst, std::abs(double(tabPdf(0, v, vec3(s))) / s.w - 1));
    std::printf("tabulated %-42s p=%.3g chi2=%.1f dof=%d mass=%.6f failed=%.0f pdf-lookup mismatch %.2g\n",
                c.name().c_str(), r.pValue, r.chi2, r.dof, r.expectedTotal, r.failedObserved, worst);
    EXPECT_NEAR(r.expectedTotal, 1.0, 1e-5) << c.name();
    if (r.pValue < mx.cellAlpha()) ADD_FAILURE() << c.name() << ": p = " << r.pValue << "\n" << r.dump;
  }
  std::printf("tabulated chi-square: %zu cases, alpha %.3g per case, %.1f s\n", cases.size(), mx.cellAlpha(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

// The grid that fits the budget, and the budget it uses.
TEST(Strategies, TabulatedGridFitsBudget) {
  for (std::uint64_t bytes : {4096ull, 65536ull, 1ull << 20}) {
    std::uint32_t nu, np;
    sampling::tabulatedGrid(bytes, nu, np);
    std::uint64_t used = sizeof(TabTable) + 4ull * (nu + std::uint64_t(nu) * np);
    EXPECT_LE(used, bytes);
    EXPECT_GT(sizeof(TabTable) + 4ull * ((nu + 1) + std::uint64_t(nu + 1) * 2 * (nu + 1)), bytes);
    EXPECT_EQ(np, 2 * nu);
  }
}

// Unbiasedness: the estimator of every strategy converges to the directional albedo.
TEST(Strategies, AllStrategiesUnbiased) {
  auto t0 = std::chrono::steady_clock::now();
  struct U { std::uint32_t strategy; SCase c; };
  std::vector<U> cases;
  // Models whose f is reciprocal (directionalAlbedo integrates over the second argument; the
  // estimator over the first).
  const char* models[] = {"lambert", "phong_specular", "phong", "lewis", "blinn", "torrance_sparrow", "ward",
                          "ashikhmin_shirley", "lafortune", "oren_nayar", "minnaert"};
  for (const char* m : models)
    for (double t : {0.0, 30.0, 60.0, 85.0}) {
      cases.push_back({SAMPLER_COSINE, {m, false, t, 0}});
      cases.push_back({SAMPLER_UNIFORM, {m, false, t, 0}});
      cases.push_back({SAMPLER_ANALYTIC, {m, false, t, 0}});
      cases.push_back({SAMPLER_ANALYTIC, {m, true, t, 0}});
      cases.push_back({SAMPLER_TABULATED, {m, false, t, 0}});
    }
  for (const char* m : {"lambert", "phong", "blinn"})
    for (double t : {0.0, 30.0, 60.0, 85.0}) cases.push_back({SAMPLER_QUADTREE, {m, false, t, 0}});
  const double z = 5.0;
  const std::uint32_t n = 200000;
  int failures = 0;
  for (const U& u : cases) {
    const SCase& c = u.c;
    BrdfParams p = c.params();
    vec3 v = c.v();
    quadtree::SampleBatch b;
    if (u.strategy == SAMPLER_QUADTREE) {
      quadtree::QuadtreeSettings qs = qttest::testSettings();
      qs.threads = 1;
      std::vector<std::uint32_t> idx;
      quadtree::SamplerTables qt = quadtree::buildSamplerTables({{c.id(), p}}, qs, idx);
      b = quadtree::sampleCpu(qt, 0, c.id(), p, v, n, kSeed, 1);
    } else if (u.strategy == SAMPLER_TABULATED) {
      b = quadtree::sampleCpuStrategy(u.strategy, &tabTablesFor(c), 0, c.id(), p, v, n, kSeed, 1);
    } else {
      b = quadtree::sampleCpuStrategy(u.strategy, nullptr, 0, c.id(), p, v, n, kSeed, 1);
    }
    double sum = 0, sum2 = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      double x = 0;
      if (b.fOk[i].w > 0 && b.wPdf[i].w > 0) x = luminance(vec3(b.fOk[i])) * double(b.wPdf[i].z) / b.wPdf[i].w;
      sum += x;
      sum2 += x * x;
    }
    double mean = sum / n, var = std::max(0.0, sum2 / n - mean * mean), se = std::sqrt(var / (n - 1));
    double a = directionalAlbedo(c.id(), p, c.thetaDeg, c.phiDeg);
    double dev = std::abs(mean - a), tol = z * se + 2e-4 * a + 1e-7;
    const char* name = samplerName(static_cast<SamplerKind>(u.strategy));
    std::printf("%-9s %-42s mean=%.6f albedo=%.6f se=%.2e dev/se=%.2f\n", name, c.name().c_str(), mean, a,
                se, se > 0 ? dev / se : 0.0);
    if (dev > tol) {
      ++failures;
      ADD_FAILURE() << name << " " << c.name() << ": mean " << mean << " vs albedo " << a << " (se " << se
                    << ")";
    }
  }
  std::printf("unbiasedness: %zu cases, %d outside %.0f sigma, %.1f s\n", cases.size(), failures, z,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace
