// test_rough_dielectric.cpp: the rough dielectric BSDF (shaders/shared/brdf/rough_dielectric.h)
// over BOTH hemispheres: energy (R + T (n_i/n_o)^2 <= 1), the smooth limit against the delta
// dielectric's Fresnel split (dielectric.h), generalized reciprocity, the symmetry of the sides,
// and an independent quadrature of the normalisation.
//
// The hemisphere integrals are estimated by Monte Carlo with a sampler written here (not the
// renderer's): the microfacet normal m from D(m) |m.z| on wo's side, then reflection or
// refraction of wo about m with probability 1/2 each; the density of wi is the sum of the two
// maps' densities (Walter et al. 2007, eqs. 14 and 17), so the estimate is unbiased whatever
// f is. Standard errors come from the sample variance (Welford, double); fixed seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "brdf/registry.h"
#include "quadtree/quadtree_build.h"
#include "test_quadtree_chi2.h"

namespace nusselt {
namespace {

using shared::vec3;

double F(float alpha, float eta, vec3 wi, vec3 wo) { return shared::roughDielectricF(alpha, eta, wi, wo); }

vec3 dirAt(double thetaDeg, double phiDeg = 0.0) {
  double t = thetaDeg * M_PI / 180, p = phiDeg * M_PI / 180;
  return vec3(float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)), float(std::cos(t)));
}
vec3 flipZ(vec3 w) { return vec3(w.x, w.y, -w.z); }

double ggxD(vec3 m, double alpha) {
  double a2 = alpha * alpha, c2 = double(m.z) * m.z, s2 = double(m.x) * m.x + double(m.y) * m.y;
  double d = c2 * a2 + s2;
  return a2 / (M_PI * d * d);
}

// Density of wi under the test sampler for known wo (both unit; either side).
double samplerPdf(double alpha, double eta, vec3 wi, vec3 wo) {
  double side = wo.z > 0 ? 1.0 : -1.0;
  double ni = wi.z > 0 ? 1.0 : eta, no = wo.z > 0 ? 1.0 : eta;
  double pdf = 0;
  // Reflection: m = normalize(wi + wo), on wo's side.
  glm::dvec3 r = glm::dvec3(wi) + glm::dvec3(wo);
  double rl = glm::length(r);
  if (rl > 0) {
    glm::dvec3 m = r / rl;
    double om = glm::dot(glm::dvec3(wo), m);
    if (m.z * side > 0 && om > 0) pdf += 0.5 * ggxD(vec3(m), alpha) * std::abs(m.z) / (4 * om);
  }
  // Refraction (wi on the other side): m ~ -(n_i wi + n_o wo), oriented to wo's side.
  if (wi.z * wo.z < 0) {
    glm::dvec3 s = ni * glm::dvec3(wi) + no * glm::dvec3(wo);
    double s2 = glm::dot(s, s);
    glm::dvec3 m = -s / std::sqrt(s2);
    if (m.z * side < 0) m = -m;
    double om = glm::dot(glm::dvec3(wo), m), im = glm::dot(glm::dvec3(wi), m);
    if (om > 0 && im < 0) pdf += 0.5 * ggxD(vec3(m), alpha) * std::abs(m.z) * ni * ni * std::abs(im) / s2;
  }
  return pdf;
}

struct Split {
  double R = 0, T = 0;        // reflected albedo; transmitted albedo times (n_i / n_o)^2 (importance)
  double seR = 0, seT = 0, seSum = 0;  // standard errors of R, T and R + T
};

// Integrals over wi of f(wi, wo) |wi.z| on wo's side (R) and on the other side (T, scaled by
// (n_i / n_o)^2 to remove the radiance scaling), n samples.
Split estimate(float alpha, float eta, vec3 wo, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double side = wo.z > 0 ? 1.0 : -1.0;
  double mR = 0, mT = 0, mS = 0, qR = 0, qT = 0, qS = 0;
  for (int k = 1; k <= n; ++k) {
    double u1 = U(rng), u2 = U(rng), u3 = U(rng);
    // m from D(m) |m.z|: tan^2 theta = alpha^2 u / (1 - u).
    double t2 = double(alpha) * alpha * u1 / (1 - u1);
    double ct = 1 / std::sqrt(1 + t2), st = std::sqrt(std::max(0.0, 1 - ct * ct)), ph = 2 * M_PI * u2;
    glm::dvec3 m(st * std::cos(ph), st * std::sin(ph), side * ct);
    glm::dvec3 o(wo);
    double om = glm::dot(o, m);
    double wR = 0, wT = 0;
    if (om > 0) {
      glm::dvec3 wi;
      bool ok = true;
      if (u3 < 0.5) {
        wi = 2 * om * m - o;
      } else {
        // Refraction of wo through m into the other side: relative index e = n_other / n_o.
        double e = wo.z > 0 ? eta : 1.0 / eta;
        double s2t = (1 - om * om) / (e * e);
        if (s2t >= 1) ok = false;
        else wi = -o / e + (om / e - std::sqrt(1 - s2t)) * m;
      }
      if (ok) {
        vec3 w = vec3(glm::normalize(wi));
        double p = samplerPdf(alpha, eta, w, wo);
        if (p > 0 && w.z != 0) {
          double v = F(alpha, eta, w, wo) * std::abs(w.z) / p;
          double ni = w.z > 0 ? 1.0 : eta, no = wo.z > 0 ? 1.0 : eta;
          if (w.z * wo.z > 0) wR = v;
          else wT = v * (ni / no) * (ni / no);
        }
      }
    }
    double dR = wR - mR, dT = wT - mT, dS = wR + wT - mS;
    mR += dR / k; mT += dT / k; mS += dS / k;
    qR += dR * (wR - mR); qT += dT * (wT - mT); qS += dS * (wR + wT - mS);
  }
  Split s;
  s.R = mR; s.T = mT;
  s.seR = std::sqrt(qR / (n - 1) / n);
  s.seT = std::sqrt(qT / (n - 1) / n);
  s.seSum = std::sqrt(qS / (n - 1) / n);
  return s;
}

constexpr int kSamples = 1000000;
constexpr double kZ = 5.0;  // 5 standard errors: P(|Z| > 5) = 5.7e-7 per comparison

// The smooth limit: at alpha = 0.002 the reflected and transmitted albedos are the delta
// dielectric's Fresnel split, R = dielectricReflectance(eta, wo), T = 1 - R, from outside and
// from inside (where 60 degrees is beyond the critical angle: R = 1), and R at normal incidence
// is (n - 1)^2 / (n + 1)^2. Allowance beyond 5 standard errors: 1e-3, for the bias of a lobe of
// width alpha (shadowing 1 - G1 ~ (alpha tan theta)^2 / 4 = 1.3e-4 at 85 degrees, and the
// curvature of F over the spread of m, O(alpha^2 F'')).
TEST(RoughDielectric, SmoothLimitIsTheFresnelSplit) {
  const float alpha = 0.002f;
  for (float eta : {1.5f, 2.42f}) {
    double n = eta;
    double r0 = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
    unsigned seed = 1;
    for (int inside = 0; inside < 2; ++inside)
      for (double th : {0.0, 30.0, 60.0, 85.0}) {
        vec3 wo = dirAt(th);
        if (inside) wo = flipZ(wo);
        Split s = estimate(alpha, eta, wo, kSamples, seed++);
        double R = shared::dielectricReflectance(eta, wo);
        if (th == 0.0) EXPECT_NEAR(R, r0, 1e-6);
        std::printf("[rough_dielectric smooth] eta=%.2f %s theta=%2.0f  R=%.5f (+-%.1e) T=%.5f (+-%.1e)  Fresnel R=%.5f\n",
                    eta, inside ? "inside " : "outside", th, s.R, s.seR, s.T, s.seT, R);
        EXPECT_NEAR(s.R, R, kZ * s.seR + 1e-3) << "eta " << eta << " inside " << inside << " theta " << th;
        EXPECT_NEAR(s.T, 1 - R, kZ * s.seT + 1e-3) << "eta " << eta << " inside " << inside << " theta " << th;
      }
  }
}

// Energy: R + T (n_i / n_o)^2 <= 1 (5 standard errors) for the typical (alpha 0.2, eta 1.5) and
// hard (alpha 0.02, eta 2.42) sets and a rough one (alpha 0.7), from both sides; the values
// (1 minus the single-scattering loss of the Smith term) are printed.
TEST(RoughDielectric, EnergyIsConserved) {
  unsigned seed = 100;
  for (auto [alpha, eta] : {std::pair{0.2f, 1.5f}, std::pair{0.02f, 2.42f}, std::pair{0.7f, 1.5f}})
    for (int inside = 0; inside < 2; ++inside)
      for (double th : {0.0, 30.0, 60.0, 85.0}) {
        vec3 wo = dirAt(th, 20.0);
        if (inside) wo = flipZ(wo);
        Split s = estimate(alpha, eta, wo, kSamples, seed++);
        std::printf("[rough_dielectric energy] alpha=%.2f eta=%.2f %s theta=%2.0f  R=%.5f T=%.5f R+T=%.5f (+-%.1e)\n",
                    alpha, eta, inside ? "inside " : "outside", th, s.R, s.T, s.R + s.T, s.seSum);
        EXPECT_LE(s.R + s.T, 1 + kZ * s.seSum) << "alpha " << alpha << " eta " << eta << " inside " << inside
                                                << " theta " << th;
        EXPECT_GT(s.R, 0.0);
        if (!(inside && th >= 60.0)) EXPECT_GT(s.T, 0.0);  // (inside at 60, 85: mostly TIR)
      }
}

// The normalisation, independently of the sampler above: a midpoint rule over each hemisphere in
// (t, phi), |cos theta_i| = t^2 (dense towards the horizon), against the Monte Carlo estimate, alpha = 0.5 (a broad lobe the
// rule resolves: doubling the grid changes it by < 2e-4, checked below), at 30 degrees from both
// sides. Agreement within 5 standard errors + 2 x the grid's change.
TEST(RoughDielectric, QuadratureAgreesWithMonteCarlo) {
  const float alpha = 0.5f, eta = 1.5f;
  auto quad = [&](vec3 wo, int N, double& R, double& T) {
    R = T = 0;
    for (int side = 0; side < 2; ++side) {
      double acc = 0;
      // mu = cos theta = t^2 (dense at the horizon), f |cos| dw = f mu dmu dphi = f t^2 2t dt dphi.
      for (int a = 0; a < N; ++a) {
        double t = (a + 0.5) / N, mu = t * t, st = std::sqrt(1 - mu * mu);
        for (int b = 0; b < 2 * N; ++b) {
          double ph = (b + 0.5) / (2 * N) * 2 * M_PI;
          vec3 wi(float(st * std::cos(ph)), float(st * std::sin(ph)), float(side == 0 ? mu : -mu));
          acc += F(alpha, eta, wi, wo) * mu * 2 * t;
        }
      }
      acc *= (1.0 / N) * (2 * M_PI / (2 * N));
      bool same = (side == 0) == (wo.z > 0);
      double ni = side == 0 ? 1.0 : eta, no = wo.z > 0 ? 1.0 : eta;
      if (same) R = acc;
      else T = acc * (ni / no) * (ni / no);
    }
  };
  unsigned seed = 500;
  for (int inside = 0; inside < 2; ++inside) {
    vec3 wo = dirAt(30.0, 45.0);
    if (inside) wo = flipZ(wo);
    double R1, T1, R2, T2;
    quad(wo, 400, R1, T1);
    quad(wo, 800, R2, T2);
    Split s = estimate(alpha, eta, wo, kSamples, seed++);
    double gR = std::abs(R2 - R1), gT = std::abs(T2 - T1);
    std::printf("[rough_dielectric quadrature] %s R: quad %.5f (grid change %.1e) MC %.5f (+-%.1e); T: quad %.5f "
                "(grid change %.1e) MC %.5f (+-%.1e)\n",
                inside ? "inside " : "outside", R2, gR, s.R, s.seR, T2, gT, s.T, s.seT);
    EXPECT_LT(gR, 2e-4);
    EXPECT_LT(gT, 2e-4);
    EXPECT_NEAR(R2, s.R, kZ * s.seR + 2 * gR);
    EXPECT_NEAR(T2, s.T, kZ * s.seT + 2 * gT);
  }
}

// Generalized reciprocity: f(wi, wo) / n_o^2 = f(wo, wi) / n_i^2 (reflection: symmetric), and the
// symmetry of the sides f(wi, wo; eta) = f(flipZ wi, flipZ wo; 1 / eta), at random pairs over the
// sphere. Tolerance 1e-4 relative (float evaluation in two different orders) + 1e-6 absolute.
TEST(RoughDielectric, ReciprocityAndSides) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto randomDir = [&]() {
    double z = 2 * U(rng) - 1, ph = 2 * M_PI * U(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
    return vec3(float(s * std::cos(ph)), float(s * std::sin(ph)), float(z));
  };
  int transmitting = 0, nonzero = 0;
  for (auto [alpha, eta] : {std::pair{0.2f, 1.5f}, std::pair{0.02f, 2.42f}, std::pair{0.7f, 1.5f}})
    for (int k = 0; k < 20000; ++k) {
      vec3 a = randomDir(), b = randomDir();
      double na = a.z > 0 ? 1.0 : eta, nb = b.z > 0 ? 1.0 : eta;
      double fab = F(alpha, eta, a, b), fba = F(alpha, eta, b, a);
      ASSERT_TRUE(std::isfinite(fab) && fab >= 0) << fab;
      double x = fab / (nb * nb), y = fba / (na * na);
      EXPECT_NEAR(x, y, 1e-4 * std::max(x, y) + 1e-6) << "alpha " << alpha << " a.z " << a.z << " b.z " << b.z;
      double g = F(alpha, 1.0f / eta, flipZ(a), flipZ(b));
      EXPECT_NEAR(fab, g, 1e-4 * std::max(fab, g) + 1e-6) << "alpha " << alpha << " a.z " << a.z << " b.z " << b.z;
      if (fab > 0) ++nonzero;
      if (fab > 0 && a.z * b.z < 0) ++transmitting;
    }
  // The pairs exercise transmission (the test cannot pass on a zero BTDF).
  EXPECT_GT(transmitting, 1000);
  EXPECT_GT(nonzero, 10000);
}

// The model's catalogue entry: transmitting, not delta, the shaders' modelTransmits equal to the
// catalogue for every model; the parameters seen from the inside; eval through the dispatch equals
// the scalar formula; zero in the plane of the surface.
TEST(RoughDielectric, CatalogueAndDispatch) {
  const ModelSpec* m = findModel("rough_dielectric");
  ASSERT_NE(m, nullptr);
  EXPECT_TRUE(m->transmits);
  EXPECT_FALSE(m->delta);
  for (const ModelSpec& o : allModels()) {
    // The transmitting models: this one and the thin sheet (test_rough_thin_dielectric.cpp).
    EXPECT_EQ(o.transmits, o.id == m->id || o.name == "rough_thin_dielectric") << o.name;
    // The shaders' trait (dispatch.h) is the catalogue's.
    EXPECT_EQ(shared::modelTransmits(o.id), o.transmits) << o.name;
  }
  BrdfParams p = packParams(*m, typicalParams(*m), "rough_dielectric");
  // Seen from the inside: eta -> 1 / eta, so that f(wi, wo) = f'(flipZ wi, flipZ wo) (the renderer's
  // turned-over frame); etaScale (n_wi / n_wo)^2 of a crossing from either side.
  BrdfParams q = shared::transmissionInsideParams(m->id, p);
  EXPECT_EQ(shared::brdfParam(q, ROUGH_DIELECTRIC_ETA), 1.0f / 1.5f);
  EXPECT_EQ(shared::brdfParam(q, ROUGH_DIELECTRIC_ALPHA), 0.2f);
  for (auto [wi, wo] : {std::pair{flipZ(dirAt(20, 180)), dirAt(30)}, std::pair{dirAt(50, 90), dirAt(10)}}) {
    const float a = shared::brdfEval(m->id, p, wi, wo).x, b = shared::brdfEval(m->id, q, flipZ(wi), flipZ(wo)).x;
    EXPECT_GT(a, 0.0f);
    EXPECT_NEAR(a, b, 1e-5f * a);
  }
  EXPECT_FLOAT_EQ(shared::transmissionEtaScale(m->id, p, false), 1.5f * 1.5f);
  EXPECT_FLOAT_EQ(shared::transmissionEtaScale(m->id, q, true), 1.0f / (1.5f * 1.5f));
  vec3 wo = dirAt(30), wi = flipZ(dirAt(20, 180));
  EXPECT_EQ(shared::brdfEval(MODEL_ROUGH_DIELECTRIC, p, wi, wo).x, float(F(0.2f, 1.5f, wi, wo)));
  EXPECT_GT(F(0.2f, 1.5f, wi, wo), 0.0);
  EXPECT_EQ(F(0.2f, 1.5f, vec3(1, 0, 0), wo), 0.0);
}

// The generic sampler's two discs (quadtree_build.h, BuildSettings::lowerDisc): for the typical
// and hard sets at 0, 30, 60 and 85 degrees, the upper tree's total is the reflected albedo R and
// the lower tree's the transmitted one (radiance: T (n_o / n_i)^2), both against the Monte Carlo
// estimate above (5 standard errors + 1e-4 relative: the builder's integration tolerance), and
// every leaf's envelope bounds f on a 25 x 25 lattice (as Quadtree.EnvelopesBoundFOnADenseLattice).
TEST(RoughDielectric, LowerDiscTreeTotalsAndEnvelopes) {
  const ModelSpec* m = findModel("rough_dielectric");
  unsigned seed = 900;
  for (int hard = 0; hard < 2; ++hard) {
    BrdfParams p = packParams(*m, hard ? hardParams(*m) : typicalParams(*m), "rough_dielectric");
    float alpha = shared::brdfParam(p, ROUGH_DIELECTRIC_ALPHA), eta = shared::brdfParam(p, ROUGH_DIELECTRIC_ETA);
    for (double th : {0.0, 30.0, 60.0, 85.0}) {
      vec3 v = dirAt(th);
      quadtree::BuildSettings bs;
      quadtree::Tree up = quadtree::buildTree(m->id, p, v, bs);
      bs.lowerDisc = true;
      quadtree::Tree low = quadtree::buildTree(m->id, p, v, bs);
      Split s = estimate(alpha, eta, v, kSamples, seed++);
      // wo outside (n_o = 1), wi inside (n_i = eta): T (radiance) = the estimate / (n_i / n_o)^2.
      double Trad = s.T / (eta * eta), seTrad = s.seT / (eta * eta);
      std::printf("[rough_dielectric trees] %s theta=%2.0f  upper %.6f (MC R %.6f +-%.1e)  lower %.6f (MC T %.6f +-%.1e)  "
                  "leaves %u + %u, depth %u / %u\n",
                  hard ? "hard   " : "typical", th, up.mass, s.R, s.seR, low.mass, Trad, seTrad, up.stats.leaves,
                  low.stats.leaves, up.stats.maxDepth, low.stats.maxDepth);
      EXPECT_NEAR(up.mass, s.R, kZ * s.seR + 1e-4 * s.R) << "theta " << th << " hard " << hard;
      EXPECT_NEAR(low.mass, Trad, kZ * seTrad + 1e-4 * Trad) << "theta " << th << " hard " << hard;
      quadtree::EnvelopeAudit a = quadtree::auditEnvelopes(m->id, p, v, low, 24, true);
      EXPECT_EQ(a.leavesAbove, 0u) << "lower disc theta " << th << " hard " << hard << ": worst f / e " << a.worst;
      // The audit sees the lower disc's f (a tree audited as upper would be checked against the
      // reflection, a different function).
      EXPECT_GT(a.leaves, 0u);
    }
  }
}

// The generic sampler over both discs (quadtree.h, QT_SET_TRANSMITS), on the CPU: for the typical
// and hard sets at 0, 30, 60, 85 degrees (tables) and 37.3 (between tables), 2^20 samples binned
// over the sphere (qttest::quadChiSquare: 16 rings in cos theta over [-1, 1] with an edge at 0, x 32
// sectors, equal-probability bins of an independent pilot run; expected counts from quadPdf), at
// significance 0.01 with Bonferroni over the 10 cases; the share of samples below the surface
// against the tables' a_low / (a_up + a_low) (on tables; z-test, |z| < 5); the pdf integrates to 1
// over the sphere; on tables every weight f |cos| / pdf is a_up + a_low (2e-3); no bound
// violations, no trial failures. (QuadtreeGpu.ChiSquareCpuGpuAndParity runs these cases too, within its matrix.)
// Then the same test must reject a broken sampler: the tables' lower masses halved, which halves
// the probability of the lower disc while its trees (and so the density within it) stay as they
// are; its pdf claims f |cos| / (a_up + a_low / 2) (a sampler that can fail). The typical set seen
// from the inside (eta 1 / 1.5, the renderer's set for paths inside) is the third set (Bonferroni
// over 15 cases).
TEST(RoughDielectric, ChiSquareBothDiscs) {
  const ModelSpec* m = findModel("rough_dielectric");
  const std::uint32_t n = qttest::kSamples;
  const std::vector<double> angles = {0.0, 30.0, 60.0, 85.0, 37.3};
  const double alpha = 0.01 / (3.0 * double(angles.size()));
  int brokenRejected = 0, brokenCases = 0;
  // hard = 2: the typical set seen from the inside (eta 1 / 1.5: transmissionInsideParams), the
  // renderer's second set for paths inside the object.
  for (int hard = 0; hard < 3; ++hard) {
    BrdfParams p = packParams(*m, hard == 1 ? hardParams(*m) : typicalParams(*m), "rough_dielectric");
    if (hard == 2) p = shared::transmissionInsideParams(m->id, p);
    std::vector<std::uint32_t> idx;
    quadtree::SamplerTables t = quadtree::buildSamplerTables({{m->id, p}}, qttest::testSettings(), idx);
    ASSERT_EQ(t.sets.size(), 1u);
    ASSERT_NE(t.sets[0].info.w & QT_SET_TRANSMITS, 0u);
    ASSERT_EQ(t.tables.size(), 2u * t.sets[0].info.y * t.sets[0].info.z);
    for (double th : angles) {
      qttest::Case c{"rough_dielectric", hard == 1, th, 0.0};
      vec3 v = qttest::knownDirection(c);
      const std::string label = (hard == 2 ? "inside " : "") + c.name();
      quadtree::SampleBatch b = quadtree::sampleCpu(t, 0, m->id, p, v, n, 1234u);
      quadtree::SampleBatch pilot = quadtree::sampleCpu(t, 0, m->id, p, v, qttest::kPilotSamples, 99u);
      EXPECT_EQ(b.boundViolations, 0u) << label;
      EXPECT_EQ(b.trialFailures, 0u) << label;
      qttest::Chi2Result r = qttest::quadChiSquare(t, 0, m->id, p, v, pilot.wPdf, b.wPdf);
      bool onTable = std::fmod(th, 1.0) == 0.0;
      std::uint32_t k = std::uint32_t(std::lround(th));
      double aUp = t.tables[k].data.x, aLow = t.tables[t.sets[0].info.y + k].data.x;
      double below = 0, ok = 0, lo = 1e30, hi = 0;
      for (std::uint32_t i = 0; i < n; ++i) {
        if (b.wPdf[i].w <= 0) continue;
        ++ok;
        if (b.wPdf[i].z < 0) ++below;
        double wgt = shared::luminance(vec3(b.fOk[i])) * std::abs(b.wPdf[i].z) / b.wPdf[i].w / (aUp + aLow);
        lo = std::min(lo, wgt);
        hi = std::max(hi, wgt);
      }
      double share = aLow / (aUp + aLow), z = (below / ok - share) / std::sqrt(share * (1 - share) / ok);
      std::printf("[rough_dielectric chi2] %-44s p=%.3g chi2=%.1f dof=%d sum(pdf)=%.5f below %.5f (a_low/a %.5f, z=%.2f) "
                  "weight/a in [%.5f, %.5f] evals/sample=%.3f\n",
                  label.c_str(), r.pValue, r.chi2, r.dof, r.expectedTotal, below / ok, share, z, lo, hi,
                  double(b.evaluations) / n);
      EXPECT_NEAR(r.expectedTotal, 1.0, 2e-4) << label;
      EXPECT_GE(r.pValue, alpha) << label << "\n" << r.dump;
      if (onTable) {
        EXPECT_LT(std::abs(z), 5.0) << label;
        EXPECT_NEAR(lo, 1.0, 2e-3) << label;
        EXPECT_NEAR(hi, 1.0, 2e-3) << label;
      }
      // The broken sampler (tables' lower masses halved), on tables, the typical set.
      if (!onTable || hard) continue;
      quadtree::SamplerTables broken = t;
      for (std::uint32_t j = t.sets[0].info.y; j < broken.tables.size(); ++j) broken.tables[j].data.x *= 0.5f;
      quadtree::SampleBatch bb = quadtree::sampleCpu(broken, 0, m->id, p, v, n, 1234u);
      quadtree::SampleBatch bp = quadtree::sampleCpu(broken, 0, m->id, p, v, qttest::kPilotSamples, 99u);
      qttest::Chi2Result rb = qttest::quadChiSquare(broken, 0, m->id, p, v, bp.wPdf, bb.wPdf);
      std::printf("[rough_dielectric chi2] broken (lower disc probability halved) %s: p=%.3g chi2=%.1f dof=%d\n",
                  label.c_str(), rb.pValue, rb.chi2, rb.dof);
      ++brokenCases;
      if (rb.pValue < alpha) ++brokenRejected;
    }
  }
  EXPECT_EQ(brokenRejected, brokenCases) << "the chi-square test did not reject every broken sampler";
}

}  // namespace
}  // namespace nusselt
