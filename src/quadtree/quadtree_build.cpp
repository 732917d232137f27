// quadtree_build.cpp: one disc tree per known direction (Montes et al. 2008), docs/sampler.md.
//
// Geometry (shaders/shared/quadtree_layout.h): square cells over the inner disc r^2 < 3/4 and polar
// cells (c = cos theta, phi) over the rim annulus c < 1/2; isotropic sets store the half disc y >= 0.
// A cell becomes a leaf when n_max I >= V (I = integral of f over the cell, V = integral of its
// envelope e >= f), otherwise it is split into four. The envelope is A exp(k1 t1 + k2 t2) (+ B c^-s
// at the horizon of models unbounded there) in the leaf's proposal coordinates, fitted to every
// point evaluated in the cell (its Gauss points, its children's, a boundary grid, the rim, and the
// point of the cell nearest to each known peak of the model), times a margin; the constant
// envelope of the paper (k = 0, B = 0) is one of the candidates, and the smallest V wins.
// Integrals: tensor Gauss-Legendre; cells cut by the inner circle are integrated column by column;
// polar cells at the horizon of models with f ~ c^-s use an end-clustering substitution in c. A
// leaf's mass is refined adaptively inside the leaf (without creating tree nodes) until it agrees
// with its sub-cells' sum.
#include "quadtree/quadtree_build.h"

#include "brdf/merl.h"
#include "brdf/registry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace nusselt::quadtree {

using namespace shared;

ModelTraits modelTraits(std::uint32_t model, const BrdfParams& p) {
  const ModelSpec& spec = modelById(model);
  return spec.traits ? spec.traits(p) : ModelTraits{};
}

namespace {

constexpr double kRimCos = QT_RIM_COS;           // polar annulus: cos theta < kRimCos
constexpr double kInnerR2 = QT_INNER_R2;         // inner disc: r^2 < kInnerR2 (= 1 - kRimCos^2)
const double kInnerR = std::sqrt(kInnerR2);
constexpr double kTwoPi = 2 * M_PI;
// A leaf's mass is the sum over sub-cells at least this deep (root children: depth 1).
constexpr std::uint32_t kMinIntegrationDepth = 3;
// Grid of the proposal domain searched for f / e in leaves below 1 / n_max (polish); it shares
// with the audits' grids (16, 24) only the points at quarters, so they check points it did not see.
constexpr int kLowLeafLattice = 20;


// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
struct Gauss {
  std::vector<double> x, w;
  explicit Gauss(int n) {
    for (int i = 0; i < n; ++i) {
      double z = std::cos(M_PI * (i + 0.75) / (n + 0.5));
      double dp = 0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = 0;
        for (int j = 1; j <= n; ++j) {
          double p2 = p1;
          p1 = p0;
          p0 = ((2.0 * j - 1) * z * p1 - (j - 1.0) * p2) / j;
        }
        dp = n * (z * p0 - p1) / (z * z - 1);
        double dz = p0 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x.push_back(z);
      w.push_back(2.0 / ((1 - z * z) * dp * dp));
    }
  }
};
const Gauss& gauss5() { static const Gauss g(5); return g; }
const Gauss& gauss8() { static const Gauss g(8); return g; }

// One node of a 1D rule on [a, b]: position and weight; `cluster` (-1 none, 0 towards a, 1 towards b)
// uses the substitution distance ~ u^4 from that end, which makes an end singularity (x^-1/2, a
// sqrt edge) smooth.
struct RulePoint {
  double pos, weight, dist;  // dist: distance from the clustered end (exact when tiny)
};
void rule1D(double a, double b, int cluster, const Gauss& g, std::vector<RulePoint>& out) {
  out.clear();
  double L = b - a;
  if (L <= 0) return;
  for (std::size_t i = 0; i < g.x.size(); ++i) {
    double t = g.x[i], w = g.w[i];
    RulePoint p;
    if (cluster >= 0) {
      double u = 0.5 * (t + 1);
      p.dist = L * u * u * u * u;
      p.weight = 0.5 * w * 4 * L * u * u * u;
      p.pos = cluster == 0 ? a + p.dist : b - p.dist;
    } else {
      p.pos = a + 0.5 * L * (1 + t);
      p.weight = 0.5 * L * w;
      p.dist = 0;
    }
    out.push_back(p);
  }
}

// A point where f was evaluated: disc position, cos theta, azimuth (polar cells; NaN: not computed),
// f, and w: > 0 a quadrature point of the cell's basic rule (its weight), 0 a quadrature point of
// a finer rule (adaptive refinement), -1 a bound point (boundary grid, peaks, horizon, ridge).
struct Pt {
  float x, y, c, phi, f;
  double w;
};

struct Cell {
  bool polar = false;
  double a0 = 0, a1 = 0, b0 = 0, b1 = 0;  // square: [x0, x1] x [y0, y1]; polar: [c0, c1] x [t0, t1] (phi / pi)
  std::uint32_t depth = 0;
  int split = 0;  // polar cells: 0 = 2 x 2, 1 = four slices in c, 2 = four slices in phi (choosePolarSplit)
  bool cut() const {  // a square cell cut by the inner circle
    if (polar) return false;
    double fx = std::max(std::abs(a0), std::abs(a1)), fy = std::max(std::abs(b0), std::abs(b1));
    return fx * fx + fy * fy > kInnerR2;
  }
  // 0 = empty (outside the inner disc)
  bool outside() const {
    if (polar) return false;
    double cx = std::clamp(0.0, a0, a1), cy = std::clamp(0.0, b0, b1);
    return cx * cx + cy * cy >= kInnerR2;
  }
};

struct CellResult {
  int gridC = 0, gridP = 0;  // polar cells: the first gridC x gridP points are the rule's (c-major)
  double q = 0;     // integral of f over the cell's region
  double zs = 0;    // integral of c^-s over the region (polar cells at the horizon)
  double fmax = 0;  // max of f over the points evaluated
  bool anyPositive = false;
  std::vector<Pt> pts;  // every point evaluated (quadrature points carry their weight)
};

// Polar box of (square & inner disc): c in [kRimCos, coA], phi in [pa, pa + dp], padded so that it
// surely covers the region. Azimuths from the inside corners and the circle crossings of the edges.
struct PolarBox {  // azimuths in units of pi
  float c0 = float(kRimCos), c1 = 1, p0 = -1, p1 = 1;
};
PolarBox polarBox(double x0, double x1, double y0, double y1) {
  PolarBox b;
  double cx = std::clamp(0.0, x0, x1), cy = std::clamp(0.0, y0, y1);
  double ra2 = cx * cx + cy * cy;
  bool centreInside = x0 < 0 && 0 < x1 && y0 < 0 && 0 < y1;
  if (!centreInside) {
    double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
    double pc = std::atan2(my, mx);
    double lo = 10, hi = -10;
    auto add = [&](double px, double py) {
      double a = std::atan2(mx * py - my * px, mx * px + my * py);
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    };
    for (int q = 0; q < 4; ++q) {
      double px = (q & 1) ? x1 : x0, py = (q & 2) ? y1 : y0;
      double r2 = px * px + py * py;
      if (r2 < kInnerR2 && r2 > 0) add(px, py);
    }
    for (double xe : {x0, x1})
      if (std::abs(xe) < kInnerR) {
        double yc = std::sqrt(kInnerR2 - xe * xe);
        for (double y : {-yc, yc})
          if (y >= y0 && y <= y1) add(xe, y);
      }
    for (double ye : {y0, y1})
      if (std::abs(ye) < kInnerR) {
        double xc = std::sqrt(kInnerR2 - ye * ye);
        for (double x : {-xc, xc})
          if (x >= x0 && x <= x1) add(x, ye);
      }
    // A corner at the disc centre has no azimuth: the edges through it bound the range.
    if (cx == 0 && cy == 0) {
      for (double px : {x0, x1})
        for (double py : {y0, y1})
          if (px != 0 || py != 0) add(px == 0 ? 0 : px * 1e-3, py == 0 ? 0 : py * 1e-3);
    }
    if (hi >= lo) {
      b.p0 = float((pc + lo - 1e-6) / M_PI);
      b.p1 = float((pc + hi + 1e-6) / M_PI);
    }
  }
  b.c1 = float(std::min(1.0, std::sqrt(1 - ra2) * (1 + 1e-6) + 1e-7));
  return b;
}

// Proposal coordinates of a point in a leaf: square (t over the cell) or polar (c^2 and phi over the box).
struct Frame {
  int kind = QT_PROPOSAL_SQUARE;
  double a0, a1, b0, b1;  // square: x, y bounds; polar: c0, c1, phi0 / pi, phi1 / pi
  void coords(const Pt& p, double& t1, double& t2) const {
    if (kind == QT_PROPOSAL_SQUARE) {
      t1 = (p.x - a0) / (a1 - a0);
      t2 = (p.y - b0) / (b1 - b0);
    } else {
      double c = p.c, u0 = a0 * a0, u1 = a1 * a1;
      t1 = (c * c - u0) / (u1 - u0);
      double ph = (std::isnan(p.phi) ? std::atan2(double(p.y), double(p.x)) : double(p.phi)) / M_PI;
      // into [mid - 1, mid + 1), mid the box's middle (a box spans at most the full circle, 2)
      double mid = 0.5 * (b0 + b1);
      while (ph < mid - 1) ph += 2;
      while (ph >= mid + 1) ph -= 2;
      t2 = (ph - b0) / (b1 - b0);
    }
    t1 = std::clamp(t1, 0.0, 1.0);
    t2 = std::clamp(t2, 0.0, 1.0);
  }
};

// The point of a leaf's proposal domain at proposal coordinates (t1, t2), as the samplers map it
// (shaders/shared/quadtree.h): square: (x, y) over [a0, a1] x [b0, b1]; polar: c^2 over [a0^2, a1^2],
// phi / pi over [b0, b1]; a polar cut keeps only points inside the square cell [cx0, cx1] x [cy0, cy1].
// False where the sampler discards the point (outside the disc or the cell, at the horizon).
bool proposalPoint(int kind, double a0, double a1, double b0, double b1, double cx0, double cx1, double cy0,
                   double cy1, double t1, double t2, double& x, double& y, double& c) {
  if (kind == QT_PROPOSAL_SQUARE) {
    x = a0 + t1 * (a1 - a0);
    y = b0 + t2 * (b1 - b0);
    double r2 = x * x + y * y;
    if (r2 >= 1) return false;
    c = std::sqrt(1 - r2);
    return true;
  }
  double u0 = a0 * a0, u1 = a1 * a1;
  c = std::sqrt(u0 + t1 * (u1 - u0));
  if (!(float(c) > 0)) return false;
  double ph = M_PI * (b0 + t2 * (b1 - b0)), rr = std::sqrt((1 - c) * (1 + c));
  x = rr * std::cos(ph);
  y = rr * std::sin(ph);
  return !(kind == QT_PROPOSAL_POLAR_CUT && (x < cx0 || x > cx1 || y < cy0 || y > cy1));
}

// A leaf's envelope A exp(k1 (t1 - 1/2) + k2 (t2 - 1/2)) + B c^-s.
double envelopeAt(double A, double k1, double k2, double B, double s, double t1, double t2, double c) {
  double e = A * std::exp(k1 * (t1 - 0.5) + k2 * (t2 - 0.5));
  if (B > 0) e += B * std::pow(c, -s);
  return e;
}

double expMass(double k) { return k == 0 ? 1.0 : 2.0 * std::sinh(0.5 * k) / k; }

struct Envelope {
  double A = 0, k1 = 0, k2 = 0, B = 0;
  double V = 0;       // integral of the envelope over the leaf's region (cost: evaluations of f)
  double trialV = 0;  // ... over its proposal domain (cost: trials, incl. discarded points)
};

// ---- Exact bounds of a measured table (merl) over a region of the disc ----------------------------
// The interpolant of shaders/shared/brdf/merl.h is multilinear in the table coordinates
// u = (u_h, u_d, u_p) inside each table cell, so over a box [lo, hi] of u its maximum lies on the
// grid {lo, the integer nodes between, hi} of each axis: evaluating it there gives the exact
// maximum over the box. A region of the disc maps to a curved set of u; interval arithmetic on the
// coordinate change encloses it in a box, so the maximum over that box bounds f over the region.
struct Interval {
  double lo, hi;
};
Interval iv(double a, double b) { return {std::min(a, b), std::max(a, b)}; }
Interval operator+(Interval a, Interval b) { return {a.lo + b.lo, a.hi + b.hi}; }
Interval operator-(Interval a, Interval b) { return {a.lo - b.hi, a.hi - b.lo}; }
Interval operator*(Interval a, Interval b) {
  double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}
Interval operator*(double s, Interval a) { return iv(s * a.lo, s * a.hi); }
Interval sq(Interval a) {
  if (a.lo >= 0) return {a.lo * a.lo, a.hi * a.hi};
  if (a.hi <= 0) return {a.hi * a.hi, a.lo * a.lo};
  return {0, std::max(a.lo * a.lo, a.hi * a.hi)};
}
Interval sqrtI(Interval a) { return {std::sqrt(std::max(a.lo, 0.0)), std::sqrt(std::max(a.hi, 0.0))}; }
// a / b for b > 0.
Interval divPos(Interval a, Interval b) {
  double p[4] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}
// cos and sin over [p0, p1] (radians, p1 - p0 <= 2 pi).
Interval cosRange(double p0, double p1) {
  double lo = std::min(std::cos(p0), std::cos(p1)), hi = std::max(std::cos(p0), std::cos(p1));
  for (int k = int(std::ceil(p0 / M_PI)); k * M_PI <= p1; ++k) (k % 2 == 0 ? hi : lo) = (k % 2 == 0 ? 1.0 : -1.0);
  return {lo, hi};
}
Interval sinRange(double p0, double p1) { return cosRange(p0 - M_PI / 2, p1 - M_PI / 2); }

// The exact maximum of the interpolant over the u box (grid of box ends and nodes between), or,
// for a box whose grid has more than kMerlGridMax points, the largest node of the cells it meets
// (merlNodeMax). The grid is evaluated axis by axis, as merlLookup (brdf/merl.h) interpolates:
// along phi_d at every node row the box meets, then along theta_d, then along theta_h.
constexpr std::size_t kMerlGridMax = 4096;
double merlBoxMax(const MerlTable& t, Interval uh, Interval ud, Interval up) {
  uh = {std::clamp(uh.lo, 0.0, 89.0), std::clamp(uh.hi, 0.0, 89.0)};
  ud = {std::clamp(ud.lo, 0.0, 89.0), std::clamp(ud.hi, 0.0, 89.0)};
  if (up.hi - up.lo >= 179) up = {0, 180};
  // A coordinate of the grid: the lower node of its cell and the fraction towards the next.
  struct At {
    int n0;
    double f;
  };
  auto axis = [](Interval a, std::vector<At>& out) {
    out.clear();
    auto add = [&](double u) {
      int n = std::min(int(u), 88);
      out.push_back({n, u - n});
    };
    add(a.lo);
    for (double k = std::floor(a.lo) + 1; k < a.hi; k += 1) add(k);
    add(a.hi);
  };
  static thread_local std::vector<At> A, B, C;
  static thread_local std::vector<double> Tk, Tj;
  axis(uh, A);
  axis(ud, B);
  if (up.hi - up.lo >= 179 && A.size() * B.size() <= kMerlGridMax) {
    // Every phi_d: the interpolant at (u_h, u_d) is at most the bilinear interpolation of the
    // nodes' maxima over phi_d, whose maximum over the box is on its grid.
    auto M = [&](int i, int j) { return double(t.maxOverPhi[std::size_t(i) * 90 + std::size_t(j)]); };
    double m = 0;
    for (const At& a : A)
      for (const At& b : B) {
        const int i0 = a.n0, j0 = b.n0;
        double c0 = M(i0, j0) + b.f * (M(i0, j0 + 1) - M(i0, j0)), c1 = M(i0 + 1, j0) + b.f * (M(i0 + 1, j0 + 1) - M(i0 + 1, j0));
        m = std::max(m, c0 + a.f * (c1 - c0));
      }
    return m;
  }
  C.clear();
  {
    auto add = [&](double u) {
      u = std::fmod(u, 180.0);
      if (u < 0) u += 180;
      int k = std::min(int(u), 179);
      C.push_back({k, u - k});
    };
    add(up.lo);
    for (double k = std::floor(up.lo) + 1; k < up.hi; k += 1) add(k);
    add(up.hi);
  }
  const std::size_t nA = A.size(), nB = B.size(), nC = C.size();
  if (nA * nB * nC > kMerlGridMax)
    return merlNodeMax(t, int(uh.lo), int(uh.hi) + 1, int(ud.lo), int(ud.hi) + 1, int(std::floor(up.lo)),
                       int(std::floor(up.hi)) + 1);
  const int i0 = A.front().n0, j0 = B.front().n0;
  const std::size_t ni = std::size_t(A.back().n0 - i0 + 2), nj = std::size_t(B.back().n0 - j0 + 2);
  // Tk[(i, j), c]: along phi_d at node row (i0 + i, j0 + j).
  Tk.resize(ni * nj * nC);
  for (std::size_t i = 0; i < ni; ++i)
    for (std::size_t j = 0; j < nj; ++j) {
      const float* row = t.luminance.data() + ((std::size_t(i0) + i) * 90 + std::size_t(j0) + j) * 180;
      double* out = &Tk[(i * nj + j) * nC];
      for (std::size_t c = 0; c < nC; ++c) {
        const int k0 = C[c].n0, k1 = k0 + 1 == 180 ? 0 : k0 + 1;
        out[c] = double(row[k0]) + C[c].f * (double(row[k1]) - double(row[k0]));
      }
    }
  // Tj[(i, b), c]: then along theta_d.
  Tj.resize(ni * nB * nC);
  for (std::size_t i = 0; i < ni; ++i)
    for (std::size_t b = 0; b < nB; ++b) {
      const double* lo = &Tk[(i * nj + std::size_t(B[b].n0 - j0)) * nC];
      const double* hi = lo + nC;
      double* out = &Tj[(i * nB + b) * nC];
      for (std::size_t c = 0; c < nC; ++c) out[c] = lo[c] + B[b].f * (hi[c] - lo[c]);
    }
  // The maximum along theta_h.
  double m = 0;
  for (const At& a : A)
    for (std::size_t b = 0; b < nB; ++b) {
      const double* lo = &Tj[(std::size_t(a.n0 - i0) * nB + b) * nC];
      const double* hi = lo + nB * nC;
      for (std::size_t c = 0; c < nC; ++c) m = std::max(m, lo[c] + a.f * (hi[c] - lo[c]));
    }
  return m;
}

// luminance(f(wi, wo)) of a measured table as the builder evaluates it: merlEval's coordinates
// (the shared code) and its trilinear interpolation applied to the node luminances. Luminance is
// linear, so this is the sampler's quadEvalLum up to float rounding (relative 1e-7: the
// integrals and fits see no difference; the bounds are proven apart, with their own safety), at a
// third of the table reads.
float merlEvalLum(const MerlTable& t, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return 0.0f;
  const vec3 u = merlCoordinates(wi, wo);
  const std::uint32_t i0 = std::min(std::uint32_t(u.x), MERL_THETA_H_RES - 2u), j0 = std::min(std::uint32_t(u.y), MERL_THETA_D_RES - 2u);
  const std::uint32_t k0 = std::min(std::uint32_t(u.z), MERL_PHI_D_RES - 1u), k1 = k0 + 1u == MERL_PHI_D_RES ? 0u : k0 + 1u;
  const float fi = u.x - float(i0), fj = u.y - float(j0), fk = u.z - float(k0);
  auto row = [&](std::uint32_t i, std::uint32_t j) {
    const float* r = t.luminance.data() + (std::size_t(i) * MERL_THETA_D_RES + j) * MERL_PHI_D_RES;
    return r[k0] + fk * (r[k1] - r[k0]);
  };
  const float c00 = row(i0, j0), c01 = row(i0, j0 + 1u), c10 = row(i0 + 1u, j0), c11 = row(i0 + 1u, j0 + 1u);
  const float c0 = c00 + fj * (c01 - c00), c1 = c10 + fj * (c11 - c10);
  const float f = c0 + fi * (c1 - c0);
  return std::isfinite(f) ? std::max(f, 0.0f) : 0.0f;
}

// An upper bound of luminance(f(w, v)) over the w in the box x * y * z (disc coordinates and
// cos theta; v fixed, v.z >= 0).
double merlRegionBound(const MerlTable& t, vec3 v, Interval x, Interval y, Interval z) {
  const double vx = v.x, vy = v.y, vz = v.z;
  // f(., v) is symmetric in w.y for v.y = 0 (isotropic): bound over |w.y| (a padded polar box
  // reaches 1e-6 below the seam y = 0).
  if (vy == 0 && y.lo < 0) y = y.hi <= 0 ? Interval{-y.hi, -y.lo} : Interval{0, std::max(-y.lo, y.hi)};
  // Widening of the table coordinates: covers the float rounding of the shared evaluation.
  const double pad = 0.01;
  Interval d = vx * x + vy * y + vz * z;  // w . v
  d = {std::clamp(d.lo, -1.0, 1.0), std::clamp(d.hi, -1.0, 1.0)};
  // cos theta_d = |w + v| / 2 = sqrt((1 + w.v) / 2)
  Interval cd = sqrtI({(1 + d.lo) / 2, (1 + d.hi) / 2});
  Interval thetaD = {std::acos(std::min(cd.hi, 1.0)), std::acos(std::min(cd.lo, 1.0))};
  // theta_h = atan(rho / (w.z + v.z)), rho = |(w + v)_xy|: numerator and denominator depend on
  // different coordinates, so the quotient's interval is tight (cos theta_h = (w.z + v.z) / |w + v|
  // would tie both to w and, near w = -v, lose degrees to the box's corners off the sphere).
  Interval rhoH = sqrtI(sq(x + Interval{vx, vx}) + sq(y + Interval{vy, vy}));
  Interval zv = z + Interval{vz, vz};
  Interval thetaH = {0, M_PI / 2};
  if (zv.lo > 0) thetaH = {std::atan(rhoH.lo / zv.hi), std::atan(rhoH.hi / zv.lo)};
  else if (zv.hi > 0) thetaH = {std::atan(rhoH.lo / zv.hi), M_PI / 2};
  const double k = 2 / M_PI;
  Interval uh = {90 * std::sqrt(thetaH.lo * k) - pad, 90 * std::sqrt(thetaH.hi * k) + pad};
  Interval ud = {90 * thetaD.lo * k - pad, 90 * thetaD.hi * k + pad};
  Interval up = {0, 180};
  // phi_d: w = cos(theta_d) h + sin(theta_d) (cos(phi_d) t + sin(phi_d) b) with t.z = -sin(theta_h),
  // so w.z = cos(theta_d) cos(theta_h) - sin(theta_d) sin(theta_h) cos(phi_d); cos(theta_d)
  // cos(theta_h) = (w.z + v.z) / 2, sin(theta_d) sin(theta_h) = rho sqrt((1 - w.v) / (1 + w.v)) / 2
  // with rho = |(w + v)_xy|:  cos(phi_d) = (v.z - w.z) / (rho sqrt((1 - w.v) / (1 + w.v))).
  // The sets of an isotropic model have v.y = 0, v.x >= 0 and w.y >= 0 (half disc), where
  // sin(phi_d) = v.x w.y / (rho sin(theta_d)) >= 0: phi_d = acos(cos(phi_d)) in [0, pi].
  Interval wx = x + Interval{vx, vx}, wy = y + Interval{vy, vy};
  Interval rho = sqrtI(sq(wx) + sq(wy));
  if (vy == 0 && y.lo >= 0 && rho.lo > 1e-9 && d.hi < 1 - 1e-12 && d.lo > -1 + 1e-12) {
    Interval ratio = sqrtI(divPos({1 - d.hi, 1 - d.lo}, {1 + d.lo, 1 + d.hi}));
    Interval den = rho * ratio;
    if (den.lo > 1e-12) {
      Interval cp = divPos(Interval{vz, vz} - z, den);
      cp = {std::clamp(cp.lo, -1.0, 1.0), std::clamp(cp.hi, -1.0, 1.0)};
      double p0 = std::acos(cp.hi), p1 = std::acos(cp.lo);
      // Near the plane of incidence the cosine's enclosure is loose (it reaches +-1, and acos is
      // steep there); sin(phi_d) = v.x w.y / (rho sin(theta_d)) in [sMin, sMax] keeps phi_d within
      // asin(sMax) of 0 or pi, and at least asin(sMin) away from both. Without the second, a
      // region a degree off the plane counts the nodes on it, which hold the horizon's very large
      // values for a table of ward (f ~ 1/sqrt(cos)): leaves there went to the depth cap.
      Interval sd = sqrtI({(1 - d.hi) / 2, (1 - d.lo) / 2});
      if (sd.lo > 1e-12) {
        double sMax = vx * y.hi / (rho.lo * sd.lo);
        if (sMax < 1) {
          double a = std::asin(sMax);
          if (p0 >= M_PI / 2) p0 = std::max(p0, M_PI - a);
          else if (p1 <= M_PI / 2) p1 = std::min(p1, a);
        }
      }
      const double sMin = std::min(1.0, vx * y.lo / (rho.hi * sd.hi));
      if (sMin > 0) {
        const double a = std::asin(sMin);
        p0 = std::max(p0, a);
        p1 = std::min(p1, M_PI - a);
      }
      up = {p0 * 180 / M_PI - pad, p1 * 180 / M_PI + pad};
    }
  }
  return merlBoxMax(t, uh, ud, up);
}

class Builder {
 public:
  Builder(std::uint32_t model, const BrdfParams& params, vec3 v, bool halfDisc, const BuildSettings& s)
      : m_model(model), m_params(params), m_v(v), m_half(halfDisc), m_s(s) {
    m_traits = modelTraits(model, params);
    if (model == MODEL_MERL) m_merl = &merlTable(params);
    collectPeaks();
  }
  Tree build();

 private:
  std::uint32_t m_model;
  BrdfParams m_params;
  vec3 m_v;
  bool m_half;
  BuildSettings m_s;
  ModelTraits m_traits;
  std::vector<std::array<double, 2>> m_peaks;  // disc points
  // Ridges: lines of the disc along which f folds or streaks, thinner than any rule resolves
  // (axis 0: x = value, axis 1: y = value); each cell they cross gets a dense line of points.
  struct Ridge {
    int axis;
    double value;
  };
  std::vector<Ridge> m_ridges;
  std::uint64_t m_evals = 0;
  const MerlTable* m_merl = nullptr;  // merl: the table (exact bounds, certify)
  std::uint64_t m_certifyBoxes = 0;
  std::vector<RulePoint> m_rx, m_ry;
  double m_aEst = 0;

  // luminance(f(w, v)) (merl: merlEvalLum); on the lower disc at the mirror image below the surface.
  double evalLum(vec3 w) const {
    if (m_s.lowerDisc) return quadEvalLum(m_model, m_params, vec3(w.x, w.y, -w.z), m_v);
    return m_merl ? merlEvalLum(*m_merl, w, m_v) : quadEvalLum(m_model, m_params, w, m_v);
  }
  double eval(double x, double y, double c, double phi, double w, CellResult& r) {
    ++m_evals;
    double f = evalLum(vec3(float(x), float(y), float(c)));
    if (f > r.fmax) r.fmax = f;
    if (f > 0) r.anyPositive = true;
    r.pts.push_back({float(x), float(y), float(c), float(phi), float(f), w});
    return f;
  }
  void evalDisc(double x, double y, CellResult& r) {  // bound point given in the disc
    double r2 = x * x + y * y;
    if (r2 >= 1) return;
    double rr = std::sqrt(r2);
    eval(x, y, std::sqrt((1 - rr) * (1 + rr)), NAN, -1, r);
  }
  void evalPolar(double c, double phi, CellResult& r) {  // bound point given in polar coordinates
    double rr = std::sqrt((1 - c) * (1 + c));
    eval(rr * std::cos(phi), rr * std::sin(phi), c, phi, -1, r);
  }
  // Whether the quadrature points of r see what its bound points see: no bound point more than 4x
  // above every quadrature point (f times c^s for models unbounded at the horizon, whose
  // horizon points are large by nature). A narrow lobe or streak that only a peak or edge point
  // hits would otherwise be missed by the integral, however well the rules agree.
  bool resolved(const CellResult& r) const {
    const double s = m_traits.rimExponent;
    double qmax = 0, bmax = 0;
    for (const Pt& p : r.pts) {
      double v = s > 0 ? p.f * std::pow(std::max(double(p.c), 1e-30), s) : p.f;
      if (p.w < 0) bmax = std::max(bmax, v);
      else qmax = std::max(qmax, v);
    }
    return bmax <= 4 * qmax;
  }

  void collectPeaks();
  CellResult integrate(const Cell& c);
  CellResult integrateSquare(double x0, double x1, double y0, double y1);
  CellResult integratePolar(double c0, double c1, double p0, double p1);
  void boundPoints(const Cell& c, CellResult& r);
  std::array<Cell, 4> children(const Cell& c) const;
  double refine(const Cell& c, const CellResult& r, CellResult& all, int budget);
  Frame frameOf(const Cell& c, PolarBox* box) const;
  Envelope fit(const Cell& c, const Frame& fr, const CellResult& all, const std::vector<Pt>& quad);
  void polish(const Cell& c, const Frame& fr, CellResult& all, Envelope& env, int lattice);
  bool certify(const Frame& fr, Envelope& env, double giveUp);
  double tolerance(double q) const { return std::max(m_s.relTol * std::abs(q), m_s.absTol * m_aEst); }
};

void Builder::collectPeaks() {
  double vx = m_v.x, vy = m_v.y;
  double vr = std::sqrt(vx * vx + vy * vy);
  m_peaks.push_back({0.0, 0.0});  // normal
  m_peaks.push_back({-vx, -vy});  // mirror direction R(v)
  if (vr > 1e-9) {
    m_peaks.push_back({-vx / vr, -vy / vr});  // rim, forward
    m_peaks.push_back({vx / vr, vy / vr});    // rim, back-scatter
    m_peaks.push_back({vx, vy});              // retro direction
  } else {
    for (int k = 0; k < 8; ++k) m_peaks.push_back({std::cos(k * M_PI / 4), std::sin(k * M_PI / 4)});
  }
  // The model's own features (shaders/shared/brdf/<model>.h): extra peaks, and ridges that
  // replace the default ones below.
  ModelFeatures features;
  if (const auto hook = modelById(m_model).features) hook(m_params, m_v, features);
  // (Lower disc: the normal, the straight-through direction -v (= the mirror point above) and the
  // rim points serve as they are; the model adds its refraction direction.)
  const auto& extra = m_s.lowerDisc ? features.lowerPeaks : features.peaks;
  m_peaks.insert(m_peaks.end(), extra.begin(), extra.end());
  for (const DiscRidge& r : features.ridges) m_ridges.push_back({r.axis, r.value});
  if (features.ridges.empty() && m_traits.anisotropic) {
    m_ridges.push_back({0, -vx});
    m_ridges.push_back({1, -vy});
  }
}

CellResult Builder::integrate(const Cell& c) {
  if (c.polar) return integratePolar(c.a0, c.a1, c.b0 * M_PI, c.b1 * M_PI);
  return integrateSquare(c.a0, c.a1, c.b0, c.b1);
}

// Integral of f over [x0,x1] x [y0,y1] intersected with the inner disc.
CellResult Builder::integrateSquare(double x0, double x1, double y0, double y1) {
  CellResult r;
  double cx = std::clamp(0.0, x0, x1), cy = std::clamp(0.0, y0, y1);
  if (cx * cx + cy * cy >= kInnerR2) return r;
  double fx = std::max(std::abs(x0), std::abs(x1)), fy = std::max(std::abs(y0), std::abs(y1));
  const Gauss& g = gauss5();
  if (fx * fx + fy * fy <= kInnerR2) {
    double hx = 0.5 * (x1 - x0), hy = 0.5 * (y1 - y0);
    for (std::size_t i = 0; i < g.x.size(); ++i)
      for (std::size_t j = 0; j < g.x.size(); ++j) {
        double x = x0 + hx * (1 + g.x[i]), y = y0 + hy * (1 + g.x[j]);
        double w = g.w[i] * g.w[j] * hx * hy;
        r.q += w * eval(x, y, std::sqrt(1 - x * x - y * y), NAN, w, r);
      }
    return r;
  }
  // Cut by the inner circle: columns split at the circle crossings of the horizontal edges; the
  // column height sqrt(R^2 - x^2) has a square-root end at x = +-R, where the rule clusters.
  double bps[6];
  int nb = 0;
  bps[nb++] = std::max(x0, -kInnerR);
  bps[nb++] = std::min(x1, kInnerR);
  for (double ye : {y0, y1}) {
    if (std::abs(ye) >= kInnerR) continue;
    double xc = std::sqrt(kInnerR2 - ye * ye);
    for (double s : {-xc, xc})
      if (s > x0 && s < x1) bps[nb++] = s;
  }
  for (int i = 1; i < nb; ++i)
    for (int j = i; j > 0 && bps[j] < bps[j - 1]; --j) std::swap(bps[j], bps[j - 1]);
  for (int k = 0; k + 1 < nb; ++k) {
    double xa = bps[k], xb = bps[k + 1];
    if (xb - xa <= 0) continue;
    double xm = 0.5 * (xa + xb);
    if (std::abs(xm) >= kInnerR) continue;
    double hm = std::sqrt(kInnerR2 - xm * xm);
    if (-hm >= y1 || hm <= y0) continue;  // column outside the circle
    bool loCirc = -hm > y0, hiCirc = hm < y1;
    int cl = -1;
    if ((loCirc || hiCirc) && xa == -kInnerR) cl = 0;
    else if ((loCirc || hiCirc) && xb == kInnerR) cl = 1;
    rule1D(xa, xb, cl, (loCirc || hiCirc) ? gauss8() : g, m_rx);
    for (const RulePoint& px : m_rx) {
      double x = px.pos;
      double h2 = cl == 0 ? px.dist * (2 * kInnerR - px.dist) : cl == 1 ? px.dist * (2 * kInnerR - px.dist) : kInnerR2 - x * x;
      if (h2 <= 0) continue;
      double h = std::sqrt(h2);
      double lo = loCirc ? std::max(-h, y0) : y0, hi = hiCirc ? std::min(h, y1) : y1;
      if (hi <= lo) continue;
      rule1D(lo, hi, -1, g, m_ry);
      for (const RulePoint& py : m_ry) {
        double y = py.pos;
        double w = px.weight * py.weight;
        double c2 = 1 - x * x - y * y;
        if (c2 <= 0) continue;
        r.q += w * eval(x, y, std::sqrt(c2), NAN, w, r);
      }
    }
  }
  return r;
}

// Integral of f over the polar cell [c0, c1] x [p0, p1] (disc measure c dc dphi). At the horizon
// (c0 = 0) of a model with f ~ c^-s the c rule clusters towards 0.
CellResult Builder::integratePolar(double c0, double c1, double p0, double p1) {
  CellResult r;
  const double s = m_traits.rimExponent;
  bool cluster = c0 == 0 && s > 0;
  rule1D(c0, c1, cluster ? 0 : -1, cluster ? gauss8() : gauss5(), m_rx);
  rule1D(p0, p1, -1, gauss5(), m_ry);
  r.gridC = int(m_rx.size());
  r.gridP = int(m_ry.size());
  for (const RulePoint& pc : m_rx) {
    double c = std::max(cluster ? pc.dist : pc.pos, 1e-300);
    double zc = s > 0 ? std::pow(c, -s) : 1.0;
    for (const RulePoint& pp : m_ry) {
      double w = pc.weight * pp.weight * c;
      double f = 0;
      double rr = std::sqrt((1 - c) * (1 + c));
      f = eval(rr * std::cos(pp.pos), rr * std::sin(pp.pos), c, pp.pos, w, r);
      r.q += w * f;
      r.zs += w * zc;
    }
  }
  return r;
}

// Extra points for the envelope: a boundary grid, the point of the cell nearest to each peak, the
// ridge line, and the cell's part of the horizon (polar) or of the inner circle (cut squares).
void Builder::boundPoints(const Cell& cell, CellResult& r) {
  // The ridges (collectPeaks) get their own dense lines of points (below) instead of a denser
  // grid everywhere.
  const int G = 4;
  if (!cell.polar) {
    double x0 = cell.a0, x1 = cell.a1, y0 = cell.b0, y1 = cell.b1;
    auto inside = [&](double x, double y) { return x * x + y * y < kInnerR2; };
    for (int i = 0; i <= G; ++i)
      for (int j = 0; j <= G; ++j) {
        double x = x0 + (x1 - x0) * i / G, y = y0 + (y1 - y0) * j / G;
        if (inside(x, y)) evalDisc(x, y, r);
      }
    for (const auto& pk : m_peaks) {
      double px = std::clamp(pk[0], x0, x1), py = std::clamp(pk[1], y0, y1);
      double r2 = px * px + py * py;
      if (r2 >= kInnerR2) {  // nearest point of the inner disc: onto the circle, slightly inside
        double sc = kInnerR * (1 - 1e-7) / std::sqrt(r2);
        px *= sc;
        py *= sc;
        if (px < x0 || px > x1 || py < y0 || py > y1) continue;
      }
      evalDisc(px, py, r);
      // A peak inside the cell: also a ring of points close around it, where a function whose
      // limit at the peak depends on the direction of approach (schlick's anisotropy factor at
      // the mirror direction) takes its supremum.
      if (std::abs(px - pk[0]) + std::abs(py - pk[1]) < 1e-6)
        for (double rho : {1e-4, 1e-2})
          for (int k = 0; k < 8; ++k) {
            double qx = px + rho * (x1 - x0) * std::cos(k * M_PI / 4), qy = py + rho * (y1 - y0) * std::sin(k * M_PI / 4);
            if (qx >= x0 && qx <= x1 && qy >= y0 && qy <= y1 && qx * qx + qy * qy < kInnerR2) evalDisc(qx, qy, r);
          }
    }
    for (const Ridge& rd : m_ridges) {
      double lo = rd.axis ? y0 : x0, hi = rd.axis ? y1 : x1, a0 = rd.axis ? x0 : y0, a1 = rd.axis ? x1 : y1;
      if (rd.value < lo || rd.value > hi) continue;
      for (int j = 0; j <= 32; ++j) {
        double t = a0 + (a1 - a0) * j / 32, x = rd.axis ? t : rd.value, y = rd.axis ? rd.value : t;
        if (inside(x, y)) evalDisc(x, y, r);
      }
    }
    if (cell.cut()) {  // the inner circle inside the cell, and its end points on the edges
      PolarBox b = polarBox(x0, x1, y0, y1);
      for (int k = 0; k <= 32; ++k) {
        double ph = M_PI * (b.p0 + (double(b.p1) - b.p0) * k / 32);
        double x = kInnerR * (1 - 1e-7) * std::cos(ph), y = kInnerR * (1 - 1e-7) * std::sin(ph);
        if (x >= x0 && x <= x1 && y >= y0 && y <= y1) evalDisc(x, y, r);
      }
    }
    return;
  }
  double c0 = cell.a0, c1 = cell.a1, p0 = cell.b0 * M_PI, p1 = cell.b1 * M_PI;
  double cLo = std::max(c0, 1e-6);
  for (int i = 0; i <= G; ++i)
    for (int j = 0; j <= G; ++j) evalPolar(cLo + (c1 - cLo) * i / G, p0 + (p1 - p0) * j / G, r);
  if (c0 == 0)  // the horizon: cos theta = 1e-3 and 1e-6
    for (int k = 0; k <= 32; ++k)
      for (double c : {1e-3, 1e-6})
        if (c <= c1) evalPolar(c, p0 + (p1 - p0) * k / 32, r);
  for (const auto& pk : m_peaks) {
    double r2 = pk[0] * pk[0] + pk[1] * pk[1];
    double c = std::sqrt(std::max(0.0, 1 - r2));
    double ph = std::atan2(pk[1], pk[0]);
    double mid = 0.5 * (p0 + p1);
    while (ph < mid - M_PI) ph += kTwoPi;
    while (ph >= mid + M_PI) ph -= kTwoPi;
    double pc = std::clamp(c, cLo, c1), pp = std::clamp(ph, p0, p1);
    evalPolar(pc, pp, r);
    if (std::abs(pc - c) + std::abs(pp - ph) < 1e-6)  // at or inside the cell: a ring around it (as for squares)
      for (double rho : {1e-4, 1e-2})
        for (int k = 0; k < 8; ++k) {
          double qc = pc + rho * (c1 - c0) * std::cos(k * M_PI / 4), qp = pp + rho * (p1 - p0) * std::sin(k * M_PI / 4);
          if (qc >= cLo && qc <= c1 && qp >= p0 && qp <= p1) evalPolar(qc, qp, r);
        }
  }
  for (const Ridge& rd : m_ridges)
    for (int i = 0; i <= 32; ++i) {
      double c = cLo + (c1 - cLo) * i / 32, rr = std::sqrt((1 - c) * (1 + c));
      if (std::abs(rd.value) >= rr) continue;
      // x = r cos(phi) = value, or y = r sin(phi) = value: two azimuths each, in any turn.
      double a = rd.axis ? std::asin(rd.value / rr) : std::acos(rd.value / rr);
      double b = rd.axis ? M_PI - a : -a;
      for (double ph : {a, b, a - kTwoPi, b - kTwoPi, a + kTwoPi, b + kTwoPi})
        if (ph >= p0 && ph <= p1) evalPolar(c, ph, r);
    }
}

std::array<Cell, 4> Builder::children(const Cell& c) const {
  std::array<Cell, 4> ch;
  for (int k = 0; k < 4; ++k) {
    ch[k] = c;
    ch[k].depth = c.depth + 1;
  }
  if (!c.polar) {
    double xm = 0.5 * (c.a0 + c.a1), ym = 0.5 * (c.b0 + c.b1);
    for (int k = 0; k < 4; ++k) {
      if (k & 1) ch[k].a0 = xm; else ch[k].a1 = xm;
      if (k & 2) ch[k].b0 = ym; else ch[k].b1 = ym;
    }
    return ch;
  }
  if (c.split == 2) {  // four azimuth slices
    double q = 0.25 * (c.b1 - c.b0);
    for (int k = 0; k < 4; ++k) {
      ch[k].b0 = c.b0 + k * q;
      ch[k].b1 = k == 3 ? c.b1 : c.b0 + (k + 1) * q;
    }
    return ch;
  }
  if (c.split == 1) {  // four slices in c
    double q = 0.25 * (c.a1 - c.a0);
    for (int k = 0; k < 4; ++k) {
      ch[k].a0 = c.a0 + k * q;
      ch[k].a1 = k == 3 ? c.a1 : c.a0 + (k + 1) * q;
    }
    return ch;
  }
  double cm = 0.5 * (c.a0 + c.a1), tm = 0.5 * (c.b0 + c.b1);
  for (int k = 0; k < 4; ++k) {
    if (k & 1) ch[k].a0 = cm; else ch[k].a1 = cm;
    if (k & 2) ch[k].b0 = tm; else ch[k].b1 = tm;
  }
  return ch;
}

// How a polar cell splits (the descent needs no polar geometry, so the builder may choose): along
// the axis where log f varies most over the cell's own Gauss grid (four slices), else 2 x 2; the
// aspect (azimuth width over c height, both angles at the horizon) stays within [1/16, 16] and
// far from 1 only where f asks for it. Models whose horizon structure does not depend on the
// azimuth (schlick's multiple-reflection term) then refine in c alone.
int choosePolarSplit(const Cell& c, const CellResult& r) {
  double aspect = (c.b1 - c.b0) * M_PI / (c.a1 - c.a0);
  double varC = 0, varP = 0;
  int nC = r.gridC, nP = r.gridP;
  if (nC >= 2 && nP >= 2 && int(r.pts.size()) >= nC * nP && r.fmax > 0) {
    double floor = 1e-9 * r.fmax;
    auto L = [&](int i, int j) { return std::log(std::max(double(r.pts[std::size_t(i * nP + j)].f), floor)); };
    for (int i = 0; i < nC; ++i)
      for (int j = 0; j + 1 < nP; ++j) varP += std::abs(L(i, j + 1) - L(i, j));
    for (int j = 0; j < nP; ++j)
      for (int i = 0; i + 1 < nC; ++i) varC += std::abs(L(i + 1, j) - L(i, j));
    varC /= nP * (nC - 1);
    varP /= nC * (nP - 1);
  }
  if (varC > 3 * varP && aspect <= 16) return 1;
  if (varP > 3 * varC && aspect >= 1.0 / 16) return 2;
  if (aspect > 2.5) return 2;
  if (aspect < 0.4) return 1;
  return 0;
}

// Adaptive refinement of the integral of a cell whose basic rule gave r.q: the sum over its four
// sub-cells, recursively where they disagree (integration only: no tree nodes). Points go to all.
double Builder::refine(const Cell& cell, const CellResult& r, CellResult& all, int budget) {
  Cell c = cell;
  c.split = 0;  // integration only: halve both axes (a cell whose grid looks flat along one axis may hide a streak)
  std::array<Cell, 4> ch = children(c);
  double sum = 0;
  CellResult sub[4];
  for (int k = 0; k < 4; ++k) {
    if (ch[k].outside()) continue;
    sub[k] = integrate(ch[k]);
    sum += sub[k].q;
  }
  // Agreement of two rules is trusted only from kMinIntegrationDepth on: on large cells two coarse
  // rules can agree on a lobe that neither resolves.
  bool ok = (std::abs(r.q - sum) <= tolerance(sum) && c.depth + 1 >= kMinIntegrationDepth) || budget <= 0;
  double total = 0;
  for (int k = 0; k < 4; ++k) {
    all.fmax = std::max(all.fmax, sub[k].fmax);
    all.anyPositive = all.anyPositive || sub[k].anyPositive;
    for (const Pt& p : sub[k].pts) all.pts.push_back({p.x, p.y, p.c, p.phi, p.f, 0.0});
    if (!ok && sub[k].anyPositive) total += refine(ch[k], sub[k], all, budget - 1);
    else total += sub[k].q;
  }
  return ok ? sum : total;
}

Frame Builder::frameOf(const Cell& c, PolarBox* box) const {
  Frame fr;
  if (c.polar) {
    fr.kind = QT_PROPOSAL_POLAR;
    fr.a0 = c.a0;
    fr.a1 = c.a1;
    fr.b0 = c.b0;
    fr.b1 = c.b1;
  } else if (c.cut()) {
    PolarBox b = polarBox(c.a0, c.a1, c.b0, c.b1);
    if (box) *box = b;
    fr.kind = QT_PROPOSAL_POLAR_CUT;
    fr.a0 = b.c0;
    fr.a1 = b.c1;
    fr.b0 = b.p0;
    fr.b1 = b.p1;
  } else {
    fr.kind = QT_PROPOSAL_SQUARE;
    fr.a0 = c.a0;
    fr.a1 = c.a1;
    fr.b0 = c.b0;
    fr.b1 = c.b1;
  }
  return fr;
}

// The envelope of smallest volume among: the constant of the paper (margin x max f), exponentials
// A exp(k1 (t1 - 1/2) + k2 (t2 - 1/2)) with slopes from a weighted least-squares fit of log f (and
// scaled or one-axis variants), and, at the horizon of models with f ~ c^-s, A + B c^-s. Each
// candidate's A is the smallest that keeps e >= margin f at every point evaluated in the cell.
// V is the envelope's integral over the leaf's region: closed form for squares and polar cells,
// the cell's quadrature (`quad`: points with weights) for squares cut by the inner circle.
Envelope Builder::fit(const Cell& cell, const Frame& fr, const CellResult& all, const std::vector<Pt>& quad) {
  const double margin = m_s.boundMargin, s = m_traits.rimExponent;
  double measure;  // area of the proposal domain (disc measure)
  if (fr.kind == QT_PROPOSAL_SQUARE) measure = (fr.a1 - fr.a0) * (fr.b1 - fr.b0);
  else measure = 0.5 * (fr.a1 * fr.a1 - fr.a0 * fr.a0) * (fr.b1 - fr.b0) * M_PI;
  // Points in proposal coordinates.
  struct P {
    double t1, t2, f, c;
  };
  std::vector<P> pts;
  pts.reserve(all.pts.size());
  for (const Pt& p : all.pts) {
    if (!(p.f > 0)) continue;
    P q;
    fr.coords(p, q.t1, q.t2);
    q.f = p.f;
    q.c = p.c;
    pts.push_back(q);
  }
  std::vector<P> qp;
  if (fr.kind == QT_PROPOSAL_POLAR_CUT)
    for (const Pt& p : quad) {
      P q;
      fr.coords(p, q.t1, q.t2);
      q.f = p.w;  // weight
      q.c = p.c;
      qp.push_back(q);
    }
  auto volumeExp = [&](double k1, double k2, double A) {
    if (fr.kind == QT_PROPOSAL_POLAR_CUT) {
      double v = 0;
      for (const P& q : qp) v += q.f * std::exp(k1 * (q.t1 - 0.5) + k2 * (q.t2 - 0.5));
      return A * v;
    }
    return A * measure * expMass(k1) * expMass(k2);
  };
  auto amplitude = [&](double k1, double k2) {
    double a = 0;
    for (const P& q : pts) a = std::max(a, q.f * std::exp(-k1 * (q.t1 - 0.5) - k2 * (q.t2 - 0.5)));
    return margin * a;
  };
  Envelope best;
  best.A = margin * all.fmax;
  best.V = volumeExp(0, 0, best.A);
  best.trialV = best.A * measure;
  if (pts.empty()) return best;
  auto consider = [&](double k1, double k2) {
    if (std::abs(k1) < QT_MIN_SLOPE) k1 = 0;
    if (std::abs(k2) < QT_MIN_SLOPE) k2 = 0;
    // Slopes up to 40 (a factor e^40 across the domain); squares cut by the inner circle measure V
    // with their quadrature points, which resolve exp(k t) for |k| <= 8 only.
    const double kMax = fr.kind == QT_PROPOSAL_POLAR_CUT ? 8.0 : 40.0;
    k1 = std::clamp(k1, -kMax, kMax);
    k2 = std::clamp(k2, -kMax, kMax);
    if (k1 == 0 && k2 == 0) return;
    double A = amplitude(k1, k2);
    double V = volumeExp(k1, k2, A);
    double trialV = A * measure * expMass(k1) * expMass(k2);
    // A cut cell's proposal covers its polar box: an exponential that puts most of its mass outside
    // the cell would waste trials on discards. At least a third of the proposal inside.
    if (fr.kind == QT_PROPOSAL_POLAR_CUT && trialV > 3 * V) return;
    if (V < best.V) best = Envelope{A, k1, k2, 0, V, trialV};
  };
  // Weighted least squares of log f = a + k1 t1 + k2 t2 (weights f: the fit matters where f is large).
  double S[3][3] = {}, R[3] = {};
  for (const P& q : pts) {
    double w = q.f, l = std::log(q.f);
    double b[3] = {1, q.t1 - 0.5, q.t2 - 0.5};
    for (int i = 0; i < 3; ++i) {
      R[i] += w * b[i] * l;
      for (int j = 0; j < 3; ++j) S[i][j] += w * b[i] * b[j];
    }
  }
  // Solve the 3 x 3 system (Cramer).
  auto det3 = [](double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  double D = det3(S);
  if (std::abs(D) > 1e-300) {
    double sol[3];
    for (int c = 0; c < 3; ++c) {
      double M[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) M[i][j] = j == c ? R[i] : S[i][j];
      sol[c] = det3(M) / D;
    }
    double k1 = sol[1], k2 = sol[2];
    if (std::isfinite(k1) && std::isfinite(k2)) {
      consider(k1, k2);
      consider(k1, 0);
      consider(0, k2);
      consider(0.6 * k1, 0.6 * k2);
      consider(1.3 * k1, 1.3 * k2);
    }
  }
  // f ~ c^-s at the horizon: A + B c^-s (V(B) = A(B) area + B zs is convex: golden section).
  if (fr.kind == QT_PROPOSAL_POLAR && cell.a0 == 0 && s > 0) {
    double zs = (std::pow(fr.a1, 2 - s) - std::pow(fr.a0, 2 - s)) / (2 - s) * (fr.b1 - fr.b0) * M_PI;  // int c^-s c dc dphi
    std::vector<std::array<double, 2>> fc;  // (margin f_i, c_i^-s)
    double bMax = 0;
    for (const P& q : pts)
      if (q.c > 0) {
        double cs = std::pow(q.c, -s);
        fc.push_back({margin * q.f, cs});
        bMax = std::max(bMax, margin * q.f / cs);
      }
    auto hOf = [&](double b) {
      double m = 0;
      for (const auto& p : fc) m = std::max(m, p[0] - b * p[1]);
      return m;
    };
    auto vOf = [&](double b) { return measure * hOf(b) + zs * b; };
    double lo = 0, hi = bMax;
    const double gr = 0.5 * (std::sqrt(5.0) - 1);
    double b1 = hi - gr * (hi - lo), b2 = lo + gr * (hi - lo);
    double v1 = vOf(b1), v2 = vOf(b2);
    for (int it = 0; it < 48 && hi - lo > 1e-9 * bMax; ++it) {
      if (v1 <= v2) { hi = b2; b2 = b1; v2 = v1; b1 = hi - gr * (hi - lo); v1 = vOf(b1); }
      else { lo = b1; b1 = b2; v1 = v2; b2 = lo + gr * (hi - lo); v2 = vOf(b2); }
    }
    for (double b : {b1, b2, bMax})
      if (b > 0 && vOf(b) < best.V) best = Envelope{hOf(b), 0, 0, b, vOf(b), vOf(b)};
  }
  return best;
}

// The envelope of a leaf, checked between its points: from the three points where f / e is largest,
// a pattern search in the proposal coordinates (steps 1/16 of the domain, halved when no
// neighbour is higher) climbs to the local maximum of f / e, which a narrow ridge or peak between
// the grid and Gauss points can hide.
void Builder::polish(const Cell& cell, const Frame& fr, CellResult& all, Envelope& env, int lattice) {
  const double s = m_traits.rimExponent;
  auto envAt = [&](double t1, double t2, double c) { return envelopeAt(env.A, env.k1, env.k2, env.B, s, t1, t2, c); };
  // f / e at proposal coordinates (t1, t2); -1 outside the leaf's region.
  auto ratioAt = [&](double t1, double t2) {
    double x, y, c;
    if (!(t1 >= 0 && t1 <= 1 && t2 >= 0 && t2 <= 1) ||
        !proposalPoint(fr.kind, fr.a0, fr.a1, fr.b0, fr.b1, cell.a0, cell.a1, cell.b0, cell.b1, t1, t2, x, y, c))
      return -1.0;
    double f = evalLum(vec3(float(x), float(y), float(c)));
    ++m_evals;
    all.pts.push_back({float(x), float(y), float(c), NAN, float(f), -1});
    return f / envAt(t1, t2, c);
  };
  // A leaf below 1 / n_max (tail or capped) is coarse where f is steep: its Gauss and boundary
  // points can miss a corner or edge where f / e is far larger (found by the envelope audit of
  // hard sets: up to 1e3). There a (lattice + 1)^2 grid of the proposal domain joins the seeds.
  if (lattice > 0)
    for (int i = 0; i <= lattice; ++i)
      for (int j = 0; j <= lattice; ++j) ratioAt(double(i) / lattice, double(j) / lattice);
  // Seeds: the three points of largest f / e.
  constexpr int kSeeds = 3;
  double best[kSeeds][3];  // ratio, t1, t2
  for (auto& b : best) b[0] = -1, b[1] = b[2] = 0;
  for (const Pt& p : all.pts) {
    if (!(p.f > 0) || !(p.c > 0)) continue;
    double t1, t2;
    fr.coords(p, t1, t2);
    double r = p.f / envAt(t1, t2, double(p.c));
    for (int k = 0; k < kSeeds; ++k)
      if (r > best[k][0]) {
        for (int m = kSeeds - 1; m > k; --m)
          for (int q = 0; q < 3; ++q) best[m][q] = best[m - 1][q];
        best[k][0] = r; best[k][1] = t1; best[k][2] = t2;
        break;
      }
  }
  double top = best[0][0];
  for (auto& b : best) {
    if (b[0] <= 0) continue;
    double r = b[0], t1 = b[1], t2 = b[2], step = 1.0 / 16;
    for (int it = 0; it < 12 && step > 1.0 / 8192; ++it) {
      bool moved = false;
      const double d[4][2] = {{step, 0}, {-step, 0}, {0, step}, {0, -step}};
      for (const auto& dd : d) {
        double q = ratioAt(t1 + dd[0], t2 + dd[1]);
        if (q > r) { r = q; t1 += dd[0]; t2 += dd[1]; moved = true; break; }
      }
      if (!moved) step *= 0.5;
    }
    top = std::max(top, r);
  }
  // Where the search climbed above what the points saw (f / e above 1 / margin), the envelope
  // grows to keep its margin there too.
  double scale = m_s.boundMargin * top;
  if (scale > 1) {
    env.A *= scale;
    env.B *= scale;
    env.V *= scale;
    env.trialV *= scale;
  }
}

// merl: makes the envelope a proven bound. The leaf's proposal domain is covered by boxes of
// proposal coordinates; a box is proven when the envelope's minimum over it (at a corner: the
// exponential is monotone along each axis) is at least the exact bound of f over it
// (merlRegionBound); unproven boxes are split four ways (down to 1/64 of the domain), and the
// envelope is scaled by the largest bound / minimum left (the growth).
// Boxes are taken largest ratio bound / minimum first: a box whose ratio is at most the growth
// found so far is proven by the grown envelope (the growth never decreases), so once the first
// box at the finest level sets the growth, the boxes left are proven without splitting them (a
// sub-box's bound is at most its box's, its envelope minimum at least as large). The growth is
// the same as that of a search of every box. Returns false, leaving the envelope unproven, as
// soon as the growth exceeds giveUp (the leaf would then be split anyway).
bool Builder::certify(const Frame& fr, Envelope& env, double giveUp) {
  const double safety = 1.001;  // float rounding of the shared evaluation and of the envelope
  struct Box {
    double a0, a1, b0, b1;
    int depth;
    double ratio;  // bound of f over the box / the envelope's minimum over it
  };
  auto ratioOf = [&](Box& b) {
    ++m_certifyBoxes;
    Interval x, y, z;
    if (fr.kind == QT_PROPOSAL_SQUARE) {
      x = {fr.a0 + b.a0 * (fr.a1 - fr.a0), fr.a0 + b.a1 * (fr.a1 - fr.a0)};
      y = {fr.b0 + b.b0 * (fr.b1 - fr.b0), fr.b0 + b.b1 * (fr.b1 - fr.b0)};
      Interval r2 = sq(x) + sq(y);
      if (r2.lo >= 1) return 0.0;  // outside the disc: never sampled
      z = sqrtI({1 - std::min(r2.hi, 1.0), 1 - r2.lo});
    } else {
      double u0 = fr.a0 * fr.a0, u1 = fr.a1 * fr.a1;
      Interval c2 = {u0 + b.a0 * (u1 - u0), u0 + b.a1 * (u1 - u0)};
      z = sqrtI(c2);
      Interval r = sqrtI({1 - c2.hi, 1 - c2.lo});
      double p0 = M_PI * (fr.b0 + b.b0 * (fr.b1 - fr.b0)), p1 = M_PI * (fr.b0 + b.b1 * (fr.b1 - fr.b0));
      x = r * cosRange(p0, p1);
      y = r * sinRange(p0, p1);
    }
    double bound = safety * merlRegionBound(*m_merl, m_v, x, y, z);
    if (bound <= 0) return 0.0;
    // e > 0 everywhere (A > 0, |k| <= 40), so the ratio is finite
    double e = env.A * std::exp(std::min(env.k1 * (b.a0 - 0.5), env.k1 * (b.a1 - 0.5)) +
                                std::min(env.k2 * (b.b0 - 0.5), env.k2 * (b.b1 - 0.5)));
    return e > 0 ? bound / e : INFINITY;
  };
  auto lower = [](const Box& p, const Box& q) { return p.ratio < q.ratio; };
  std::vector<Box> heap;
  Box root{0, 1, 0, 1, 0, 0};
  root.ratio = ratioOf(root);
  double worst = 1;  // the growth: boxes at or below it are proven
  if (root.ratio > worst) heap.push_back(root);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), lower);
    Box b = heap.back();
    heap.pop_back();
    if (b.ratio <= worst) continue;
    if (b.depth >= 6 || m_certifyBoxes >= (1u << 30)) {
      worst = b.ratio;
      if (worst > giveUp) return false;
      continue;
    }
    double am = 0.5 * (b.a0 + b.a1), bm = 0.5 * (b.b0 + b.b1);
    Box ch[4] = {{b.a0, am, b.b0, bm, b.depth + 1, 0}, {am, b.a1, b.b0, bm, b.depth + 1, 0},
                 {b.a0, am, bm, b.b1, b.depth + 1, 0}, {am, b.a1, bm, b.b1, b.depth + 1, 0}};
    for (Box& c : ch) {
      c.ratio = ratioOf(c);
      if (c.ratio > worst) {
        heap.push_back(c);
        std::push_heap(heap.begin(), heap.end(), lower);
      }
    }
  }
  if (worst > 1) {
    env.A *= worst;
    env.V *= worst;
    env.trialV *= worst;
  }
  return true;
}

struct Item {
  Cell cell;
  std::uint32_t parent, slot;
  CellResult res;
};

Tree Builder::build() {
  Tree tree;
  const float s = m_traits.rimExponent;
  // Root children (quadtree_layout.h).
  std::vector<Cell> roots;
  auto square = [](double x0, double x1, double y0, double y1) {
    Cell c;
    c.a0 = x0; c.a1 = x1; c.b0 = y0; c.b1 = y1; c.depth = 1;
    return c;
  };
  auto polarCell = [](double t0, double t1) {
    Cell c;
    c.polar = true;
    c.a0 = 0; c.a1 = kRimCos; c.b0 = t0; c.b1 = t1; c.depth = 1;
    return c;
  };
  if (m_half) roots = {square(-1, 0, 0, 1), square(0, 1, 0, 1), polarCell(0, 1)};
  else roots = {square(-1, 1, -1, 1), polarCell(0, 1), polarCell(1, 2)};

  QuadNode rootNode;
  rootNode.mass = vec4(0.0f);
  rootNode.child = uvec4(QT_EMPTY);
  tree.nodes.push_back(rootNode);
  tree.root = 0;

  std::vector<Item> stack;
  m_aEst = 0;
  for (std::size_t k = 0; k < roots.size(); ++k) {
    CellResult r = integrate(roots[k]);
    m_aEst += r.q;
    stack.push_back({roots[k], 0, std::uint32_t(k), std::move(r)});
  }
  std::reverse(stack.begin(), stack.end());
  double running = m_aEst;
  while (!stack.empty()) {
    Item it = std::move(stack.back());
    stack.pop_back();
    CellResult all = std::move(it.res);
    double parentQ = all.q;
    boundPoints(it.cell, all);
    // A polar cell whose own rule does not resolve it (a streak between its Gauss points) splits
    // 2 x 2; otherwise along the axis its rule sees varying.
    if (it.cell.polar) it.cell.split = resolved(all) ? choosePolarSplit(it.cell, all) : 0;
    const Cell& cell = it.cell;
    auto link = [&](std::uint32_t value) { tree.nodes[it.parent].child[it.slot] = value; };
    std::array<Cell, 4> ch = children(cell);
    CellResult child[4];
    double sumq = 0;
    std::vector<Pt> quad;  // the children's quadrature points (weights): V of cut cells
    for (int c = 0; c < 4; ++c) {
      if (ch[c].outside()) continue;
      child[c] = integrate(ch[c]);
      sumq += child[c].q;
      all.fmax = std::max(all.fmax, child[c].fmax);
      all.anyPositive = all.anyPositive || child[c].anyPositive;
      for (const Pt& p : child[c].pts) {
        all.pts.push_back(p);
        if (p.w > 0) quad.push_back(p);
      }
    }
    // Running estimate of the total (the scale of the absolute tolerances): a lobe missed by a
    // coarse rule raises it as soon as it is resolved.
    running += sumq - parentQ;
    m_aEst = std::max(m_aEst, running);
    if (!all.anyPositive) {  // f = 0 at every point evaluated, peaks included
      link(QT_EMPTY);
      ++tree.stats.emptyChildren;
      continue;
    }
    // Four slices along one axis test the rule along the other one not at all: then the mass is
    // refined 2 x 2 (refine) before it is trusted.
    bool accurate = std::abs(parentQ - sumq) <= tolerance(sumq) && cell.depth + 1 >= kMinIntegrationDepth &&
                    (!cell.polar || cell.split == 0);
    PolarBox box;
    Frame fr = frameOf(cell, &box);
    Envelope env = fit(cell, fr, all, quad);
    bool capped = cell.depth >= m_s.maxDepth;
    auto accepts = [&](double q, const Envelope& e) { return m_s.nMax * q >= e.V; };
    // Tail cells (negligible mass) stop refining below 1/n_max, but not below 1/16 of their
    // trials (the trial cap), unless their mass is below 1e-12 a (never sampled in practice).
    auto tailOk = [&](double q, const Envelope& e) {
      return (q < m_s.tailTol * m_aEst && 16 * q >= e.trialV) || q < 1e-12 * m_aEst;
    };
    // Leaves only where the children's quadrature sees what the bound points see (or at the cap).
    const bool seen = resolved(all);
    bool leaf = (seen && (accepts(sumq, env) || tailOk(sumq, env))) || capped;
    double mass = sumq;
    if (leaf && !accurate) {
      // The leaf's mass by adaptive integration inside it (no tree nodes); its new points refine
      // the envelope too.
      double total = 0;
      for (int c = 0; c < 4; ++c)
        if (child[c].anyPositive) total += refine(ch[c], child[c], all, 12);
        else total += child[c].q;
      running += total - sumq;
      m_aEst = std::max(m_aEst, running);
      mass = total;
      env = fit(cell, fr, all, quad);
      leaf = (seen && (accepts(mass, env) || tailOk(mass, env))) || capped;
      if (!leaf) {
        // Split after all: the children start from their basic rules again.
        running -= total - sumq;
      }
    }
    if (leaf && mass > 0) {
      // merl: no search between the points; certify proves the envelope (or grows it) exactly
      // (6% fewer evaluations of f and 1% fewer leaves on the ward table).
      if (!m_merl) polish(cell, fr, all, env, accepts(mass, env) ? 0 : kLowLeafLattice);
      bool proven = true;
      if (m_merl) {
        // The largest growth with which the leaf is kept (accepted, or a tail leaf; any at the
        // cap), a little above so that only clear failures give up: a leaf that fails the split
        // rule already is split without a proof.
        double giveUp = INFINITY;
        if (!capped && !(mass < 1e-12 * m_aEst)) {
          giveUp = m_s.nMax * mass / env.V;
          if (mass < m_s.tailTol * m_aEst) giveUp = std::max(giveUp, 16 * mass / env.trialV);
          giveUp *= 1 + 1e-9;
        }
        proven = giveUp >= 1 && certify(fr, env, giveUp);
      }
      if (!proven || (!capped && !(accepts(mass, env) || tailOk(mass, env)))) {
        leaf = false;  // the envelope had to grow: split after all
        running -= mass - sumq;
      }
    }
    if (leaf) {
      // A leaf whose mass is below 1e-30 of the total is never chosen by a float descent, and its
      // float envelope can underflow: it is left out (a bias below 1e-30).
      if (mass <= 1e-30 * m_aEst) {
        link(QT_EMPTY);
        ++tree.stats.emptyChildren;
        continue;
      }
      QuadLeaf L;
      L.data = vec4(float(env.A), float(mass), float(fr.kind), env.B > 0 ? s : 0.0f);
      L.env = vec4(float(env.k1), float(env.k2), float(env.B), 0.0f);
      L.box = fr.kind == QT_PROPOSAL_SQUARE ? vec4(0.0f) : vec4(float(fr.a0), float(fr.a1), float(fr.b0), float(fr.b1));
      link(QT_LEAF_BIT | std::uint32_t(tree.leaves.size()));
      tree.leaves.push_back(L);
      tree.stats.leaves++;
      bool good = accepts(mass, env);
      if (!good) {
        if (capped) tree.stats.cappedLeaves++;
        else tree.stats.tailLeaves++;
        tree.stats.lowAcceptanceMass += mass;
      }
      if (fr.kind != QT_PROPOSAL_SQUARE) tree.stats.rimLeaves++;
      if (env.k1 != 0 || env.k2 != 0) tree.stats.expLeaves++;
      if (env.B > 0) tree.stats.singularLeaves++;
      tree.stats.maxDepth = std::max(tree.stats.maxDepth, cell.depth);
      if (good) tree.stats.minAcceptance = std::min(tree.stats.minAcceptance, env.V > 0 ? mass / env.V : 1.0);
      continue;
    }
    std::uint32_t index = std::uint32_t(tree.nodes.size());
    QuadNode node;
    node.mass = vec4(0.0f);
    node.child = uvec4(QT_EMPTY);
    tree.nodes.push_back(node);
    link(index);
    for (int c = 3; c >= 0; --c) {
      if (ch[c].outside()) continue;
      stack.push_back({ch[c], index, std::uint32_t(c), std::move(child[c])});
    }
  }
  // Masses, bottom-up: children are created after their parents.
  std::vector<double> nodeMass(tree.nodes.size(), 0.0);
  for (std::size_t i = tree.nodes.size(); i-- > 0;) {
    QuadNode& n = tree.nodes[i];
    double total = 0;
    for (int c = 0; c < 4; ++c) {
      std::uint32_t l = n.child[c];
      double m = 0;
      if (l == QT_EMPTY) m = 0;
      else if (l & QT_LEAF_BIT) m = tree.leaves[l & ~QT_LEAF_BIT].data.y;
      else m = nodeMass[l];
      n.mass[c] = float(m);
      total += m;
    }
    nodeMass[i] = total;
  }
  tree.mass = nodeMass[0] * (m_half ? 2.0 : 1.0);
  if (tree.mass <= 0) {
    tree.nodes.clear();
    tree.leaves.clear();
    tree.root = QT_EMPTY;
    tree.mass = 0;
  }
  tree.stats.nodes = std::uint32_t(tree.nodes.size());
  tree.stats.evaluations = m_evals;
  tree.stats.certifyBoxes = m_certifyBoxes;
  return tree;
}

}  // namespace

void forEachLeaf(const QuadNode* nodes, const QuadLeaf* leaves, std::uint32_t root, bool anisotropic,
                 const std::function<void(std::uint32_t, const QuadLeaf&, double, double, double)>& fn) {
  if (root == QT_EMPTY) return;
  struct C { std::uint32_t link; double x0, y0, size; };
  const QuadNode& R = nodes[root];
  std::vector<C> stack;
  if (anisotropic) stack = {{R.child[2], 0, 0, 0}, {R.child[1], 0, 0, 0}, {R.child[0], -1, -1, 2}};
  else stack = {{R.child[2], 0, 0, 0}, {R.child[1], 0, 0, 1}, {R.child[0], -1, 0, 1}};
  while (!stack.empty()) {
    C c = stack.back();
    stack.pop_back();
    if (c.link == QT_EMPTY) continue;
    if (c.link & QT_LEAF_BIT) {
      std::uint32_t l = c.link & ~QT_LEAF_BIT;
      fn(l, leaves[l], c.x0, c.y0, c.size);
      continue;
    }
    const QuadNode& n = nodes[c.link];
    double h = 0.5 * c.size;
    for (int k = 3; k >= 0; --k) stack.push_back({n.child[k], c.x0 + ((k & 1) ? h : 0), c.y0 + ((k & 2) ? h : 0), h});
  }
}

EnvelopeAudit auditEnvelopes(std::uint32_t model, const BrdfParams& params, vec3 v, const Tree& tree, int grid, bool lowerDisc) {
  return auditEnvelopes(model, params, v, tree.nodes.data(), tree.leaves.data(), tree.root, tree.mass, grid, lowerDisc);
}

EnvelopeAudit auditEnvelopes(std::uint32_t model, const BrdfParams& params, vec3 v, const QuadNode* nodes, const QuadLeaf* leaves,
                             std::uint32_t root, double mass, int grid, bool lowerDisc) {
  const float side = lowerDisc ? -1.0f : 1.0f;
  EnvelopeAudit a;
  if (root == QT_EMPTY) return a;
  const bool aniso = modelTraits(model, params).anisotropic;
  forEachLeaf(nodes, leaves, root, aniso,
              [&](std::uint32_t, const QuadLeaf& L, double x0, double y0, double size) {
                if (L.data.y < 1e-20 * mass) return;
                ++a.leaves;
                const std::uint32_t kind = std::uint32_t(L.data.z + 0.5f);
                const double A = L.data.x, s = L.data.w, k1 = L.env.x, k2 = L.env.y, B = L.env.z;
                double worst = 0;
                for (int i = 0; i <= grid; ++i)
                  for (int j = 0; j <= grid; ++j) {
                    double t1 = double(i) / grid, t2 = double(j) / grid, x, y, c;
                    bool square = kind == QT_PROPOSAL_SQUARE;
                    if (!proposalPoint(int(kind), square ? x0 : L.box.x, square ? x0 + size : L.box.y, square ? y0 : L.box.z,
                                       square ? y0 + size : L.box.w, x0, x0 + size, y0, y0 + size, t1, t2, x, y, c))
                      continue;
                    double e = envelopeAt(A, k1, k2, B, s, t1, t2, c);
                    double f = quadEvalLum(model, params, vec3(float(x), float(y), side * float(c)), v);
                    ++a.evaluations;
                    if (f > 0) worst = std::max(worst, e > 0 ? f / e : INFINITY);
                  }
                a.worst = std::max(a.worst, worst);
                if (worst > 1) {
                  ++a.leavesAbove;
                  a.massAbove += L.data.y;
                }
              });
  return a;
}

Tree buildTree(std::uint32_t model, const BrdfParams& params, vec3 v, const BuildSettings& settings) {
  // Isotropic sets tabulate v at azimuth 0, where f(., v) is symmetric in w.y: the half disc.
  bool half = !modelTraits(model, params).anisotropic;
  if (half && v.y != 0.0f) throw std::invalid_argument("quadtree::buildTree: isotropic model with v.y != 0");
  Builder b(model, params, v, half, settings);
  return b.build();
}

}  // namespace nusselt::quadtree
