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

// Tables used by the tests: 18 along theta (5 degree steps: 0, 30, 60, 85 tabulated, 37.3 between
// 35 and 40) to keep the suite within minutes; 4 along phi for anisotropic models.
inline quadtree::QuadtreeSettings testSettings() {
  quadtree::QuadtreeSettings s;
  s.thetaTables = 18;
  s.phiTables = 4;
  s.useCache = false;
  return s;
}

// The default matrix: every model, typical and hard, at 37.3 deg and two tabulated angles chosen
// by model (all of 0, 30, 60, 85 are covered across models); NUSSELT_QT_FULL=1: all five angles.
inline std::vector<Case> caseMatrix() {
  bool full = std::getenv("NUSSELT_QT_FULL") && std::string(std::getenv("NUSSELT_QT_FULL")) != "0";
  std::vector<Case> cases;
  const double tab[4] = {0, 30, 60, 85};
  int k = 0;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      std::vector<double> angles{37.3};
      if (full) angles = {0, 30, 60, 85, 37.3};
      else { angles.push_back(tab[k % 4]); angles.push_back(tab[(k + 2) % 4]); }
      for (double a : angles) cases.push_back({m.name, hard != 0, a, 0});
      if (m.id == MODEL_POULIN_FOURNIER || (hard && (m.id == MODEL_WARD || m.id == MODEL_ASHIKHMIN_SHIRLEY || m.id == MODEL_SCHLICK)))
        cases.push_back({m.name, hard != 0, 37.3, 20});  // anisotropic: azimuth between tables
      ++k;
    }
  }
  return cases;
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

constexpr int kRings = 32, kSectors = 64;

// Integral of the disc density (quadPdf / cos) over one bin, adaptive in (r^2, phi).
inline double binIntegral(std::uint32_t set, std::uint32_t model, const BrdfParams& p, vec3 v, double u0, double u1, double p0,
                          double p1, int depth = 0) {
  static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  auto rule = [&](double a0, double a1, double b0, double b1) {
    double s = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double u = a0 + (a1 - a0) * 0.5 * (1 + gx[i]), ph = b0 + (b1 - b0) * 0.5 * (1 + gx[j]);
        double r = std::sqrt(u), co = std::sqrt(std::max(0.0, 1 - u));
        if (co <= 0) continue;
        vec3 w(float(r * std::cos(ph)), float(r * std::sin(ph)), float(co));
        double pdf = quadPdf(set, model, p, v, w) / co;  // disc density
        s += gw[i] * gw[j] * pdf;
      }
    return s * 0.25 * (a1 - a0) * (b1 - b0) * 0.5;  // dA = d(r^2) dphi / 2
  };
  double whole = rule(u0, u1, p0, p1);
  double um = 0.5 * (u0 + u1), pm = 0.5 * (p0 + p1);
  double parts = rule(u0, um, p0, pm) + rule(um, u1, p0, pm) + rule(u0, um, pm, p1) + rule(um, u1, pm, p1);
  if (depth >= 7 || std::abs(whole - parts) <= 1e-4 * std::abs(parts) + 1e-9) return parts;
  return binIntegral(set, model, p, v, u0, um, p0, pm, depth + 1) + binIntegral(set, model, p, v, um, u1, p0, pm, depth + 1) +
         binIntegral(set, model, p, v, u0, um, pm, p1, depth + 1) + binIntegral(set, model, p, v, um, u1, pm, p1, depth + 1);
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
