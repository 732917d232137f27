// test_quadtree.cpp: the generic quadtree sampler on the CPU (the shared code of
// shaders/shared/quadtree.h): tree totals against directionalAlbedo, envelopes, and the cache. (Its
// chi-square goodness of fit, weights, acceptance, bound violations and trial failures on the CPU
// are tested with the GPU's: tests/gpu/test_quadtree_gpu.cpp.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "brdf/albedo.h"
#include "quadtree/quadtree_build.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

// Integral over the disc of luminance f(w, v), v = (sin th, 0, cos th), integrating over the FIRST
// argument (the tree's convention; directionalAlbedo integrates over the second, which differs for
// the non-reciprocal strauss). Variables (c = cos theta, phi): dA = c dc dphi, which makes the
// 1/cos rim growth of strauss / beard_maxwell bounded; composite 4-point Gauss-Legendre on a
// P x 2P grid with c graded towards the rim (c = s^2).
double albedoFirstArgument(std::uint32_t model, const BrdfParams& p, double th, int P = 512) {
  static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  vec3 v(float(std::sin(th)), 0.0f, float(std::cos(th)));
  double sum = 0;
  for (int a = 0; a < P; ++a)
    for (int i = 0; i < 4; ++i) {
      double sv = (a + 0.5 * (1 + gx[i])) / P, c = sv * sv, r = std::sqrt((1 - c) * (1 + c));
      double row = 0;
      for (int b = 0; b < 2 * P; ++b)
        for (int j = 0; j < 4; ++j) {
          double ph = M_PI * (b + 0.5 * (1 + gx[j])) / P;
          vec3 w(float(r * std::cos(ph)), float(r * std::sin(ph)), float(c));
          row += gw[j] * quadEvalLum(model, p, w, v);
        }
      sum += gw[i] * row * c * 2 * sv;  // dc = 2 s ds
    }
  return sum * 0.25 * (1.0 / P) * (M_PI / P);
}

}  // namespace

// Each tree's total (integral of luminance f over the disc) is the directional albedo within 1e-4,
// at normal incidence, 30, 37, 60, 85 degrees and at the last table (89 degrees, grazing). (The
// chi-square suites check every table they use: their pdf must integrate to 1 within 2e-4.)
TEST(Quadtree, TreeTotalsMatchDirectionalAlbedo) {
  double worst = 0;
  std::string worstName;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      BrdfParams p = packParams(m, hard ? hardParams(m) : typicalParams(m), m.name);
      for (double t : {0.0, 30.0, 37.0, 60.0, 85.0, 89.0}) {
        double th = t * M_PI / 180;
        quadtree::Tree tree = quadtree::buildTree(m.id, p, vec3(float(std::sin(th)), 0.0f, float(std::cos(th))), {});
        // strauss is not reciprocal: the tree integrates f(., v) over its first argument, which
        // directionalAlbedo (integral over the second) does not; our own quadrature there.
        double a = m.id == MODEL_STRAUSS ? albedoFirstArgument(m.id, p, th) : directionalAlbedo(m.id, p, t);
        double err = std::abs(tree.mass - a) / std::max(a, 1e-30);
        std::string name = m.name + (hard ? "/hard" : "/typical") + "/theta=" + std::to_string(int(t));
        EXPECT_LE(err, 1e-4) << name << ": tree " << tree.mass << " albedo " << a;
        if (err > worst) { worst = err; worstName = name; }
      }
    }
  }
  std::printf("worst relative difference tree total vs directionalAlbedo: %.3g (%s)\n", worst, worstName.c_str());
}

// The anisotropic sets (trees per incident azimuth) over a grid of incident directions: a streak
// of f (ward's hard set: roughness 0.01 across, 0.3 along) that crosses a rim cell between its
// Gauss points once lost 9 % of the albedo at theta 40, phi 67.5 while every phi = 0 angle above
// passed. Threshold 5e-4: the worst of this grid is 1.9e-4 (ashikhmin_shirley hard, theta 85,
// phi 22.5; an independent 8000 x 32000 midpoint rule agrees with directionalAlbedo to 4e-8).
// Normal incidence has no azimuth: one case (its five azimuths built the same tree, v = (0, 0, 1)
// exactly, and compared it with five quadratures of the same integral: 36 cases per set, not 40).
TEST(Quadtree, AnisotropicTreeTotalsOverIncidentAzimuth) {
  double worst = 0;
  std::string worstName;
  int cases = 0;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      BrdfParams p = packParams(m, hard ? hardParams(m) : typicalParams(m), m.name);
      if (!quadtree::modelTraits(m.id, p).anisotropic) continue;
      for (double t : {0.0, 15.0, 25.0, 40.0, 55.0, 70.0, 80.0, 85.0})
        for (double ph : {0.0, 22.5, 45.0, 67.5, 90.0}) {
          if (t == 0.0 && ph != 0.0) continue;
          double th = t * M_PI / 180, pr = ph * M_PI / 180;
          vec3 v(float(std::sin(th) * std::cos(pr)), float(std::sin(th) * std::sin(pr)), float(std::cos(th)));
          quadtree::Tree tree = quadtree::buildTree(m.id, p, v, {});
          double a = directionalAlbedo(m.id, p, t, ph);
          double err = std::abs(tree.mass - a) / std::max(a, 1e-30);
          std::string name = m.name + (hard ? "/hard" : "/typical") + "/theta=" + std::to_string(int(t)) + "/phi=" + std::to_string(ph);
          EXPECT_LE(err, 5e-4) << name << ": tree " << tree.mass << " albedo " << a;
          ++cases;
          if (err > worst) { worst = err; worstName = name; }
        }
    }
  }
  std::printf("%d anisotropic cases: worst relative difference tree total vs directionalAlbedo %.3g (%s)\n", cases, worst,
              worstName.c_str());
}

// Arbiter for the models unbounded at the rim: an independent quadrature (first argument) beside
// the tree and directionalAlbedo.
TEST(Quadtree, RimModelsIndependentQuadrature) {
  for (const char* name : {"beard_maxwell", "strauss", "schlick"}) {
    const ModelSpec* m = findModel(name);
    BrdfParams p = packParams(*m, typicalParams(*m), name);
    double th = 85 * M_PI / 180;
    quadtree::Tree tree = quadtree::buildTree(m->id, p, vec3(float(std::sin(th)), 0.0f, float(std::cos(th))), {});
    double q1 = albedoFirstArgument(m->id, p, th, 256), q2 = albedoFirstArgument(m->id, p, th, 512);
    double da = directionalAlbedo(m->id, p, 85.0);
    std::printf("%s typical 85: tree %.7f directionalAlbedo %.7f quadrature(256) %.7f quadrature(512) %.7f\n", name, tree.mass,
                da, q1, q2);
    EXPECT_NEAR(q1, q2, 1e-5 * q2) << name << ": reference quadrature not converged";
    EXPECT_NEAR(tree.mass, q2, 1e-4 * q2) << name;
  }
}

// The envelopes are true bounds: every leaf of the trees of every model (typical and hard) at
// 0, 25, 30, 40, 60, 85 and 89 degrees (and azimuths 20, 45 and 67.5 degrees for the anisotropic
// sets), checked against f on a 25 x 25 lattice of its proposal domain (the builder's own lattice
// in leaves below 1/n_max is 21 x 21: the two share only the points at quarters). Any f > e there would bias the sampler (the sampling tests count such samples too).
TEST(Quadtree, EnvelopesBoundFOnADenseLattice) {
  double worst = 0;
  std::string worstName;
  std::uint64_t evaluations = 0;
  std::uint32_t leaves = 0;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      BrdfParams p = packParams(m, hard ? hardParams(m) : typicalParams(m), m.name);
      bool aniso = quadtree::modelTraits(m.id, p).anisotropic;
      for (double t : {0.0, 25.0, 30.0, 40.0, 60.0, 85.0, 89.0})
        for (double ph : aniso ? std::vector<double>{0.0, 20.0, 45.0, 67.5} : std::vector<double>{0.0}) {
          double th = t * M_PI / 180, pr = ph * M_PI / 180;
          vec3 v(float(std::sin(th) * std::cos(pr)), float(std::sin(th) * std::sin(pr)), float(std::cos(th)));
          quadtree::Tree tree = quadtree::buildTree(m.id, p, v, {});
          quadtree::EnvelopeAudit a = quadtree::auditEnvelopes(m.id, p, v, tree, 24);
          std::string name = m.name + (hard ? "/hard" : "/typical") + "/theta=" + std::to_string(int(t)) + "/phi=" + std::to_string(int(ph));
          EXPECT_EQ(a.leavesAbove, 0u) << name << ": " << a.leavesAbove << " leaves (mass " << a.massAbove / tree.mass
                                       << " of the total) where f exceeds the envelope, by up to " << a.worst;
          evaluations += a.evaluations;
          leaves += a.leaves;
          if (a.worst > worst) { worst = a.worst; worstName = name; }
        }
    }
  }
  std::printf("%u leaves audited with %llu evaluations: largest f / envelope %.4f (%s)\n", leaves,
              static_cast<unsigned long long>(evaluations), worst, worstName.c_str());
}

// Chi-square of CPU samples against the sampler's pdf, weights, acceptance, bound violations and
// trial failures over the case matrix: QuadtreeGpu.ChiSquareCpuGpuAndParity (tests/gpu/), which
// tests the CPU's and the GPU's samples of each case against one computation of its bins.

// A second build of the same material comes from the cache; a corrupt entry is detected and rebuilt.
TEST(Quadtree, DiskCache) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("nusselt-qt-cache-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  ::setenv("NUSSELT_CACHE_DIR", dir.c_str(), 1);
  const ModelSpec* m = findModel("phong");
  BrdfParams p = packParams(*m, typicalParams(*m), "phong");
  quadtree::QuadtreeSettings s;
  s.thetaTables = 6;
  std::vector<std::uint32_t> idx;
  quadtree::SamplerTables a = quadtree::buildSamplerTables({{m->id, p}}, s, idx);
  EXPECT_EQ(a.cacheMisses, 1u);
  quadtree::SamplerTables b = quadtree::buildSamplerTables({{m->id, p}}, s, idx);
  EXPECT_EQ(b.cacheHits, 1u);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(QuadNode)));
  // Corrupt one byte of the payload.
  fs::path file;
  for (const auto& e : fs::directory_iterator(dir)) file = e.path();
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(200);
    char c = 0x5a;
    f.write(&c, 1);
  }
  quadtree::SamplerTables c = quadtree::buildSamplerTables({{m->id, p}}, s, idx);
  EXPECT_EQ(c.cacheRejected, 1u);
  EXPECT_EQ(0, std::memcmp(a.leaves.data(), c.leaves.data(), a.leaves.size() * sizeof(QuadLeaf)));
  // Truncated file.
  fs::resize_file(file, 100);
  quadtree::SamplerTables d = quadtree::buildSamplerTables({{m->id, p}}, s, idx);
  EXPECT_EQ(d.cacheRejected, 1u);
  quadtree::SamplerTables e = quadtree::buildSamplerTables({{m->id, p}}, s, idx);
  EXPECT_EQ(e.cacheHits, 1u);
  ::unsetenv("NUSSELT_CACHE_DIR");
  fs::remove_all(dir);
}

// The density quadSample returns with a direction is quadPdf's at that direction: between tables
// the sampler reuses the f its rejection evaluated for the drawn tree's corner of the mixture
// (quadMixturePdfKnown) and evaluates the other corners only; the two must agree to float rounding
// on every sample (isotropic, anisotropic and transmitting sets; directions between tables and one
// on a table; the defensive cosine's samples included, which evaluate every corner).
TEST(Quadtree, SampledPdfIsQuadPdf) {
  struct Case {
    const char* model;
    bool hard;
    double theta, phi;
  };
  const Case cases[] = {{"blinn", false, 31.37, 0}, {"blinn", true, 62.71, 40}, {"ward", true, 47.3, 23.9},
                        {"ward", false, 30.0, 0},   {"rough_dielectric", false, 55.55, 10}, {"lafortune", false, 84.2, 0}};
  const std::uint32_t n = 20000;
  for (const Case& c : cases) {
    const ModelSpec* m = findModel(c.model);
    ASSERT_NE(m, nullptr);
    BrdfParams p = packParams(*m, c.hard ? hardParams(*m) : typicalParams(*m), c.model);
    std::vector<std::uint32_t> set;
    quadtree::SamplerTables t = quadtree::buildSamplerTables({{m->id, p}}, quadtree::QuadtreeSettings{}, set);
    const double th = c.theta * M_PI / 180, ph = c.phi * M_PI / 180;
    vec3 v(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
    quadtree::SampleBatch b = quadtree::sampleCpu(t, set[0], m->id, p, v, n, 4321u);
    quadtree::QuadHostScope scope(t);
    double worst = 0;
    std::uint32_t compared = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const vec4& s = b.wPdf[i];
      if (!(s.w > 0)) continue;
      float q = quadPdf(set[0], m->id, p, v, vec3(s));
      ASSERT_GT(q, 0.0f) << c.model << " sample " << i;
      double rel = std::abs(double(q) - double(s.w)) / double(q);
      worst = std::max(worst, rel);
      ++compared;
    }
    std::printf("%s %s theta %.2f phi %.1f: %u samples, worst relative difference %.3g\n", c.model,
                c.hard ? "hard" : "typical", c.theta, c.phi, compared, worst);
    EXPECT_GT(compared, n * 9 / 10) << c.model;
    // Rounding only: a lobe of exponent ~1e4 (blinn hard) turns one ulp of its argument into a
    // relative 1e-3 .. 1e-4 of f (measured: 5.4e-5); a wrong corner's weight or f is off by the
    // interpolation weights' order (>= 1e-2 here).
    EXPECT_LT(worst, 1e-3) << c.model << " theta " << c.theta;
  }
}
