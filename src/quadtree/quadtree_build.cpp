// quadtree_build.cpp: one disc quadtree per known direction (Montes et al. 2008).
//
// Root: the square [-1, 1]^2, f = 0 outside the disc. A node is split into four while
// n_max I / V < 1 (I = integral of f over the node, V = M x proposal area, M an upper bound of
// f on the node) or while its integral is not converged (|Q(node) - sum Q(children)| too large).
// Integrals: tensor Gauss-Legendre on cells inside the disc; on cells cut by the rim, columns
// split at the rim crossings with end-clustering substitutions (distance to the rim ~ t^4), which
// make the rim singularities f ~ cos^-s (s <= 1) smooth, with cos computed from the exact distance
// to the rim (no cancellation). Bounds: the maximum over the node's 4 x 25 Gauss points, a 5 x 5
// boundary grid, points on the rim arc, and the point of the node nearest to each known peak of
// the model (mirror direction, normal, rim points, lobe axes, ridge), times a margin.
#include "quadtree/quadtree_build.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace nusselt::quadtree {

using namespace shared;

ModelTraits modelTraits(std::uint32_t model, const BrdfParams& p) {
  ModelTraits t;
  switch (model) {
    case MODEL_WARD: {
      std::uint32_t norm = std::uint32_t(brdfParam(p, WARD_NORMALIZATION) + 0.5f);
      t.rimExponent = norm == WARD_NORM_WARD92 ? 0.5f : (norm == WARD_NORM_DUER ? 1.0f : 0.0f);
      t.anisotropic = brdfParam(p, WARD_AX) != brdfParam(p, WARD_AY);
      break;
    }
    case MODEL_MINNAERT: t.rimExponent = std::max(0.0f, 1.0f - brdfParam(p, MINNAERT_K)); break;
    case MODEL_SCHLICK:
      t.rimExponent = brdfParam(p, SCHLICK_MULTIPLE) > 0.5f ? 1.0f : 0.0f;
      t.anisotropic = brdfParam(p, SCHLICK_P) < 1.0f;
      break;
    case MODEL_BEARD_MAXWELL: t.rimExponent = 1.0f; break;
    // strauss' specular term carries 1 / cos(theta_i) of the SAMPLED direction (it is not
    // reciprocal): f(., v) ~ 1 / cos at the rim wherever the lobe reaches it.
    case MODEL_STRAUSS: t.rimExponent = 1.0f; break;
    case MODEL_ASHIKHMIN_SHIRLEY:
      t.anisotropic = brdfParam(p, ASHIKHMIN_SHIRLEY_NU) != brdfParam(p, ASHIKHMIN_SHIRLEY_NV);
      break;
    case MODEL_LAFORTUNE: {
      std::uint32_t count = std::uint32_t(brdfParam(p, LAFORTUNE_LOBE_COUNT) + 0.5f);
      for (std::uint32_t j = 0; j < count; ++j) {
        std::uint32_t o = LAFORTUNE_LOBES + 4 * j;
        if (brdfParam(p, o) != brdfParam(p, o + 1)) t.anisotropic = true;
      }
      break;
    }
    case MODEL_POULIN_FOURNIER: t.anisotropic = true; break;
    default: break;
  }
  return t;
}

namespace {

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
const Gauss& gaussInterior() { static const Gauss g(5); return g; }
const Gauss& gaussRim() { static const Gauss g(8); return g; }

// A point of a 1D rule on [a, b]: position, weight, distances to a and to b (exact, also when
// tiny: the rim substitutions need them to compute cos without cancellation).
struct RulePoint {
  double pos, weight, da, db;
};

// Symmetric clustering map on [-1, 1] with P'(t) = 35/32 (1 - t^2)^3: distance to an end ~ (1-t)^4.
double clusterP(double t) { return (35.0 / 16.0) * (t - t * t * t + 0.6 * std::pow(t, 5) - std::pow(t, 7) / 7.0); }
double clusterDP(double t) { double s = 1 - t * t; return (35.0 / 32.0) * 2.0 * s * s * s; }

void rule1D(double a, double b, bool clusterA, bool clusterB, const Gauss& g, std::vector<RulePoint>& out) {
  out.clear();
  double L = b - a;
  if (L <= 0) return;
  for (std::size_t i = 0; i < g.x.size(); ++i) {
    double t = g.x[i], w = g.w[i];
    RulePoint p;
    if (clusterA && clusterB) {
      double P = clusterP(t);
      p.da = 0.5 * L * (1 + P);
      p.db = 0.5 * L * (1 - P);
      p.weight = w * 0.5 * L * clusterDP(t);
    } else if (clusterA || clusterB) {
      double u = 0.5 * (t + 1);
      double d = L * u * u * u * u;  // distance from the clustered end
      double wt = 0.5 * w * 4 * L * u * u * u;
      if (clusterA) { p.da = d; p.db = L - d; } else { p.db = d; p.da = L - d; }
      p.weight = wt;
    } else {
      p.da = 0.5 * L * (1 + t);
      p.db = 0.5 * L * (1 - t);
      p.weight = 0.5 * L * w;
    }
    p.pos = clusterB && !clusterA ? b - p.db : a + p.da;
    out.push_back(p);
  }
}

struct CellResult {
  double q = 0;     // integral of f over cell and disc
  double area = 0;  // area of (cell & disc)
  double zs = 0;    // integral of cos^-s over (cell & disc): the rim proposal's measure
  double fmax = 0;  // max of f over the points evaluated
  bool anyPositive = false;
  // (f, cos theta) of every point evaluated, kept for models unbounded at the rim (s > 0): the
  // envelope A + B cos^-s is fitted to them (Builder::fitEnvelope).
  std::vector<std::array<float, 2>> pts;
};

class Builder {
 public:
  Builder(std::uint32_t model, const BrdfParams& params, vec3 v, const BuildSettings& s)
      : m_model(model), m_params(params), m_v(v), m_s(s) {
    m_traits = modelTraits(model, params);
    collectPeaks();
  }

  Tree build();

 private:
  std::uint32_t m_model;
  BrdfParams m_params;
  vec3 m_v;
  BuildSettings m_s;
  ModelTraits m_traits;
  std::vector<std::array<double, 2>> m_peaks;  // disc points
  bool m_ridge = false;
  double m_ridgeX = 0;
  std::uint64_t m_evals = 0;
  std::vector<RulePoint> m_rx, m_ry;

  // f at the disc point (x, y) with cos theta = co (co computed by the caller, accurately).
  double eval(double x, double y, double co, CellResult& r) {
    ++m_evals;
    double f = quadEvalLum(m_model, m_params, vec3(float(x), float(y), float(co)), m_v);
    if (f > r.fmax) r.fmax = f;
    if (m_traits.rimExponent > 0) r.pts.push_back({float(f), float(co)});
    if (f > 0) r.anyPositive = true;
    return f;
  }
  void evalPoint(double x, double y, CellResult& r) {
    double r2 = x * x + y * y;
    if (r2 >= 1) return;
    double rr = std::sqrt(r2);
    eval(x, y, std::sqrt((1 - rr) * (1 + rr)), r);
  }

  void collectPeaks();
  void fitEnvelope(const CellResult& r, double area, double zs, double& A, double& B);
  std::vector<std::array<double, 2>> m_fit;
  CellResult integrate(double x0, double x1, double y0, double y1);
  void boundPoints(double x0, double x1, double y0, double y1, CellResult& r);
};

void Builder::collectPeaks() {
  double vx = m_v.x, vy = m_v.y;
  double vr = std::sqrt(vx * vx + vy * vy);
  m_peaks.push_back({0.0, 0.0});   // normal
  m_peaks.push_back({-vx, -vy});   // mirror direction R(v)
  if (vr > 1e-9) {
    m_peaks.push_back({-vx / vr, -vy / vr});  // rim, forward
    m_peaks.push_back({vx / vr, vy / vr});    // rim, back-scatter
    m_peaks.push_back({vx, vy});              // retro direction
  } else {
    for (int k = 0; k < 8; ++k) m_peaks.push_back({std::cos(k * M_PI / 4), std::sin(k * M_PI / 4)});
  }
  if (m_model == MODEL_LAFORTUNE) {
    std::uint32_t count = std::uint32_t(brdfParam(m_params, LAFORTUNE_LOBE_COUNT) + 0.5f);
    for (std::uint32_t j = 0; j < count && j < LAFORTUNE_MAX_LOBES; ++j) {
      std::uint32_t o = LAFORTUNE_LOBES + 4 * j;
      double ax = brdfParam(m_params, o) * m_v.x, ay = brdfParam(m_params, o + 1) * m_v.y,
             az = brdfParam(m_params, o + 2) * m_v.z;
      double n = std::sqrt(ax * ax + ay * ay + az * az);
      if (n <= 0) continue;
      double hr = std::sqrt(ax * ax + ay * ay);
      if (az > 0) m_peaks.push_back({ax / n, ay / n});
      else if (hr > 0) m_peaks.push_back({ax / hr, ay / hr});
    }
  }
  if (m_model == MODEL_POULIN_FOURNIER) {
    m_ridge = true;  // reflection cone of the cylinder axis (x): w.x = -v.x
    m_ridgeX = -vx;
  }
}

// Integral of f over [x0,x1] x [y0,y1] intersected with the disc.
CellResult Builder::integrate(double x0, double x1, double y0, double y1) {
  CellResult r;
  double cx = std::clamp(0.0, x0, x1), cy = std::clamp(0.0, y0, y1);
  double rmin2 = cx * cx + cy * cy;
  if (rmin2 >= 1) return r;
  double fx = std::max(std::abs(x0), std::abs(x1)), fy = std::max(std::abs(y0), std::abs(y1));
  double rmax2 = fx * fx + fy * fy;
  if (rmax2 <= 1) {
    const Gauss& g = gaussInterior();
    double hx = 0.5 * (x1 - x0), hy = 0.5 * (y1 - y0);
    for (std::size_t i = 0; i < g.x.size(); ++i)
      for (std::size_t j = 0; j < g.x.size(); ++j) {
        double x = x0 + hx * (1 + g.x[i]), y = y0 + hy * (1 + g.x[j]);
        double rr = std::sqrt(x * x + y * y);
        double co = std::sqrt((1 - rr) * (1 + rr));
        double w = g.w[i] * g.w[j] * hx * hy;
        r.q += w * eval(x, y, co, r);
        if (m_traits.rimExponent > 0) r.zs += w * std::pow(co, -double(m_traits.rimExponent));
      }
    r.area = (x1 - x0) * (y1 - y0);
    if (m_traits.rimExponent == 0) r.zs = r.area;
    return r;
  }
  // Cut by the rim: split x at the rim crossings of the horizontal edges.
  double bps[6];
  int nb = 0;
  bps[nb++] = std::max(x0, -1.0);
  bps[nb++] = std::min(x1, 1.0);
  for (double ye : {y0, y1}) {
    if (std::abs(ye) >= 1) continue;
    double xc = std::sqrt((1 - ye) * (1 + ye));
    for (double s : {-xc, xc})
      if (s > x0 && s < x1) bps[nb++] = s;
  }
  for (int i = 1; i < nb; ++i)  // insertion sort (at most 6 values)
    for (int j = i; j > 0 && bps[j] < bps[j - 1]; --j) std::swap(bps[j], bps[j - 1]);
  const Gauss& g = gaussRim();
  for (int k = 0; k + 1 < nb; ++k) {
    double xa = bps[k], xb = bps[k + 1];
    if (xb - xa <= 0) continue;
    double xm = 0.5 * (xa + xb);
    if (std::abs(xm) >= 1) continue;
    double hm = std::sqrt((1 - xm) * (1 + xm));
    if (-hm >= y1 || hm <= y0) continue;  // columns outside the disc
    bool loRim = -hm > y0, hiRim = hm < y1;
    bool anyRim = loRim || hiRim;
    bool clA = anyRim && (xa != x0 || std::abs(xa) == 1.0);
    bool clB = anyRim && (xb != x1 || std::abs(xb) == 1.0);
    rule1D(xa, xb, clA, clB, g, m_rx);
    for (const RulePoint& px : m_rx) {
      double x = px.pos;
      // 1 - x^2 from the exact distance to x = +-1 when that end is clustered.
      double h2;
      if (clA && xa == -1.0) h2 = px.da * (2 - px.da);
      else if (clB && xb == 1.0) h2 = px.db * (2 - px.db);
      else h2 = (1 - x) * (1 + x);
      if (h2 <= 0) continue;
      double h = std::sqrt(h2);
      double lo = loRim ? -h : y0, hi = hiRim ? h : y1;
      if (hi <= lo) continue;
      rule1D(lo, hi, loRim, hiRim, g, m_ry);
      for (const RulePoint& py : m_ry) {
        double y = py.pos;
        double dHi = hiRim ? py.db : h - y;
        double dLo = loRim ? py.da : y + h;
        double co2 = dHi * dLo;
        if (co2 <= 0) continue;
        double co = std::sqrt(co2), w = px.weight * py.weight;
        r.q += w * eval(x, y, co, r);
        r.area += w;
        r.zs += w * std::pow(co, -double(m_traits.rimExponent));
      }
    }
  }
  return r;
}

// Extra points for the bound: a 5 x 5 grid on the cell (edges and corners), the rim arc, the
// point of the cell nearest to each peak, and the ridge line.
void Builder::boundPoints(double x0, double x1, double y0, double y1, CellResult& r) {
  // poulin_fournier's cylinder ridge is a fold that the Gauss points straddle: a 5 x 5 grid let
  // 42 of 200k samples exceed M (test case theta 37.3, phi 20), 17 x 17 none.
  const int G = m_ridge ? 16 : 4;
  for (int i = 0; i <= G; ++i)
    for (int j = 0; j <= G; ++j) evalPoint(x0 + (x1 - x0) * i / G, y0 + (y1 - y0) * j / G, r);
  for (const auto& pk : m_peaks) {
    double px = std::clamp(pk[0], x0, x1), py = std::clamp(pk[1], y0, y1);
    double r2 = px * px + py * py;
    if (r2 >= 1) {  // nearest point inside the disc: pull onto the rim, slightly inside
      double s = (1 - 1e-7) / std::sqrt(r2);
      px *= s;
      py *= s;
      if (px < x0 || px > x1 || py < y0 || py > y1) continue;
    }
    evalPoint(px, py, r);
  }
  if (m_ridge && m_ridgeX >= x0 && m_ridgeX <= x1)
    for (int j = 0; j <= 8; ++j) evalPoint(m_ridgeX, y0 + (y1 - y0) * j / 8, r);
  // Rim arc inside the cell: cos theta = 1e-3 and 1e-6.
  double fx = std::max(std::abs(x0), std::abs(x1)), fy = std::max(std::abs(y0), std::abs(y1));
  double cx = std::clamp(0.0, x0, x1), cy = std::clamp(0.0, y0, y1);
  if (fx * fx + fy * fy > 1 && cx * cx + cy * cy < 1) {
    for (int k = 0; k < 64; ++k) {
      double ph = 2 * M_PI * (k + 0.5) / 64;
      for (double co : {1e-3, 1e-6}) {
        double rr = std::sqrt((1 - co) * (1 + co));
        double x = rr * std::cos(ph), y = rr * std::sin(ph);
        if (x >= x0 && x <= x1 && y >= y0 && y <= y1) eval(x, y, co, r);
      }
    }
    // and the arc's end points on the cell edges
    for (double ye : {y0, y1})
      if (std::abs(ye) < 1) {
        double xc = std::sqrt((1 - ye) * (1 + ye));
        for (double s : {-xc, xc})
          if (s >= x0 && s <= x1) evalPoint(s * (1 - 1e-7), ye * (1 - 1e-7), r);
      }
    for (double xe : {x0, x1})
      if (std::abs(xe) < 1) {
        double yc = std::sqrt((1 - xe) * (1 + xe));
        for (double s : {-yc, yc})
          if (s >= y0 && s <= y1) evalPoint(xe * (1 - 1e-7), s * (1 - 1e-7), r);
      }
  }
}

// The envelope e = A + B cos^-s of a cell cut by the rim (s > 0: f ~ cos^-s at the horizon) with
// the smallest volume V = A area + B zs subject to e >= margin f at every point evaluated in the
// cell (its quadrature points, its children's, the bound points incl. the rim arc at cos 1e-6).
// B = 0 where f stays bounded up to the rim (a pure cos^-s proposal would then accept only ~1/2:
// f cos^s vanishes linearly at the rim), A = 0 where f is purely singular; mixtures in between.
// V(B) = area h(B) + zs B with h(B) = max_i (F_i - B c_i)^+ is convex: golden-section search.
void Builder::fitEnvelope(const CellResult& r, double area, double zs, double& A, double& B) {
  const double s = m_traits.rimExponent, margin = m_s.boundMargin;
  std::vector<std::array<double, 2>>& fc = m_fit;  // (F_i, c_i = cos_i^-s)
  fc.clear();
  double bMax = 0;
  for (const auto& p : r.pts)
    if (p[1] > 0 && p[0] > 0) {
      double c = std::pow(double(p[1]), -s);
      fc.push_back({margin * double(p[0]), c});
      bMax = std::max(bMax, fc.back()[0] / c);
    }
  auto hOf = [&](double b) {
    double m = 0;
    for (const auto& p : fc) m = std::max(m, p[0] - b * p[1]);
    return m;
  };
  auto vOf = [&](double b) { return area * hOf(b) + zs * b; };
  double lo = 0, hi = bMax;
  const double gr = 0.5 * (std::sqrt(5.0) - 1);
  double b1 = hi - gr * (hi - lo), b2 = lo + gr * (hi - lo);
  double v1 = vOf(b1), v2 = vOf(b2);
  for (int it = 0; it < 48 && hi - lo > 1e-9 * bMax; ++it) {
    if (v1 <= v2) { hi = b2; b2 = b1; v2 = v1; b1 = hi - gr * (hi - lo); v1 = vOf(b1); }
    else { lo = b1; b1 = b2; v1 = v2; b2 = lo + gr * (hi - lo); v2 = vOf(b2); }
  }
  double best = v1 <= v2 ? b1 : b2, vBest = std::min(v1, v2);
  for (double b : {0.0, bMax})
    if (vOf(b) < vBest) { vBest = vOf(b); best = b; }
  B = best;
  A = hOf(best);
  // The fmax of points without a stored cos (none today) still bounds f: keep A >= 0, B >= 0.
  A = std::max(A, 0.0);
}

// Polar box of (cell & disc): r in [r_a, 1] (cos theta in [0, coA]), phi in [pa, pa + dp], padded
// so that it surely covers the region; z = integral of cos^-s over the box (disc measure), the
// proposal's area measure. Angles from the inside corners and the rim crossings of the edges.
struct PolarBox {
  float coA = 1, pa = 0, dp = float(2 * M_PI);
};
PolarBox polarBox(double x0, double x1, double y0, double y1) {
  PolarBox b;
  double cx = std::clamp(0.0, x0, x1), cy = std::clamp(0.0, y0, y1);
  double ra = std::sqrt(cx * cx + cy * cy);
  // Azimuth range about the cell's centre direction; only a cell with the disc centre strictly
  // inside (the root) needs the full circle. A corner at the centre (the root's children) has
  // no azimuth and is skipped: its range comes from the edges' rim crossings.
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
      if (r2 < 1 && r2 > 0) add(px, py);
    }
    for (double xe : {x0, x1})
      if (std::abs(xe) < 1) {
        double yc = std::sqrt((1 - xe) * (1 + xe));
        for (double y : {-yc, yc})
          if (y >= y0 && y <= y1) add(xe, y);
      }
    for (double ye : {y0, y1})
      if (std::abs(ye) < 1) {
        double xc = std::sqrt((1 - ye) * (1 + ye));
        for (double x : {-xc, xc})
          if (x >= x0 && x <= x1) add(x, ye);
      }
    if (hi >= lo) {
      b.pa = float(pc + lo - 1e-6);
      b.dp = float(hi - lo + 2e-6);
    }
  }
  b.coA = float(std::min(1.0, std::sqrt(std::max(0.0, (1 - ra) * (1 + ra))) * (1 + 1e-6) + 1e-7));
  return b;
}

struct Item {
  float x0, y0, size;
  std::uint32_t depth;
  std::uint32_t parent, slot;  // parent node (QT_EMPTY for the root)
  CellResult res;
};

Tree Builder::build() {
  Tree tree;
  std::vector<Item> stack;
  Item root{-1.0f, -1.0f, 2.0f, 0, QT_EMPTY, 0, integrate(-1, 1, -1, 1)};
  double aEst = -1, running = 0;
  stack.push_back(root);
  const float s = m_traits.rimExponent;
  while (!stack.empty()) {
    Item it = std::move(stack.back());
    stack.pop_back();
    double x0 = it.x0, y0 = it.y0, h = 0.5 * it.size;
    CellResult child[4];
    CellResult all = std::move(it.res);
    double parentQ = all.q;
    double sumq = 0, area = 0, zs = 0;
    for (int c = 0; c < 4; ++c) {
      double cx0 = x0 + ((c & 1) ? h : 0), cy0 = y0 + ((c & 2) ? h : 0);
      child[c] = integrate(cx0, cx0 + h, cy0, cy0 + h);
      sumq += child[c].q;
      area += child[c].area;
      zs += child[c].zs;
      all.fmax = std::max(all.fmax, child[c].fmax);
      all.anyPositive = all.anyPositive || child[c].anyPositive;
      all.pts.insert(all.pts.end(), child[c].pts.begin(), child[c].pts.end());
    }
    // Running estimate of the total (leaves so far + pending cells): the scale of the absolute
    // tolerances. A lobe missed by the root's quadrature raises it as soon as it is resolved.
    if (aEst < 0) { aEst = std::max(sumq, parentQ); running = sumq; }
    else running += sumq - parentQ;
    aEst = std::max(aEst, running);
    boundPoints(x0, x0 + it.size, y0, y0 + it.size, all);

    auto link = [&](std::uint32_t value) {
      if (it.parent == QT_EMPTY) tree.root = value;
      else tree.nodes[it.parent].child[it.slot] = value;
    };
    if (!all.anyPositive) {  // f = 0 at every point evaluated, peaks included
      link(QT_EMPTY);
      ++tree.stats.emptyChildren;
      continue;
    }
    float fx = std::max(std::abs(it.x0), std::abs(it.x0 + it.size)),
          fy = std::max(std::abs(it.y0), std::abs(it.y0 + it.size));
    // Envelope e >= f on R = (cell & disc); V = integral of e over R. Cells inside the disc:
    // e = M, proposal uniform in the square. Cells cut by the rim: e = A + B cos^-s, proposal the
    // polar box of R (points outside the cell rejected before f is evaluated), so V is measured on
    // R itself, not on the box: a square cut diagonally by the rim no longer pays for the part of
    // its proposal outside the disc, and acceptance I / V tends to 1 / margin as cells shrink.
    bool cut = fx * fx + fy * fy > 1.0f;
    double A = m_s.boundMargin * all.fmax, B = 0, V;
    PolarBox box;
    if (cut) {
      box = polarBox(it.x0, it.x0 + it.size, it.y0, it.y0 + it.size);
      if (s > 0) fitEnvelope(all, area, zs, A, B);
      V = A * area + B * zs;
    } else {
      V = A * double(it.size) * double(it.size);
    }
    bool rim = cut;
    double M = A;
    bool accurate = std::abs(parentQ - sumq) <= std::max(m_s.relTol * sumq, m_s.absTol * aEst);
    bool accepts = m_s.nMax * sumq >= V;
    // Tail cells (negligible mass) stop refining even when their acceptance is below 1/n_max.
    bool tail = sumq < m_s.tailTol * aEst;
    if ((accurate && (accepts || tail)) || it.depth >= m_s.maxDepth) {
      if (sumq <= 0) {
        link(QT_EMPTY);
        ++tree.stats.emptyChildren;
        continue;
      }
      QuadLeaf leaf;
      leaf.data = vec4(float(M), float(sumq), rim ? float(QT_PROPOSAL_RIM) : float(QT_PROPOSAL_UNIFORM), rim ? s : 0.0f);
      leaf.box = rim ? vec4(box.coA, box.pa, box.dp, float(B)) : vec4(0.0f);
      link(QT_LEAF_BIT | std::uint32_t(tree.leaves.size()));
      tree.leaves.push_back(leaf);
      tree.stats.leaves++;
      if (!accepts) {
        if (tail) tree.stats.tailLeaves++;
        else tree.stats.cappedLeaves++;
        tree.stats.lowAcceptanceMass += sumq;
      }
      if (rim) tree.stats.rimLeaves++;
      tree.stats.maxDepth = std::max(tree.stats.maxDepth, it.depth);
      if (!tail || accepts) tree.stats.minAcceptance = std::min(tree.stats.minAcceptance, V > 0 ? sumq / V : 1.0);
      continue;
    }
    std::uint32_t index = std::uint32_t(tree.nodes.size());
    QuadNode node;
    node.mass = vec4(0.0f);
    node.child = uvec4(QT_EMPTY);
    tree.nodes.push_back(node);
    link(index);
    for (int c = 3; c >= 0; --c) {
      float hh = 0.5f * it.size;
      Item ch{it.x0 + ((c & 1) ? hh : 0.0f), it.y0 + ((c & 2) ? hh : 0.0f), hh, it.depth + 1, index,
              std::uint32_t(c), std::move(child[c])};
      stack.push_back(ch);
    }
  }
  // Masses, bottom-up: children are created after their parents.
  std::vector<double> nodeMass(tree.nodes.size(), 0.0);
  for (std::size_t i = tree.nodes.size(); i-- > 0;) {
    QuadNode& n = tree.nodes[i];
    double total = 0;
    for (int c = 0; c < 4; ++c) {
      std::uint32_t ch = n.child[c];
      double m = 0;
      if (ch == QT_EMPTY) m = 0;
      else if (ch & QT_LEAF_BIT) m = tree.leaves[ch & ~QT_LEAF_BIT].data.y;
      else m = nodeMass[ch];
      n.mass[c] = float(m);
      total += m;
    }
    nodeMass[i] = total;
  }
  if (tree.root == QT_EMPTY) tree.mass = 0;
  else if (tree.root & QT_LEAF_BIT) tree.mass = tree.leaves[tree.root & ~QT_LEAF_BIT].data.y;
  else tree.mass = nodeMass[tree.root];
  tree.stats.nodes = std::uint32_t(tree.nodes.size());
  tree.stats.evaluations = m_evals;
  return tree;
}

}  // namespace

Tree buildTree(std::uint32_t model, const BrdfParams& params, vec3 v, const BuildSettings& settings) {
  Builder b(model, params, v, settings);
  return b.build();
}

}  // namespace nusselt::quadtree
