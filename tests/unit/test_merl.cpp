// test_merl.cpp: measured BRDFs in the MERL layout (issue 20): file checks, the interpolation
// against the tabulated model, albedos, and the generic sampler over the table (chi-square on
// the CPU, exact envelopes, tree totals). Files are written at test time from analytic models.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>

#include "brdf/albedo.h"
#include "quadtree/quadtree_build.h"
#include "test_merl_common.h"
#include "util/error.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
std::string writeBytes(const std::string& name, const std::vector<unsigned char>& bytes) {
  std::string path = merltest::tempDir() + "/" + name;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  return path;
}
// The message loadMerl throws for `bytes`, or "" if it loads.
std::string loadError(const std::string& name, const std::vector<unsigned char>& bytes) {
  const std::string path = writeBytes(name, bytes);
  std::string message;
  try {
    loadMerl(path, "bad/" + name);
  } catch (const Error& e) {
    message = e.what();
  }
  std::filesystem::remove(path);
  return message;
}

}  // namespace

// Wrong header, wrong size, NaN/Inf, nothing measured, a missing file: a clear error naming the file.
TEST(Merl, BadInputIsAnErrorNamingTheFile) {
  const std::vector<unsigned char> good = readBytes(merltest::fileFor(merltest::sources()[0]));
  ASSERT_EQ(good.size(), kMerlFileBytes);
  auto expectError = [&](const std::string& name, const std::vector<unsigned char>& bytes, const std::string& phrase) {
    std::string msg = loadError(name, bytes);
    EXPECT_NE(msg.find("bad/" + name), std::string::npos) << name << ": " << msg;
    EXPECT_NE(msg.find(phrase), std::string::npos) << name << ": " << msg;
  };
  std::vector<unsigned char> b = good;
  std::int32_t dims[3] = {90, 90, 360};  // the full-phi layout some tools write
  std::memcpy(b.data(), dims, 12);
  expectError("header.binary", b, "dimension header (90, 90, 360)");
  expectError("empty.binary", {}, "shorter than the 12-byte dimension header");
  expectError("truncated.binary", std::vector<unsigned char>(good.begin(), good.end() - 8), "truncated");
  b = good;
  b.push_back(0);
  expectError("trailing.binary", b, "bytes after the table");
  auto setEntry = [&](std::vector<unsigned char>& bytes, std::size_t channel, std::size_t node, double v) {
    std::memcpy(bytes.data() + 12 + (channel * MERL_NODES + node) * 8, &v, 8);
  };
  b = good;
  setEntry(b, 1, (std::size_t(3) * 90 + 4) * 180 + 5, NAN);
  expectError("nan.binary", b, "green entry [theta_h 3, theta_d 4, phi_d 5] is NaN");
  b = good;
  setEntry(b, 2, 7, INFINITY);
  expectError("inf.binary", b, "blue entry [theta_h 0, theta_d 0, phi_d 7] is infinite");
  b = good;
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < MERL_NODES; ++n) setEntry(b, c, n, -1.0);
  expectError("unmeasured.binary", b, "no entry is measured");
  std::string msg;
  try {
    loadMerl(merltest::tempDir() + "/missing.binary", "bad/missing.binary");
  } catch (const Error& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("bad/missing.binary: cannot open"), std::string::npos) << msg;
}

// Negative ("not measured") nodes take the value of the nearest measured node along theta_d; the
// tool marks the nodes below the surface so, as real files do.
TEST(Merl, UnmeasuredNodesAreFilledFromTheNearestMeasuredOne) {
  const merltest::Source s = merltest::sources()[1];
  BrdfParams p = merltest::merlParams(s);
  const MerlTable& t = merlTable(p);
  std::vector<double> raw = tabulateMerl(findModel(s.model)->id, merltest::analyticParams(s));
  std::uint32_t negative = 0, checked = 0;
  for (std::size_t n = 0; n < MERL_NODES; ++n) negative += raw[n] < 0;
  EXPECT_EQ(t.unmeasured, negative);
  EXPECT_GT(negative, 0u);
  for (std::size_t i = 0; i < 90; i += 7)
    for (std::size_t k = 0; k < 180; k += 13)
      for (std::size_t j = 0; j < 90; ++j) {
        std::size_t n = (i * 90 + j) * 180 + k;
        if (raw[n] >= 0) {
          EXPECT_FLOAT_EQ(t.rgb[3 * n], float(raw[n] * kMerlScale[0]));
          continue;
        }
        std::size_t best = SIZE_MAX;  // nearest measured j' (smaller on ties)
        for (std::size_t d = 1; d < 90 && best == SIZE_MAX; ++d) {
          if (j >= d && raw[(i * 90 + j - d) * 180 + k] >= 0) best = j - d;
          else if (j + d < 90 && raw[(i * 90 + j + d) * 180 + k] >= 0) best = j + d;
        }
        if (best == SIZE_MAX) continue;
        ++checked;
        EXPECT_FLOAT_EQ(t.rgb[3 * n], float(raw[(i * 90 + best) * 180 + k] * kMerlScale[0])) << i << " " << j << " " << k;
      }
  EXPECT_GT(checked, 0u);
}

// The interpolant passes through the nodes: at a node's directions merl equals the model (float
// rounding of the coordinates and of the scale only).
TEST(Merl, InterpolationReproducesTheNodes) {
  const merltest::Source s = merltest::sources()[1];
  BrdfParams p = merltest::merlParams(s), a = merltest::analyticParams(s);
  const std::uint32_t model = findModel(s.model)->id;
  double worst = 0;
  int tested = 0;
  for (std::uint32_t i = 1; i < 89; i += 4)
    for (std::uint32_t j = 1; j < 89; j += 4)
      for (std::uint32_t k = 1; k < 179; k += 9) {
        vec3 wi, wo;
        if (!merlNodeDirections(i, j, k, wi, wo) || wi.z < 0.02f || wo.z < 0.02f) continue;
        vec3 fm = brdfEval(MODEL_MERL, p, wi, wo), fa = brdfEval(model, a, wi, wo);
        vec3 u = merlCoordinates(wi, wo);
        ASSERT_NEAR(u.x, float(i), 2e-3f) << i << " " << j << " " << k;
        ASSERT_NEAR(u.y, float(j), 2e-3f);
        ASSERT_NEAR(u.z, float(k), 2e-3f);
        double d = std::abs(luminance(fm) - luminance(fa)) / std::max(1e-3f, luminance(fa));
        worst = std::max(worst, d);
        ++tested;
      }
  std::printf("%d nodes: worst relative difference merl vs model %.3g\n", tested, worst);
  EXPECT_LT(worst, 1e-2);  // coordinate rounding (2e-3 table units) times the lobe's slope per node
  // Reciprocity (phi_d periodic with period pi) and zero below the surface.
  vec3 wi = normalize(vec3(0.3f, 0.2f, 0.8f)), wo = normalize(vec3(-0.5f, 0.1f, 0.6f));
  EXPECT_NEAR(luminance(brdfEval(MODEL_MERL, p, wi, wo)), luminance(brdfEval(MODEL_MERL, p, wo, wi)),
              1e-4 * luminance(brdfEval(MODEL_MERL, p, wi, wo)));
  EXPECT_EQ(luminance(brdfEval(MODEL_MERL, p, vec3(0.0f, 0.6f, -0.8f), wo)), 0.0f);
}

// Issue 20: Lambert rho = 0.5 tabulated gives albedo 0.5 within 1e-4 at 0, 30, 60, 85 degrees; a
// glossy model gives its own albedo within the tabulation error, the integral of |f_merl - f|
// cos over the hemisphere (|a_merl - a| can never exceed it; both figures are printed).
TEST(Merl, AlbedoOfTabulatedModels) {
  for (const merltest::Source& s : merltest::sources()) {
    BrdfParams p = merltest::merlParams(s), a = merltest::analyticParams(s);
    const std::uint32_t model = findModel(s.model)->id;
    for (double t : {0.0, 30.0, 60.0, 85.0}) {
      double am = directionalAlbedo(MODEL_MERL, p, t), aa = directionalAlbedo(model, a, t);
      double th = t * M_PI / 180;
      vec3 v(float(std::sin(th)), 0.0f, float(std::cos(th)));
      if (s.name == "lambert05") {
        std::printf("merl(%s) theta %4.1f: albedo %.8f\n", s.name.c_str(), t, am);
        EXPECT_NEAR(am, 0.5, 1e-4) << t;
        continue;
      }
      double l1 = hemisphereIntegral(
          [&](vec3 w) { return std::abs(double(luminance(brdfEval(MODEL_MERL, p, v, w))) - luminance(brdfEval(model, a, v, w))); },
          t, 0.0, 1e-3);
      std::printf("merl(%s) theta %4.1f: albedo %.6f, model %.6f, difference %.2e, tabulation error (L1) %.2e (%.2f%%)\n",
                  s.name.c_str(), t, am, aa, am - aa, l1, 100 * l1 / aa);
      EXPECT_LE(std::abs(am - aa), l1 * (1 + 1e-3) + 1e-6) << t;
    }
  }
}

// The tree over the table: every envelope is a proven bound (the builder's certify) and holds on
// a dense lattice; the tree totals equal the albedo quadrature.
TEST(Merl, TreesBoundTheTableAndIntegrateIt) {
  for (const merltest::Source& s : merltest::sources()) {
    BrdfParams p = merltest::merlParams(s);
    for (double t : {0.0, 30.0, 60.0, 85.0, 89.0}) {
      vec3 v = merltest::knownDirection(t);
      quadtree::Tree tree = quadtree::buildTree(MODEL_MERL, p, v, {});
      quadtree::EnvelopeAudit audit = quadtree::auditEnvelopes(MODEL_MERL, p, v, tree, 24);
      double a = directionalAlbedo(MODEL_MERL, p, t);
      std::printf("merl(%s) theta %4.1f: %u leaves, min acceptance %.3f, capped %u, tree %.6f albedo %.6f, largest f/e %.4f\n",
                  s.name.c_str(), t, tree.stats.leaves, tree.stats.minAcceptance, tree.stats.cappedLeaves, tree.mass, a, audit.worst);
      EXPECT_EQ(audit.leavesAbove, 0u) << s.name << " " << t;
      EXPECT_GE(tree.stats.minAcceptance, 0.5) << s.name << " " << t;
      EXPECT_NEAR(tree.mass, a, 1e-4 * a) << s.name << " " << t;
    }
  }
}

// The sharp table (ward) at the tables where the proof is hardest: near the plane of incidence at
// the horizon (69, 70 degrees) and at the mirror direction of a grazing v (89): the dense-lattice
// audit of every leaf, no sample that sees f above its leaf's envelope (2^18 per table), every
// uncapped leaf accepting at least 1/n_max, and the tree totals against the albedo quadrature.
TEST(Merl, SharpTableTreesAreProven) {
  const merltest::Source s = merltest::wardSource();
  BrdfParams p = merltest::merlParams(s);
  quadtree::QuadtreeSettings qs = qttest::testSettings();
  qs.onlyThetaTables = {69, 70, 89};
  std::vector<std::uint32_t> idx;
  quadtree::SamplerTables t = quadtree::buildSamplerTables({{MODEL_MERL, p}}, qs, idx);
  EXPECT_GE(t.materials[0].minAcceptance, 0.5);
  // Smallest count k with P(Binomial(2^18, 1e-4) > k) <= 0.001 (by the binomial recurrence).
  std::uint64_t failureLimit = 0;
  {
    const double n = double(1 << 18), q = 1e-4;
    double pk = std::pow(1.0 - q, n), cdf = pk;
    for (; 1.0 - cdf > 0.001; ++failureLimit) {
      pk *= (n - double(failureLimit)) / double(failureLimit + 1) * q / (1.0 - q);
      cdf += pk;
    }
  }
  for (std::uint32_t k : qs.onlyThetaTables) {
    const QuadTable& T = t.tables[t.sets[0].info.x + k];
    const vec3 v = quadTableDirection(T);
    quadtree::EnvelopeAudit audit = quadtree::auditEnvelopes(MODEL_MERL, p, v, t.nodes.data(), t.leaves.data(), T.info.x, T.data.x, 24);
    quadtree::SampleBatch b = quadtree::sampleCpu(t, 0, MODEL_MERL, p, v, 1u << 18, 4242u + k);
    const double a = directionalAlbedo(MODEL_MERL, p, double(k));
    std::printf("merl(ward) theta %u: tree %.6f albedo %.6f, largest f/e %.4f over %u leaves, %llu bound violations\n", k,
                double(T.data.x), a, audit.worst, audit.leaves, static_cast<unsigned long long>(b.boundViolations));
    EXPECT_EQ(audit.leavesAbove, 0u) << k;
    EXPECT_EQ(b.boundViolations, 0u) << k;
    // A trial failure (QT_MAX_TRIALS rejections, possible in the leaves at the depth cap, whose
    // proven envelopes may be loose) drops a sample of weight ~ the albedo: the estimate's relative
    // bias is the failure rate. Bound it by the catalogue's tolerance 1e-4: one-sided binomial
    // test at alpha 0.001 of the count in 2^18 samples.
    EXPECT_LE(b.trialFailures, failureLimit) << k;
    EXPECT_NEAR(T.data.x, a, 1e-4 * a) << k;
  }
}

// Chi-square of CPU samples against the sampler's pdf (the quadtree suite's test, its own
// Bonferroni over the measured cases); no bound violations or trial failures.
TEST(Merl, ChiSquareCpu) {
  qttest::TableCache tables;
  for (const merltest::Case& c : merltest::caseMatrix()) {
    BrdfParams p = merltest::merlParams(c.source);
    const quadtree::SamplerTables& t = tables.get(c.source.name, MODEL_MERL, p);
    quadtree::SampleBatch b = quadtree::sampleCpu(t, 0, MODEL_MERL, p, merltest::knownDirection(c.thetaDeg), qttest::kSamples, 1234u);
    qttest::Chi2Result r = merltest::checkChiSquare(c, t, p, b);
    std::printf("%-32s p=%.3g chi2=%.1f dof=%d sum(pdf)=%.5f trials/sample=%.3f\n", c.name().c_str(), r.pValue, r.chi2, r.dof,
                r.expectedTotal, double(b.trials) / qttest::kSamples);
  }
}
