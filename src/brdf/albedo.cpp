// albedo.cpp: nested adaptive Gauss-Kronrod quadrature of BRDFs over the hemisphere.
#include "brdf/albedo.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <queue>
#include <vector>

#include "../../shaders/shared/brdf/dispatch.h"

namespace nusselt {
namespace {

using shared::BrdfParams;
using shared::vec3;

// Gauss-Kronrod 7-15 nodes and weights (QUADPACK qk15).
const double kXgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                        0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                        0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                        0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
const double kWgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                        0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                        0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                        0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
const double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                       0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Piece {
  double a, b, value, error;
  bool operator<(const Piece& o) const { return error < o.error; }
};

template <class F>
Piece gk15(const F& f, double a, double b) {
  double c = 0.5 * (a + b), h = 0.5 * (b - a);
  double fc = f(c);
  double resK = fc * kWgk[7], resG = fc * kWg[3];
  for (int j = 0; j < 7; ++j) {
    double x = h * kXgk[j];
    double f1 = f(c - x), f2 = f(c + x);
    resK += kWgk[j] * (f1 + f2);
    if (j % 2 == 1) resG += kWg[j / 2] * (f1 + f2);
  }
  return {a, b, resK * h, std::abs((resK - resG) * h)};
}

// Global adaptive quadrature over the given breakpoints: bisect the piece with the largest
// error estimate until the total error is below max(relTol |I|, absTol) or maxPieces is reached.
template <class F>
double adaptive(const F& f, const std::vector<double>& breaks, double relTol, double absTol, int maxPieces) {
  std::priority_queue<Piece> q;
  double total = 0, err = 0;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    if (!(breaks[i + 1] > breaks[i])) continue;
    Piece p = gk15(f, breaks[i], breaks[i + 1]);
    total += p.value;
    err += p.error;
    q.push(p);
  }
  int pieces = static_cast<int>(q.size());
  while (!q.empty() && err > std::max(relTol * std::abs(total), absTol) && pieces < maxPieces) {
    Piece p = q.top();
    q.pop();
    double m = 0.5 * (p.a + p.b);
    if (!(m > p.a && m < p.b)) break;
    Piece l = gk15(f, p.a, m), r = gk15(f, m, p.b);
    total += l.value + r.value - p.value;
    err += l.error + r.error - p.error;
    q.push(l);
    q.push(r);
    ++pieces;
  }
  return total;
}

// Breakpoints in [lo, hi] graded towards the peak x0 (geometric offsets 1e-5 ... 0.3).
std::vector<double> gradedBreaks(double lo, double hi, double x0) {
  std::vector<double> b = {lo, hi};
  if (x0 >= lo && x0 <= hi) b.push_back(x0);
  for (double d = 1e-5; d < hi - lo; d *= 6.0) {
    if (x0 - d > lo) b.push_back(x0 - d);
    if (x0 + d < hi) b.push_back(x0 + d);
  }
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  return b;
}

// Integrates g(wo) * cos(theta_o) over the hemisphere; g is a function of a float wo.
// Variables: s in [0, 1] with cos(theta_o) = s^2 (dw = 2 s ds dphi), phi in [phiM - pi, phiM + pi].
template <class G>
double hemisphere(const G& g, double thetaI, double phiI, AlbedoMethod method, double relTol) {
  const double pi = M_PI;
  const double phiM = phiI + pi;             // mirror azimuth
  // u = cos(theta_o) = sin^2(pi t / 2): u ~ t^2 at the rim (absorbs 1/sqrt(u) and 1/u factors
  // times the cosine) and theta_o ~ (1 - t) at the pole (regular there; sqrt(u) was not).
  const double tM = 2.0 / pi * std::asin(std::sqrt(std::cos(thetaI)));  // mirror direction's t
  auto integrand = [&](double t, double phi) {
    double sn = std::sin(0.5 * pi * t), cs = std::cos(0.5 * pi * t);
    double u = sn * sn;
    double st = cs * std::sqrt(1.0 + u);  // sin(theta_o) = sqrt((1 - u)(1 + u)), 1 - u = cs^2
    vec3 wo(static_cast<float>(st * std::cos(phi)), static_cast<float>(st * std::sin(phi)), static_cast<float>(u));
    if (!(wo.z > 0.0f)) return 0.0;
    return g(wo) * u * pi * sn * cs;  // du/dt = pi sin cos
  };
  std::vector<double> sBreaks = gradedBreaks(0.0, 1.0, tM);
  for (double d = 1e-4; d < 0.5; d *= 8.0) sBreaks.push_back(1.0 - d);  // the pole
  std::sort(sBreaks.begin(), sBreaks.end());
  sBreaks.erase(std::unique(sBreaks.begin(), sBreaks.end()), sBreaks.end());
  std::vector<double> pBreaks = gradedBreaks(phiM - pi, phiM + pi, phiM);
  // Also graded towards the axes: anisotropic lobes (ward, ashikhmin_shirley, schlick p < 1) are
  // sheets along the x-z or y-z plane, peaked at those azimuths on both sides.
  for (int k = -4; k <= 4; ++k) {
    double a = k * 0.5 * pi;
    if (a <= phiM - pi || a >= phiM + pi) continue;
    pBreaks.push_back(a);
    for (double d = 1e-3; d < 0.5; d *= 16.0) {
      if (a - d > phiM - pi) pBreaks.push_back(a - d);
      if (a + d < phiM + pi) pBreaks.push_back(a + d);
    }
  }
  std::sort(pBreaks.begin(), pBreaks.end());
  pBreaks.erase(std::unique(pBreaks.begin(), pBreaks.end()), pBreaks.end());
  // Float evaluation noise is ~1e-7 relative: no tolerance below that. The inner integrals get an
  // absolute tolerance relative to the whole (a coarse first pass gives its scale).
  // The inner integrals are capped at fewer pieces than the outer one: a model whose float
  // evaluation is not smooth at the 1e-7 level (poulin_fournier's panel quadrature) would
  // otherwise spend its time refining noise.
  auto nested = [&](double outerRel, double innerRel, double innerAbs, int outerMax, int innerMax) {
    if (method == AlbedoMethod::ThetaOuter) {
      auto outer = [&](double s) {
        return adaptive([&](double phi) { return integrand(s, phi); }, pBreaks, innerRel, innerAbs, innerMax);
      };
      return adaptive(outer, sBreaks, outerRel, innerAbs, outerMax);
    }
    auto outer = [&](double phi) {
      return adaptive([&](double s) { return integrand(s, phi); }, sBreaks, innerRel, innerAbs, innerMax);
    };
    return adaptive(outer, pBreaks, outerRel, innerAbs, outerMax);
  };
  double coarse = std::abs(nested(1e-3, 1e-4, 0.0, 60, 60));
  if (coarse == 0.0) return 0.0;
  return nested(relTol, 2e-7, 0.1 * relTol * coarse, 300, 100);
}

vec3 incident(double thetaDeg, double phiDeg) {
  double t = thetaDeg * M_PI / 180.0, p = phiDeg * M_PI / 180.0;
  return vec3(static_cast<float>(std::sin(t) * std::cos(p)), static_cast<float>(std::sin(t) * std::sin(p)),
              static_cast<float>(std::cos(t)));
}

constexpr double kRelTol = 1e-6;

// The specular albedo of coupled, a_s = f0 A1 + A2, at incidence cosine ci, integrated over the
// half vector: f_s co dw_o = F D co / cb dw_h, and D ch dw_h = dv dphi / (2 pi) with
// tan^2(theta_h) = -m^2 ln(1 - v). The integrand F co / (cb ch) [co > 0] is bounded (<= 2 F) and
// smooth but for the kink where wo crosses the horizon; symmetric in phi (wi in the x-z plane).
void coupledSpecularAlbedo(double m, double ci, double& A1, double& A2) {
  const double si = std::sqrt(std::max(0.0, 1.0 - ci * ci));
  double sums[2];
  for (int which = 0; which < 2; ++which) {
    auto integrand = [&](double v, double phi) {
      double tan2 = -m * m * std::log1p(-v);
      double ch = 1.0 / std::sqrt(1.0 + tan2), sh = std::sqrt(tan2) * ch;
      double hx = sh * std::cos(phi), hz = ch;
      double cb = si * hx + ci * hz;
      if (cb <= 0.0) return 0.0;
      double co = 2.0 * cb * hz - ci;
      if (co <= 0.0) return 0.0;
      double w = std::pow(1.0 - cb, 5.0);
      double F = which == 0 ? 1.0 - w : w;  // A1: f0 (1 - w); A2: w
      return F * co / (cb * ch);
    };
    std::vector<double> vBreaks = {0.0, 0.5, 0.9, 0.99, 0.999, 0.9999, 1.0};
    std::vector<double> pBreaks = {0.0, 0.5 * M_PI, 0.9 * M_PI, 0.99 * M_PI, M_PI};
    auto inner = [&](double v) {
      return adaptive([&](double phi) { return integrand(v, phi); }, pBreaks, 1e-8, 1e-10, 200);
    };
    sums[which] = adaptive(inner, vBreaks, 1e-7, 1e-10, 200) / M_PI;  // 2 * int_0^pi / (2 pi)
  }
  A1 = sums[0];
  A2 = sums[1];
}

}  // namespace

double directionalAlbedo(std::uint32_t model, const BrdfParams& params, double thetaDeg) {
  return directionalAlbedo(model, params, thetaDeg, 0.0);
}

double directionalAlbedo(std::uint32_t model, const BrdfParams& params, double thetaDeg, double phiDeg,
                         AlbedoMethod method) {
  if (shared::modelIsDelta(model)) return 0.0;
  vec3 wi = incident(thetaDeg, phiDeg);
  auto g = [&](vec3 wo) { return static_cast<double>(shared::luminance(shared::brdfEval(model, params, wi, wo))); };
  return hemisphere(g, thetaDeg * M_PI / 180.0, phiDeg * M_PI / 180.0, method, kRelTol);
}

double hemisphereIntegral(const std::function<double(vec3)>& g, double thetaDeg, double phiDeg, double relTol) {
  return hemisphere(g, thetaDeg * M_PI / 180.0, phiDeg * M_PI / 180.0, AlbedoMethod::ThetaOuter, relTol);
}

void directionalAlbedoRgb(std::uint32_t model, const BrdfParams& params, double thetaDeg, double phiDeg,
                          double out[3]) {
  vec3 wi = incident(thetaDeg, phiDeg);
  for (int c = 0; c < 3; ++c) {
    out[c] = 0;
    if (shared::modelIsDelta(model)) continue;
    auto g = [&](vec3 wo) { return static_cast<double>(shared::brdfEval(model, params, wi, wo)[c]); };
    out[c] = hemisphere(g, thetaDeg * M_PI / 180.0, phiDeg * M_PI / 180.0, AlbedoMethod::ThetaOuter, kRelTol);
  }
}

void fillCoupledTables(BrdfParams& p) {
  using namespace shared;
  auto set = [&p](std::uint32_t i, float v) { p.v[i / 4][i % 4] = v; };
  const float m = brdfParam(p, COUPLED_M);
  static std::mutex mutex;
  static std::map<float, std::vector<float>> cache;
  std::vector<float> table;
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(m);
    if (it != cache.end()) table = it->second;
  }
  if (table.empty()) {
    // a_s = f0 A1 + A2: A2 = a_s(f0 = 0), A1 = a_s(f0 = 1) - A2.
    table.assign(2 * COUPLED_TABLE_SIZE + 2, 0.0f);
    for (int j = 0; j < COUPLED_TABLE_SIZE; ++j) {
      double x = coupledTableX(j);
      double A1, A2;
      coupledSpecularAlbedo(m, x * x, A1, A2);
      table[j] = static_cast<float>(A1);
      table[COUPLED_TABLE_SIZE + j] = static_cast<float>(A2);
    }
    // abar = 2 int_0^1 a(c) c dc = int_0^1 4 x^3 a(x) dx with a piecewise linear in x = sqrt(c):
    // exact with 3-point Gauss-Legendre per segment (degree 4); below x_0 a is constant a_0.
    const double gx[3] = {-0.774596669241483377, 0.0, 0.774596669241483377};
    const double gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    for (int t = 0; t < 2; ++t) {
      const float* a = &table[t * COUPLED_TABLE_SIZE];
      double x0 = coupledTableX(0);
      double sum = std::pow(x0, 4.0) * a[0];
      for (int j = 0; j + 1 < COUPLED_TABLE_SIZE; ++j) {
        double xa = coupledTableX(j), xb = coupledTableX(j + 1);
        for (int k = 0; k < 3; ++k) {
          double x = 0.5 * (xa + xb) + 0.5 * (xb - xa) * gx[k];
          double v = a[j] + (a[j + 1] - a[j]) * (x - xa) / (xb - xa);
          sum += 0.5 * (xb - xa) * gw[k] * 4.0 * x * x * x * v;
        }
      }
      table[2 * COUPLED_TABLE_SIZE + t] = static_cast<float>(sum);
    }
    std::lock_guard<std::mutex> lock(mutex);
    cache[m] = table;
  }
  for (int j = 0; j < COUPLED_TABLE_SIZE; ++j) {
    set(COUPLED_TABLE1 + j, table[j]);
    set(COUPLED_TABLE2 + j, table[COUPLED_TABLE_SIZE + j]);
  }
  set(COUPLED_ABAR1, table[2 * COUPLED_TABLE_SIZE]);
  set(COUPLED_ABAR2, table[2 * COUPLED_TABLE_SIZE + 1]);
}

}  // namespace nusselt
