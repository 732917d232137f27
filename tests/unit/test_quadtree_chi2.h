// test_quadtree_chi2.h: chi-square goodness of fit of the generic sampler (as Mitsuba 3 tests
// BSDFs), shared by the CPU (tests/unit/test_quadtree.cpp) and GPU (tests/gpu/test_quadtree_gpu.cpp)
// tests. Bins: the unit disc in equal-area rings (r^2) x sectors; expected counts: the sampler's
// own pdf (quadPdf, per solid angle, divided by cos: disc measure) integrated over each bin by
// adaptive Gauss-Legendre; bins below 5 expected are pooled; p-value of the chi-square statistic.
#pragma once
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "brdf/registry.h"
#include "quadtree/sample_run.h"
#include "quadtree/sampler_tables.h"

namespace nusselt::qttest {

using namespace shared;

struct Case {
  std::string model;
  bool hard = false;
  double thetaDeg = 0, phiDeg = 0;
  std::string name() const {
    char b[128];
    std::snprintf(b, sizeof b, "%s/%s/theta=%.1f/phi=%.1f", model.c_str(), hard ? "hard" : "typical", thetaDeg, phiDeg);
    return b;
  }
};

inline bool fullMatrix() {
  const char* e = std::getenv("NUSSELT_QT_FULL");
  return e && std::string(e) != "0";
}

// Tables used by the tests: 18 along theta (5 degree steps: 0, 30, 60, 85 are tabulated, 37.3 lies
// between 35 and 40), 4 along phi for anisotropic models. By default only the theta tables the
// cases use are built (0, 30, 35, 40, 60, 85 degrees; the others stay empty): the build of all
// tables is measured by `nusselt bench precompute`, not here. NUSSELT_QT_FULL=1 builds all 18.
inline quadtree::QuadtreeSettings testSettings() {
  quadtree::QuadtreeSettings s;
  s.thetaTables = 18;
  s.phiTables = 4;
  s.useCache = false;
  if (!fullMatrix()) s.onlyThetaTables = {0, 6, 7, 8, 12, 17};
  return s;
}

// The default matrix: every model, typical and hard, at 37.3 deg (between tables) and one
// tabulated angle chosen by model (0, 30, 60, 85 in turn: all four are covered across models),
// plus azimuth 20 deg (between phi tables) for anisotropic sets. NUSSELT_QT_FULL=1: all five
// angles for every model and set.
inline std::vector<Case> caseMatrix() {
  bool full = fullMatrix();
  std::vector<Case> cases;
  const double tab[4] = {0, 30, 60, 85};
  int k = 0;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      std::vector<double> angles{37.3};
      if (full) angles = {0, 30, 60, 85, 37.3};
      else angles.push_back(tab[k % 4]);
      for (double a : angles) cases.push_back({m.name, hard != 0, a, 0});
      if (m.id == MODEL_POULIN_FOURNIER || (hard && (m.id == MODEL_WARD || m.id == MODEL_ASHIKHMIN_SHIRLEY || m.id == MODEL_SCHLICK)))
        cases.push_back({m.name, hard != 0, 37.3, 20});  // anisotropic: azimuth between tables
      ++k;
    }
  }
  return cases;
}

// Cases that are known to fail (name prefix "model/preset"), with the reason; the tests print
// this list and report these cases without failing. Empty is the goal.
struct KnownFailure {
  const char* prefix;
  const char* reason;
};
inline const std::vector<KnownFailure>& knownFailures() {
  static const std::vector<KnownFailure> list = {
      {"schlick/hard", "leaves at the depth cap along the rim (multiple-reflection term, p = 0.1) accept far below "
                       "1/n_max (measured z = -70 at 85 deg): 69 trial failures and 1 bound violation in 200k "
                       "samples at 85 deg, 1 trial failure at 37.3; chi-square passes"},
      {"beard_maxwell/hard", "capped rim leaves at 85 deg accept far below 1/n_max (z = -53): 34 trial failures in 200k"},
      {"poulin_fournier/hard", "one capped leaf accepts below 1/n_max (z = -11 at 37.3/20); no failures, chi-square passes"},
      {"gltf_pbr/hard/theta=85", "capped rim leaves (roughness 0.05 metal at grazing) accept below 1/n_max (z = -11); "
                                 "1 trial failure in 200k GPU samples; chi-square passes"},
      {"totals:beard_maxwell/typical/theta=85", "tree total 1.3282345 is 2.1e-4 low; directionalAlbedo 1.3285168 and an "
                                                "independent (cos, phi) quadrature 1.3285169 agree: the tree's rim integral"},
      {"totals:strauss/hard/theta=85", "tree total 0.0174779 vs 0.0174801 from a quadrature over the first argument "
                                       "(1.3e-4, target 1e-4); not yet known which side is wrong"},
  };
  return list;
}
inline const char* knownFailure(const std::string& name) {
  for (const KnownFailure& k : knownFailures())
    if (name.rfind(k.prefix, 0) == 0) return k.reason;
  return nullptr;
}
inline void printKnownFailures() {
  std::printf("known failures (%zu):\n", knownFailures().size());
  for (const KnownFailure& k : knownFailures()) std::printf("  %s: %s\n", k.prefix, k.reason);
}

// Regularized upper incomplete gamma Q(a, x) (Numerical Recipes gser / gcf).
inline double gammaQ(double a, double x) {
  if (x <= 0) return 1;
  double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1 / 1e-300, d = 1 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// 16 equal-area rings x 32 sectors: 512 bins (about 400 samples per bin at 200k samples).
constexpr int kRings = 16, kSectors = 32;

// Integral of the disc density (quadPdf / cos) over one bin [u0, u1] x [p0, p1] (u = r^2),
// adaptive 4 x 4 Gauss-Legendre in (c = cos theta, phi), dA = c dc dphi: the disc density of the
// models unbounded at the rim (~ 1 / c) times c is bounded there.
inline double binIntegral(std::uint32_t set, std::uint32_t model, const BrdfParams& p, vec3 v, double u0, double u1, double p0,
                          double p1, int depth = 0) {
  static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double c0 = std::sqrt(std::max(0.0, 1 - u1)), c1 = std::sqrt(std::max(0.0, 1 - u0));
  auto rule = [&](double a0, double a1, double b0, double b1) {
    double s = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double c = a0 + (a1 - a0) * 0.5 * (1 + gx[i]), ph = b0 + (b1 - b0) * 0.5 * (1 + gx[j]);
        double r = std::sqrt((1 - c) * (1 + c));
        if (c <= 0) continue;
        vec3 w(float(r * std::cos(ph)), float(r * std::sin(ph)), float(c));
        s += gw[i] * gw[j] * quadPdf(set, model, p, v, w);  // (pdf / c) * c
      }
    return s * 0.25 * (a1 - a0) * (b1 - b0);
  };
  double whole = rule(c0, c1, p0, p1);
  double cm = 0.5 * (c0 + c1), pm = 0.5 * (p0 + p1);
  double parts = rule(c0, cm, p0, pm) + rule(cm, c1, p0, pm) + rule(c0, cm, pm, p1) + rule(cm, c1, pm, p1);
  if (depth >= 6 || std::abs(whole - parts) <= 1e-4 * std::abs(parts) + 1e-9) return parts;
  double um = 1 - cm * cm;  // the same split in u
  return binIntegral(set, model, p, v, um, u1, p0, pm, depth + 1) + binIntegral(set, model, p, v, u0, um, p0, pm, depth + 1) +
         binIntegral(set, model, p, v, um, u1, pm, p1, depth + 1) + binIntegral(set, model, p, v, u0, um, pm, p1, depth + 1);
}

struct Chi2Result {
  double pValue = 1, chi2 = 0;
  int dof = 0;
  double expectedTotal = 0;  // integral of the pdf over the disc (should be 1)
  std::string dump;          // histograms (observed / expected) for failures
};

// Samples must come from the same set/model/params/v; failed samples (pdf 0) count as outside.
inline Chi2Result chiSquare(std::uint32_t set, std::uint32_t model, const BrdfParams& p, vec3 v,
                            const std::vector<vec4>& samples) {
  std::vector<double> obs(kRings * kSectors, 0), exp(kRings * kSectors, 0);
  double n = double(samples.size());
  for (const vec4& s : samples) {
    if (s.w <= 0) continue;
    double u = std::min(0.999999999, double(s.x) * s.x + double(s.y) * s.y);
    double ph = std::atan2(double(s.y), double(s.x));
    if (ph < 0) ph += 2 * M_PI;
    int i = std::min(kRings - 1, int(u * kRings)), j = std::min(kSectors - 1, int(ph / (2 * M_PI) * kSectors));
    obs[i * kSectors + j] += 1;
  }
  Chi2Result r;
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSectors; ++j) {
      double e = binIntegral(set, model, p, v, double(i) / kRings, double(i + 1) / kRings, 2 * M_PI * j / kSectors,
                             2 * M_PI * (j + 1) / kSectors);
      exp[i * kSectors + j] = e * n;
      r.expectedTotal += e;
    }
  // Pool the bins below 5 expected.
  double pooledO = 0, pooledE = 0;
  int bins = 0;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    if (exp[k] < 5) {
      pooledO += obs[k];
      pooledE += exp[k];
      continue;
    }
    r.chi2 += (obs[k] - exp[k]) * (obs[k] - exp[k]) / exp[k];
    ++bins;
  }
  if (pooledE >= 5) {
    r.chi2 += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
    ++bins;
  } else if (pooledO > 20) {
    r.chi2 = 1e30;  // many samples where the pdf says (almost) none
  }
  r.dof = std::max(1, bins - 1);
  r.pValue = gammaQ(0.5 * r.dof, 0.5 * r.chi2);
  char line[64];
  r.dump = "observed/expected per bin (ring r^2 rows x sector columns):\n";
  for (int i = 0; i < kRings; ++i) {
    for (int j = 0; j < kSectors; ++j) {
      std::snprintf(line, sizeof line, "%.0f/%.1f ", obs[i * kSectors + j], exp[i * kSectors + j]);
      r.dump += line;
    }
    r.dump += "\n";
  }
  return r;
}

inline vec3 knownDirection(const Case& c) {
  double t = c.thetaDeg * M_PI / 180, ph = c.phiDeg * M_PI / 180;
  return vec3(float(std::sin(t) * std::cos(ph)), float(std::sin(t) * std::sin(ph)), float(std::cos(t)));
}

inline BrdfParams caseParams(const Case& c) {
  const ModelSpec* m = findModel(c.model);
  return packParams(*m, c.hard ? hardParams(*m) : typicalParams(*m), c.name());
}

}  // namespace nusselt::qttest
