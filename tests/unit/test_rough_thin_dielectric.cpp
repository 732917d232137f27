// test_rough_thin_dielectric.cpp: the thin rough sheet (shaders/shared/brdf/rough_thin_dielectric.h)
// over BOTH hemispheres: energy (reflection + transmission = the GGX albedo with F = 1, <= 1),
// the smooth limit against thin_dielectric's split, symmetry and the two sides, the catalogue
// entry, and the generic sampler's two discs (tree totals, envelopes, chi-square).
//
// Integrals over a hemisphere: hemisphereIntegral (src/brdf/albedo.h, nested adaptive
// Gauss-Kronrod graded towards the mirror direction, relative tolerance 1e-7 here). The lower
// hemisphere is integrated through the mirror map w -> flipZ(w), which keeps |w.z| and the solid
// angle, so that the transmission lobe (peaked at -v) is integrated as a lobe peaked at the mirror
// direction, where the rule's breakpoints are.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "brdf/albedo.h"
#include "brdf/registry.h"
#include "quadtree/quadtree_build.h"
#include "test_quadtree_chi2.h"

namespace nusselt {
namespace {

using shared::vec3;

double F(float alpha, float eta, vec3 wi, vec3 wo) { return shared::roughThinDielectricF(alpha, eta, wi, wo); }

vec3 dirAt(double thetaDeg, double phiDeg = 0.0) {
  double t = thetaDeg * M_PI / 180, p = phiDeg * M_PI / 180;
  return vec3(float(std::sin(t) * std::cos(p)), float(std::sin(t) * std::sin(p)), float(std::cos(t)));
}
vec3 flipZ(vec3 w) { return vec3(w.x, w.y, -w.z); }

// The GGX microfacet reflection lobe with F = 1, written here in double from its definition
// (Walter et al. 2007: D(h) G1(wi, h) G1(wo, h) / (4 wi.z wo.z), both above the surface), as the
// reference the model's energy must equal.
double ggxLobeF1(double alpha, vec3 wi, vec3 wo) {
  glm::dvec3 a(wi), b(wo);
  if (a.z <= 0 || b.z <= 0) return 0;
  glm::dvec3 h = glm::normalize(a + b);
  auto g1 = [&](glm::dvec3 w) {
    if (glm::dot(w, h) <= 0) return 0.0;
    double t2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
    return 2 / (1 + std::sqrt(1 + alpha * alpha * t2));
  };
  double a2 = alpha * alpha, c2 = h.z * h.z, d = c2 * (a2 - 1) + 1;
  double D = a2 / (M_PI * d * d);
  return D * g1(a) * g1(b) / (4 * a.z * b.z);
}

struct Split {
  double R = 0, T = 0, A1 = 0;  // reflected, transmitted (grey, no tint), the F = 1 GGX albedo
};
constexpr double kRelTol = 1e-7;
Split split(float alpha, float eta, double thetaDeg, double phiDeg) {
  const vec3 v = dirAt(thetaDeg, phiDeg);
  Split s;
  s.R = hemisphereIntegral([&](vec3 w) { return F(alpha, eta, w, v); }, thetaDeg, phiDeg, kRelTol);
  s.T = hemisphereIntegral([&](vec3 w) { return F(alpha, eta, flipZ(w), v); }, thetaDeg, phiDeg, kRelTol);
  s.A1 = hemisphereIntegral([&](vec3 w) { return ggxLobeF1(alpha, w, v); }, thetaDeg, phiDeg, kRelTol);
  return s;
}

// Energy: for every wo the directional albedo R + T (tint 1) equals the GGX reflection albedo with
// F = 1 (the F = 1 lobe integrated independently above), which is <= 1; both R and T are
// positive. Sets: the catalogue's typical (alpha 0.2, eta 1.5) and hard (0.02, 2.42), a rough one
// (0.7, 1.5) and the roughest (1, 4); 0 to 89 degrees. Tolerance: 1e-5 relative, 100 times the
// quadrature's (three integrals, each within about 1e-7; float evaluation of f adds about 1e-7).
// The printed loss 1 - A1 is the Smith term's single-scattering loss.
TEST(RoughThinDielectric, EnergyIsTheGgxAlbedoWithFOne) {
  for (auto [alpha, eta] : {std::pair{0.2f, 1.5f}, std::pair{0.02f, 2.42f}, std::pair{0.7f, 1.5f}, std::pair{1.0f, 4.0f}})
    for (double th : {0.0, 30.0, 60.0, 75.0, 85.0, 89.0}) {
      const Split s = split(alpha, eta, th, 20.0);
      std::printf("[rough_thin_dielectric energy] alpha=%.2f eta=%.2f theta=%2.0f  R=%.6f T=%.6f R+T=%.6f  "
                  "GGX albedo (F=1) %.6f  loss %.4f\n",
                  alpha, eta, th, s.R, s.T, s.R + s.T, s.A1, 1 - s.A1);
      EXPECT_NEAR(s.R + s.T, s.A1, 1e-5 * s.A1) << "alpha " << alpha << " eta " << eta << " theta " << th;
      EXPECT_LE(s.R + s.T, 1.0 + 1e-6) << "alpha " << alpha << " eta " << eta << " theta " << th;
      EXPECT_GT(s.R, 0.0);
      EXPECT_GT(s.T, 0.0);
    }
}

// The smooth limit is thin_dielectric: at alpha 0.002 the reflected and transmitted parts are the
// sheet's 2 R1 / (1 + R1) and (1 - R1) / (1 + R1) (thinDielectricReflectance), from 0 to 85
// degrees. Allowance 1e-3: the bias of a lobe of width alpha (as RoughDielectric's smooth limit:
// the shadowing 1 - G1 ~ (alpha tan theta)^2 / 4 is 1.3e-4 at 85 degrees at alpha 0.002, and the
// curvature of R over the spread of the microfacet normals is O(alpha^2)).
TEST(RoughThinDielectric, SmoothLimitIsThinDielectric) {
  const float alpha = 0.002f;
  for (float eta : {1.5f, 2.42f})
    for (double th : {0.0, 30.0, 60.0, 85.0}) {
      const Split s = split(alpha, eta, th, 0.0);
      const double R = shared::thinDielectricReflectance(eta, dirAt(th));
      std::printf("[rough_thin_dielectric smooth] eta=%.2f theta=%2.0f  R=%.6f T=%.6f  thin_dielectric R=%.6f T=%.6f\n",
                  eta, th, s.R, s.T, R, 1 - R);
      EXPECT_NEAR(s.R, R, 1e-3) << "eta " << eta << " theta " << th;
      EXPECT_NEAR(s.T, 1 - R, 1e-3) << "eta " << eta << " theta " << th;
    }
}

// Symmetry: f(wi, wo) = f(wo, wi) over the whole sphere (transmission included), and both sides
// alike: f(flipZ wi, flipZ wo) = f(wi, wo); the transmission lobe is the reflection lobe mirrored
// (f(wi, wo) for wi below = the reflection at flipZ(wi) with R -> 1 - R). Random pairs over the
// sphere; tolerance 1e-4 relative (float evaluation in two orders) + 1e-6 absolute.
TEST(RoughThinDielectric, SymmetryAndSides) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  auto randomDir = [&]() {
    double z = 2 * U(rng) - 1, ph = 2 * M_PI * U(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
    return vec3(float(s * std::cos(ph)), float(s * std::sin(ph)), float(z));
  };
  int transmitting = 0;
  for (auto [alpha, eta] : {std::pair{0.2f, 1.5f}, std::pair{0.02f, 2.42f}, std::pair{0.7f, 1.5f}})
    for (int k = 0; k < 20000; ++k) {
      vec3 a = randomDir(), b = randomDir();
      double fab = F(alpha, eta, a, b), fba = F(alpha, eta, b, a), g = F(alpha, eta, flipZ(a), flipZ(b));
      ASSERT_TRUE(std::isfinite(fab) && fab >= 0) << fab;
      EXPECT_NEAR(fab, fba, 1e-4 * std::max(fab, fba) + 1e-6) << "alpha " << alpha << " a.z " << a.z << " b.z " << b.z;
      EXPECT_NEAR(fab, g, 1e-4 * std::max(fab, g) + 1e-6) << "alpha " << alpha << " a.z " << a.z << " b.z " << b.z;
      if (a.z * b.z < 0) {
        // Mirrored: (1 - R) / R times the reflection at flipZ(a), R the sheet's at the half vector.
        vec3 m = flipZ(a);
        double refl = F(alpha, eta, m, b);
        glm::dvec3 h = glm::normalize(glm::dvec3(m) + glm::dvec3(b));
        double R = shared::roughThinSheetReflectance(eta, float(std::abs(glm::dot(h, glm::dvec3(b)))));
        EXPECT_NEAR(fab, refl * (1 - R) / R, 1e-4 * fab + 1e-6);
        if (fab > 0) ++transmitting;
      }
    }
  EXPECT_GT(transmitting, 1000);  // the pairs exercise transmission
}

// The catalogue entry: transmitting, not delta; the same parameters from either side
// (transmissionInsideParams is p), no radiance scaling across (transmissionEtaScale 1); the tint
// is its tint parameter (modelTintParam) and colours transmission only; eval through the dispatch
// equals the scalar formula; zero in the plane of the surface.
TEST(RoughThinDielectric, CatalogueAndDispatch) {
  const ModelSpec* m = findModel("rough_thin_dielectric");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->id, MODEL_ROUGH_THIN_DIELECTRIC);
  EXPECT_TRUE(m->transmits);
  EXPECT_FALSE(m->delta);
  EXPECT_TRUE(shared::modelTransmits(m->id));
  EXPECT_EQ(shared::modelTintParam(m->id), ROUGH_THIN_DIELECTRIC_TINT);
  BrdfParams p = packParams(*m,
                            {{"alpha", ParamValue::num(0.3)}, {"eta", ParamValue::num(1.7)},
                             {"tint", arrayValue({ParamValue::num(0.8), ParamValue::num(0.5), ParamValue::num(0.2)})}},
                            "rough_thin_dielectric");
  BrdfParams q = shared::transmissionInsideParams(m->id, p);
  for (int i = 0; i < 32; ++i) EXPECT_EQ(shared::brdfParam(q, std::uint32_t(i)), shared::brdfParam(p, std::uint32_t(i)));
  EXPECT_EQ(shared::transmissionEtaScale(m->id, p, false), 1.0f);
  EXPECT_EQ(shared::transmissionEtaScale(m->id, p, true), 1.0f);
  const vec3 wo = dirAt(30), below = flipZ(dirAt(20, 180)), above = dirAt(25, 170);
  const vec3 ft = shared::brdfEval(m->id, p, below, wo), fr = shared::brdfEval(m->id, p, above, wo);
  const float t = float(F(0.3f, 1.7f, below, wo)), r = float(F(0.3f, 1.7f, above, wo));
  EXPECT_GT(t, 0.0f);
  EXPECT_GT(r, 0.0f);
  EXPECT_EQ(ft.x, t * 0.8f);
  EXPECT_EQ(ft.y, t * 0.5f);
  EXPECT_EQ(ft.z, t * 0.2f);
  EXPECT_EQ(fr.x, r);
  EXPECT_EQ(fr.z, r);
  EXPECT_EQ(F(0.3f, 1.7f, vec3(1, 0, 0), wo), 0.0);
}

// The generic sampler's two discs: for the typical and hard sets at 0, 30, 60 and 85 degrees the
// upper tree's total is R and the lower tree's T (the quadrature above; 1e-4 relative: the
// builder's integration tolerance), and every lower leaf's envelope bounds f on a 25 x 25 lattice.
TEST(RoughThinDielectric, LowerDiscTreeTotalsAndEnvelopes) {
  const ModelSpec* m = findModel("rough_thin_dielectric");
  for (int hard = 0; hard < 2; ++hard) {
    BrdfParams p = packParams(*m, hard ? hardParams(*m) : typicalParams(*m), "rough_thin_dielectric");
    float alpha = shared::brdfParam(p, ROUGH_THIN_DIELECTRIC_ALPHA), eta = shared::brdfParam(p, ROUGH_THIN_DIELECTRIC_ETA);
    for (double th : {0.0, 30.0, 60.0, 85.0}) {
      vec3 v = dirAt(th);
      quadtree::BuildSettings bs;
      quadtree::Tree up = quadtree::buildTree(m->id, p, v, bs);
      bs.lowerDisc = true;
      quadtree::Tree low = quadtree::buildTree(m->id, p, v, bs);
      const Split s = split(alpha, eta, th, 0.0);
      std::printf("[rough_thin_dielectric trees] %s theta=%2.0f  upper %.6f (R %.6f)  lower %.6f (T %.6f)  leaves %u + %u\n",
                  hard ? "hard   " : "typical", th, up.mass, s.R, low.mass, s.T, up.stats.leaves, low.stats.leaves);
      EXPECT_NEAR(up.mass, s.R, 1e-4 * s.R) << "theta " << th << " hard " << hard;
      EXPECT_NEAR(low.mass, s.T, 1e-4 * s.T) << "theta " << th << " hard " << hard;
      quadtree::EnvelopeAudit a = quadtree::auditEnvelopes(m->id, p, v, low, 24, true);
      EXPECT_EQ(a.leavesAbove, 0u) << "lower disc theta " << th << " hard " << hard << ": worst f / e " << a.worst;
      EXPECT_GT(a.leaves, 0u);
    }
  }
}

// The generic sampler over both discs (QT_SET_TRANSMITS), on the CPU, as
// RoughDielectric.ChiSquareBothDiscs: typical and hard sets at 0, 30, 60, 85 degrees (tables) and
// 37.3 (between tables), 2^20 samples binned over the sphere (qttest::quadChiSquare, expected
// counts from quadPdf) at significance 0.01 with Bonferroni over the 10 cases; the share of samples
// below the surface against a_low / (a_up + a_low) (on tables; |z| < 5); the pdf integrates to 1;
// on tables every weight f |cos| / pdf is a_up + a_low (2e-3); no bound violations or trial
// failures. The same test must reject a broken sampler (the tables' lower masses halved: the
// lower disc drawn half as often while its pdf claims the full share).
TEST(RoughThinDielectric, ChiSquareBothDiscs) {
  const ModelSpec* m = findModel("rough_thin_dielectric");
  const std::uint32_t n = qttest::kSamples;
  const std::vector<double> angles = {0.0, 30.0, 60.0, 85.0, 37.3};
  const double alpha = 0.01 / (2.0 * double(angles.size()));
  int brokenRejected = 0, brokenCases = 0;
  for (int hard = 0; hard < 2; ++hard) {
    BrdfParams p = packParams(*m, hard ? hardParams(*m) : typicalParams(*m), "rough_thin_dielectric");
    std::vector<std::uint32_t> idx;
    quadtree::SamplerTables t = quadtree::buildSamplerTables({{m->id, p}}, qttest::testSettings(), idx);
    ASSERT_EQ(t.sets.size(), 1u);
    ASSERT_NE(t.sets[0].info.w & QT_SET_TRANSMITS, 0u);
    ASSERT_EQ(t.tables.size(), 2u * t.sets[0].info.y * t.sets[0].info.z);
    for (double th : angles) {
      qttest::Case c{"rough_thin_dielectric", hard == 1, th, 0.0};
      vec3 v = qttest::knownDirection(c);
      const std::string label = c.name();
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
      std::printf("[rough_thin_dielectric chi2] %-48s p=%.3g chi2=%.1f dof=%d sum(pdf)=%.5f below %.5f (a_low/a %.5f, "
                  "z=%.2f) weight/a in [%.5f, %.5f]\n",
                  label.c_str(), r.pValue, r.chi2, r.dof, r.expectedTotal, below / ok, share, z, lo, hi);
      EXPECT_NEAR(r.expectedTotal, 1.0, 2e-4) << label;
      EXPECT_GE(r.pValue, alpha) << label << "\n" << r.dump;
      if (onTable) {
        EXPECT_LT(std::abs(z), 5.0) << label;
        EXPECT_NEAR(lo, 1.0, 2e-3) << label;
        EXPECT_NEAR(hi, 1.0, 2e-3) << label;
      }
      if (!onTable || hard) continue;
      quadtree::SamplerTables broken = t;
      for (std::uint32_t j = t.sets[0].info.y; j < broken.tables.size(); ++j) broken.tables[j].data.x *= 0.5f;
      quadtree::SampleBatch bb = quadtree::sampleCpu(broken, 0, m->id, p, v, n, 1234u);
      quadtree::SampleBatch bp = quadtree::sampleCpu(broken, 0, m->id, p, v, qttest::kPilotSamples, 99u);
      qttest::Chi2Result rb = qttest::quadChiSquare(broken, 0, m->id, p, v, bp.wPdf, bb.wPdf);
      std::printf("[rough_thin_dielectric chi2] broken (lower disc probability halved) %s: p=%.3g chi2=%.1f dof=%d\n",
                  label.c_str(), rb.pValue, rb.chi2, rb.dof);
      ++brokenCases;
      if (rb.pValue < alpha) ++brokenRejected;
    }
  }
  EXPECT_EQ(brokenRejected, brokenCases) << "the chi-square test did not reject every broken sampler";
}

}  // namespace
}  // namespace nusselt
