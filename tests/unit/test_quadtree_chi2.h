// test_quadtree_chi2.h: chi-square goodness of fit of sampled directions against a pdf (as
// Mitsuba 3 tests its BSDFs), shared by the quadtree tests (tests/gpu/test_quadtree_gpu.cpp, CPU
// and GPU samples; tests/unit/test_quadtree.cpp) and the other strategies' (tests/unit/test_strategies.cpp).
//
// Bins: rings in c = cos theta times sectors in phi. Either fixed (equal-area rings, equal sectors)
// or equal-probability bins from an independent pilot sample (quantiles of c, then of phi within
// each ring): the bins follow the lobe, however narrow or grazing, so that the test keeps its
// power there; the partition does not depend on the tested samples, and the expected counts come
// from the pdf alone (adaptive Gauss-Legendre over each bin), so a wrong sampler is still caught.
// Failed samples (pdf 0) form one more bin whose probability is 1 - sum of the others; bins below
// 5 expected are pooled; the p-value is that of the chi-square statistic.
#pragma once
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "brdf/registry.h"
#include "quadtree/quadtree_build.h"
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

// The quadtree suite's tables: the production grid (90 theta tables, 16 phi tables), of which only
// those the cases use are built (0, 30, 37, 38, 60, 85 degrees and their phi tables; 37.3 lies
// between 37 and 38); the build of all of them is measured by `nusselt bench precompute`.
inline quadtree::QuadtreeSettings testSettings() {
  quadtree::QuadtreeSettings s;
  s.useCache = false;
  s.onlyThetaTables = {0, 30, 37, 38, 60, 85};
  return s;
}

// Every non-delta model, typical and hard, at 0, 30, 60, 85 degrees (tables) and 37.3 (between
// tables), plus azimuth 20 degrees (between phi tables) at 37.3 and 60 for the anisotropic sets.
inline std::vector<Case> caseMatrix() {
  std::vector<Case> cases;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    for (int hard = 0; hard < 2; ++hard) {
      for (double a : {0.0, 30.0, 60.0, 85.0, 37.3}) cases.push_back({m.name, hard != 0, a, 0});
      BrdfParams p = packParams(m, hard ? hardParams(m) : typicalParams(m), m.name);
      if (quadtree::modelTraits(m.id, p).anisotropic)
        for (double a : {37.3, 60.0}) cases.push_back({m.name, hard != 0, a, 20});
    }
  }
  return cases;
}

// Samples per case (about a million, as Mitsuba's tests) and per pilot run (the bins).
constexpr std::uint32_t kSamples = 1u << 20;
constexpr std::uint32_t kPilotSamples = 1u << 15;

// Bonferroni: significance 0.01 over every chi-square case of the quadtree suite, CPU and GPU.
inline double suiteAlpha() { return 0.01 / (2.0 * double(caseMatrix().size())); }

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

// Rings [c[i], c[i+1]] (ascending, c[0] = 0, c.back() = 1) times sectors [phi[i][j], phi[i][j+1]]
// covering [phi[i][0], phi[i][0] + 2 pi). A sphere binning (transmitting models: samples on both
// sides) has c[0] = -1 and an edge at c = 0.
struct Binning {
  std::vector<double> c;
  std::vector<std::vector<double>> phi;
  std::size_t size() const {
    std::size_t n = 0;
    for (const auto& p : phi) n += p.size() - 1;
    return n;
  }
  // Bin of direction w (upper hemisphere; the sphere for a sphere binning), rings first.
  std::size_t bin(vec3 w) const {
    double cz = std::clamp(double(w.z), c.front(), 1.0);
    std::size_t i = std::min<std::size_t>(c.size() - 2, std::size_t(std::upper_bound(c.begin(), c.end(), cz) - c.begin()) - 1);
    const std::vector<double>& e = phi[i];
    double ph = std::atan2(double(w.y), double(w.x));
    while (ph < e.front()) ph += 2 * M_PI;
    while (ph >= e.front() + 2 * M_PI) ph -= 2 * M_PI;
    std::size_t j = std::min<std::size_t>(e.size() - 2, std::size_t(std::upper_bound(e.begin(), e.end(), ph) - e.begin()) - 1);
    std::size_t base = 0;
    for (std::size_t k = 0; k < i; ++k) base += phi[k].size() - 1;
    return base + j;
  }
};

// Equal-area rings (in r^2) and equal sectors from phi = 0.
inline Binning uniformBinning(int rings, int sectors) {
  Binning b;
  for (int i = 0; i <= rings; ++i) b.c.push_back(std::sqrt(double(i) / rings));  // c^2 = 1 - r^2: equal steps
  b.c.front() = 0;
  b.c.back() = 1;
  for (int i = 0; i < rings; ++i) {
    std::vector<double> e;
    for (int j = 0; j <= sectors; ++j) e.push_back(2 * M_PI * j / sectors);
    b.phi.push_back(e);
  }
  return b;
}

// Equal-probability bins of an independent pilot sample (pdf 0 = failed, ignored). sphere: rings
// over c in [-1, 1] (transmitting models), the quantile edge nearest to c = 0 moved there, so that
// no bin straddles the surface.
inline Binning quantileBinning(const std::vector<vec4>& pilot, int rings, int sectors, bool sphere = false) {
  const double lo = sphere ? -1.0 : 0.0;
  std::vector<std::pair<double, double>> pts;  // (c, phi)
  for (const vec4& s : pilot)
    if (s.w > 0) pts.push_back({std::clamp(double(s.z), lo, 1.0), std::atan2(double(s.y), double(s.x))});
  if (pts.size() < std::size_t(rings * sectors * 4)) {
    Binning u = uniformBinning(rings, sectors);
    if (sphere) {  // the same rings mirrored below
      Binning b;
      for (std::size_t i = u.c.size(); i-- > 1;) b.c.push_back(-u.c[i]);
      b.c.insert(b.c.end(), u.c.begin(), u.c.end());
      b.phi = u.phi;
      b.phi.insert(b.phi.end(), u.phi.begin(), u.phi.end());
      return b;
    }
    return u;
  }
  std::sort(pts.begin(), pts.end());
  Binning b;
  b.c.push_back(lo);
  std::size_t n = pts.size();
  for (int i = 1; i < rings; ++i) b.c.push_back(pts[i * n / rings].first);
  b.c.push_back(1);
  if (sphere) {
    std::size_t k = 1;
    for (std::size_t i = 1; i + 1 < b.c.size(); ++i)
      if (std::abs(b.c[i]) < std::abs(b.c[k])) k = i;
    b.c[k] = 0;
  }
  for (int i = 0; i < rings; ++i) {
    std::vector<double> ph;
    if (!sphere) {
      for (std::size_t k = i * n / rings; k < (i + 1) * n / rings; ++k) ph.push_back(pts[k].second);
    } else {
      for (std::size_t k = 0; k < n; ++k)  // the points of ring [c[i], c[i+1]) (the edge at 0 moved)
        if (pts[k].first >= b.c[i] && (pts[k].first < b.c[i + 1] || i + 1 == std::size_t(rings))) ph.push_back(pts[k].second);
    }
    if (ph.size() < std::size_t(sectors)) {  // (sphere: a ring the moved edge emptied) equal sectors
      std::vector<double> e;
      for (int j = 0; j <= sectors; ++j) e.push_back(-M_PI + 2 * M_PI * j / sectors);
      b.phi.push_back(e);
      continue;
    }
    std::sort(ph.begin(), ph.end());
    std::vector<double> e{-M_PI};
    for (int j = 1; j < sectors; ++j) e.push_back(ph[j * ph.size() / sectors]);
    e.push_back(M_PI);
    // Equal quantiles can coincide only for an atom (none here); keep the edges strictly ascending.
    for (std::size_t j = 1; j < e.size(); ++j) e[j] = std::max(e[j], std::nextafter(e[j - 1], 10.0));
    b.phi.push_back(e);
  }
  // Strictly ascending rings too.
  for (std::size_t i = 1; i < b.c.size(); ++i) b.c[i] = std::max(b.c[i], std::nextafter(b.c[i - 1], 10.0));
  if (sphere) b.c.front() = -1.0;
  b.c.back() = std::max(1.0, b.c.back());
  return b;
}

using PdfFn = std::function<double(vec3)>;  // solid-angle pdf of a direction above the surface

// Integral of the solid-angle pdf over [c0, c1] x [p0, p1] (d omega = dc dphi): adaptive 4 x 4
// Gauss-Legendre (at least two levels, then until two levels agree to 1e-4 relative or 1e-10
// absolute). `guide` holds the (c, phi) of the pilot samples inside the cell, which steer the
// quadrature to where the mass is: a cell is halved along each axis in which its points span less
// than a quarter of it (the lobe of a hard set can be 1e-5 wide in c inside a bin that spans the
// whole hemisphere, invisible to the rules of the bin), and split 2 x 2 while it holds more than
// 32 of them. The pieces without points are then at least as far from the points as they are
// wide, and the error-driven rule resolves what tail they hold. A lobe the pilot missed shows up
// as well: either the quadrature finds it (expected counts where no sample falls) or the bin sums
// stay below 1 (the tests check that they add up to 1).
using Guide = std::vector<std::pair<float, float>>;
inline vec3 binDirection(double c, double ph) {
  double r = std::sqrt((1 - c) * (1 + c));
  return vec3(float(r * std::cos(ph)), float(r * std::sin(ph)), float(c));
}
// 4 x 4 Gauss-Legendre over [a0, a1] x [b0, b1]; *fmax (optional) gets the largest value seen.
inline double binRule(const PdfFn& pdf, double a0, double a1, double b0, double b1, double* fmax = nullptr) {
  static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double s = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double c = a0 + (a1 - a0) * 0.5 * (1 + gx[i]), ph = b0 + (b1 - b0) * 0.5 * (1 + gx[j]);
      if (c == 0) continue;  // (the Gauss points never reach c = 0: interior nodes of rings that end there)
      double f = pdf(binDirection(c, ph));
      if (fmax) *fmax = std::max(*fmax, f);
      s += gw[i] * gw[j] * f;
    }
  return s * 0.25 * (a1 - a0) * (b1 - b0);
}
// Integral of the solid-angle pdf over [c0, c1] x [p0, p1] (d omega = dc dphi): adaptive 4 x 4
// Gauss-Legendre. A cell is accepted when its rule and its four children's agree (1e-4 relative
// or 1e-10 absolute) from the second level on, and when no point of its boundary (corners, edge
// midpoints) is more than 4x above every Gauss point of its children: a lobe's tail that enters
// the cell through an edge is invisible to the interior nodes, and two rules can agree on missing
// it. `guide` holds the (c, phi) of the pilot samples inside the cell, which steer the quadrature
// to where the mass is: a cell is halved along each axis in which its points span less than a
// quarter of it (the lobe of a hard set can be 1e-5 wide in c inside a bin that spans the whole
// hemisphere), and split 2 x 2 otherwise, while it holds more than 16 of them. A lobe the pilot missed shows
// up as well: either the quadrature finds it (expected counts where no sample falls) or the bin
// sums stay below 1 (the tests check that they add up to 1).
inline double binIntegral(const PdfFn& pdf, double c0, double c1, double p0, double p1, const Guide& guide, int depth = 0,
                          double whole = -1) {
  if (whole < 0) whole = binRule(pdf, c0, c1, p0, p1);
  double cm = 0.5 * (c0 + c1), pm = 0.5 * (p0 + p1);
  bool sc = false, sp = false;
  if (guide.size() > 16) {
    float lc = 2, hc = -1, lp = 10, hp = -10;
    for (const auto& pt : guide) {
      lc = std::min(lc, pt.first); hc = std::max(hc, pt.first);
      lp = std::min(lp, pt.second); hp = std::max(hp, pt.second);
    }
    sc = hc - lc < 0.25 * (c1 - c0);
    sp = hp - lp < 0.25 * (p1 - p0);
    if (!sc && !sp) sc = sp = true;
  }
  if (depth >= 40) return whole;
  double q[4] = {-1, -1, -1, -1};  // the 2 x 2 children's rules when computed
  if (!sc && !sp) {
    double qmax = 0;
    q[0] = binRule(pdf, c0, cm, p0, pm, &qmax); q[1] = binRule(pdf, cm, c1, p0, pm, &qmax);
    q[2] = binRule(pdf, c0, cm, pm, p1, &qmax); q[3] = binRule(pdf, cm, c1, pm, p1, &qmax);
    double parts = q[0] + q[1] + q[2] + q[3];
    bool agree = std::abs(whole - parts) <= 1e-4 * std::abs(parts) + 1e-10;
    if (depth >= 24) return parts;
    if (depth >= 2 && agree) {
      double bmax = 0;
      for (double c : {c0, cm, c1})
        for (double ph : {p0, pm, p1})
          if (c != 0 && (c != cm || ph != pm)) bmax = std::max(bmax, pdf(binDirection(c, ph)));
      if (bmax <= 4 * qmax || bmax * (c1 - c0) * (p1 - p0) < 1e-12) return parts;
    }
    sc = sp = true;
  }
  // Children (halved along the chosen axes) with their points.
  double ca[2] = {c0, sc ? cm : c1}, cb[2] = {sc ? cm : c1, c1}, pa[2] = {p0, sp ? pm : p1}, pb[2] = {sp ? pm : p1, p1};
  int nc = sc ? 2 : 1, np = sp ? 2 : 1;
  Guide g[4];
  for (const auto& pt : guide) g[(sc && pt.first >= cm ? 1 : 0) + (sp && pt.second >= pm ? 2 : 0)].push_back(pt);
  double sum = 0;
  for (int i = 0; i < nc; ++i)
    for (int j = 0; j < np; ++j)
      sum += binIntegral(pdf, ca[i], cb[i], pa[j], pb[j], g[i + 2 * j], depth + 1, (sc && sp) ? q[i + 2 * j] : -1);
  return sum;
}

// Probabilities of the bins; `guide` (optional): pilot samples that steer the quadrature. Two
// threads; `threadContext` (optional) is called on each and holds what the pdf needs there (the
// quadtree's QuadHostScope) for as long as the thread runs.
using ThreadContext = std::function<std::shared_ptr<void>()>;
inline std::vector<double> binProbabilities(const PdfFn& pdf, const Binning& b, const std::vector<vec4>& guide = {},
                                            const ThreadContext& threadContext = {}) {
  std::vector<Guide> perBin(b.size());
  for (const vec4& s : guide) {
    if (s.w <= 0) continue;
    std::size_t k = b.bin(vec3(s));
    std::size_t i = 0, base = 0;
    while (base + b.phi[i].size() - 1 <= k) base += b.phi[i++].size() - 1;
    double ph = std::atan2(double(s.y), double(s.x));
    while (ph < b.phi[i].front()) ph += 2 * M_PI;
    while (ph >= b.phi[i].front() + 2 * M_PI) ph -= 2 * M_PI;
    perBin[k].push_back({s.z, float(ph)});
  }
  struct Cell { double c0, c1, p0, p1; };
  std::vector<Cell> cells;
  for (std::size_t i = 0; i + 1 < b.c.size(); ++i)
    for (std::size_t j = 0; j + 1 < b.phi[i].size(); ++j) cells.push_back({b.c[i], b.c[i + 1], b.phi[i][j], b.phi[i][j + 1]});
  std::vector<double> e(cells.size());
  std::atomic<std::size_t> next{0};
  auto work = [&]() {
    std::shared_ptr<void> ctx = threadContext ? threadContext() : nullptr;
    for (std::size_t k; (k = next.fetch_add(1)) < cells.size();)
      e[k] = binIntegral(pdf, cells[k].c0, cells[k].c1, cells[k].p0, cells[k].p1, perBin[k]);
  };
  std::thread helper(work);
  work();
  helper.join();
  return e;
}

struct Chi2Result {
  double pValue = 1, chi2 = 0;
  int dof = 0;
  double expectedTotal = 0;  // integral of the pdf over the hemisphere (1, or 1 - failure rate)
  double failedObserved = 0;
  std::string dump;          // observed / expected per bin, for failures
};

// Samples (direction, pdf; pdf 0 = failed) against the bin probabilities `prob` of `bins`.
inline Chi2Result chiSquare(const Binning& bins, const std::vector<double>& prob, const std::vector<vec4>& samples) {
  const std::size_t nb = bins.size();
  std::vector<double> obs(nb + 1, 0), exp(nb + 1, 0);
  double n = double(samples.size());
  Chi2Result r;
  for (const vec4& s : samples) {
    if (s.w <= 0) { obs[nb] += 1; continue; }
    obs[bins.bin(vec3(s))] += 1;
  }
  for (std::size_t k = 0; k < nb; ++k) {
    exp[k] = prob[k] * n;
    r.expectedTotal += prob[k];
  }
  exp[nb] = std::max(0.0, 1 - r.expectedTotal) * n;
  r.failedObserved = obs[nb];
  double pooledO = 0, pooledE = 0;
  int used = 0;
  for (std::size_t k = 0; k <= nb; ++k) {
    if (exp[k] < 5) { pooledO += obs[k]; pooledE += exp[k]; continue; }
    r.chi2 += (obs[k] - exp[k]) * (obs[k] - exp[k]) / exp[k];
    ++used;
  }
  if (pooledE >= 5) {
    r.chi2 += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
    ++used;
  } else if (pooledO > 20) {
    r.chi2 = 1e30;  // many samples where the pdf says (almost) none
  }
  r.dof = std::max(1, used - 1);
  r.pValue = gammaQ(0.5 * r.dof, 0.5 * r.chi2);
  char line[96];
  r.dump = "observed/expected per bin (rings in cos theta: edges, then sectors):\n";
  std::size_t k = 0;
  for (std::size_t i = 0; i + 1 < bins.c.size(); ++i) {
    std::snprintf(line, sizeof line, "[%.5f, %.5f]: ", bins.c[i], bins.c[i + 1]);
    r.dump += line;
    for (std::size_t j = 0; j + 1 < bins.phi[i].size(); ++j, ++k) {
      std::snprintf(line, sizeof line, "%.0f/%.1f ", obs[k], exp[k]);
      r.dump += line;
    }
    r.dump += "\n";
  }
  std::snprintf(line, sizeof line, "failed %.0f/%.1f\n", obs[nb], exp[nb]);
  r.dump += line;
  return r;
}

// The quadtree sampler's bins for one case: pilot bins from `pilot`, their probabilities from
// quadPdf (the quadrature), for as many sample batches of the case as are tested
// (QuadtreeGpu.ChiSquareCpuGpuAndParity tests the CPU's and the GPU's against one set).
// Transmitting models: bins over the sphere (both discs, each with its share of the samples).
struct QuadBins {
  Binning bins;
  std::vector<double> prob;
};
inline QuadBins quadBins(const quadtree::SamplerTables& t, std::uint32_t set, std::uint32_t model, const BrdfParams& p, vec3 v,
                         const std::vector<vec4>& pilot) {
  QuadBins b;
  b.bins = quantileBinning(pilot, 16, 32, modelById(model).transmits);
  b.prob = binProbabilities([&](vec3 w) { return double(quadPdf(set, model, p, v, w)); }, b.bins, pilot,
                            [&]() { return std::make_shared<quadtree::QuadHostScope>(t); });
  return b;
}
inline Chi2Result quadChiSquare(const QuadBins& b, const std::vector<vec4>& samples) { return chiSquare(b.bins, b.prob, samples); }
// The same for one batch of samples.
inline Chi2Result quadChiSquare(const quadtree::SamplerTables& t, std::uint32_t set, std::uint32_t model, const BrdfParams& p,
                                vec3 v, const std::vector<vec4>& pilot, const std::vector<vec4>& samples) {
  return quadChiSquare(quadBins(t, set, model, p, v, pilot), samples);
}

// Sampler tables of one material at a time (testSettings), built on first use: the case
// matrices come grouped by material, so each is built once and only one is held.
class TableCache {
 public:
  const quadtree::SamplerTables& get(const std::string& key, std::uint32_t model, const BrdfParams& p) {
    if (!m_built || key != m_key) {
      std::vector<std::uint32_t> idx;
      m_tables = quadtree::buildSamplerTables({{model, p}}, testSettings(), idx);
      m_key = key;
      m_built = true;
    }
    return m_tables;
  }

 private:
  std::string m_key;
  bool m_built = false;
  quadtree::SamplerTables m_tables;
};

// Parity of the GPU sampler with the CPU one: how many of the first n samples both drew alike
// from the same random numbers (direction within 1e-4, pdf within 1e-3 relative); float
// differences of the two compilers can flip an acceptance, a small fraction.
inline int sameSamples(const quadtree::SampleBatch& gpu, const quadtree::SampleBatch& cpu, int n) {
  int same = 0;
  for (int i = 0; i < n; ++i) {
    vec3 a(gpu.wPdf[std::size_t(i)]), b(cpu.wPdf[std::size_t(i)]);
    if (length(a - b) < 1e-4f && std::abs(gpu.wPdf[std::size_t(i)].w - cpu.wPdf[std::size_t(i)].w) <= 1e-3f * cpu.wPdf[std::size_t(i)].w + 1e-6f)
      ++same;
  }
  return same;
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
