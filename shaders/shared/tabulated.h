// tabulated.h: the `tabulated` BSDF sampling strategy (SAMPLER_TABULATED), the tabular approach the
// generic-sampling paper compares to: per material and tabulated known direction a piecewise-
// constant density over the unit disc of sampled directions, sampled by inverse CDFs. Shared by the
// CPU (tests, `nusselt sample --cpu`) and the GPU. Layout: tabulated_layout.h; builder:
// src/sampling/tabulated.cpp; method and memory choice: docs/strategies.md.
//
// Domain and density: the sampled direction w = (x, y, z) is the disc point (x, y); the disc is cut
// into nu equal-area rings (u = x^2 + y^2 = sin^2 theta in [i/nu, (i+1)/nu)) times np sectors
// (phi in [2 pi j/np, 2 pi (j+1)/np)): all cells have the disc area pi / (nu np). The table density
// is constant on each cell in disc measure, and the disc measure is cos theta times solid angle,
// so per unit solid angle
//   pdf(w) = ((1 - eps) P(cell of w) nu np / pi + eps / pi) cos theta
// with P(cell) the table's cell probability (proportional to the max of luminance(f(., v_k)) over a
// 3 x 3 point set of the cell) and the defensive cosine fraction eps, which keeps pdf > 0 wherever
// cos theta > 0, hence wherever f > 0, whatever the table missed.
// Known direction: the canonical frame of quadtree.h (isotropic sets rotate wo to azimuth 0,
// anisotropic ones reflect it into the first quadrant), then the NEAREST table in theta (and in
// phi for anisotropic sets). No interpolation between tables: the density used is exactly the one
// of that table, so sampling is unbiased; between tables the fit is only worse.
//
// Buffer access: GLSL reads the buffer references of the Globals `g` (tabSets, tabTables, tabData,
// layout.h); C++ reads host arrays through the
// thread-local TabHost pointer set by TabHostScope (src/sampling/tabulated.h).
#ifndef NUSSELT_TABULATED_H
#define NUSSELT_TABULATED_H
#include "brdf/dispatch.h"
#include "quadtree.h"
#include "tabulated_layout.h"
#include "warp.h"

#ifdef __cplusplus
SHARED_BEGIN
struct TabHost {
  const TabSet* sets = nullptr;
  const TabTable* tables = nullptr;
  const float* data = nullptr;
};
inline thread_local TabHost* g_tabHost = nullptr;
SHARED_END
#define TB_SET(i) (::nusselt::shared::g_tabHost->sets[i])
#define TB_TABLE(i) (::nusselt::shared::g_tabHost->tables[i])
#define TB_DATA(i) (::nusselt::shared::g_tabHost->data[i])
#else
#ifndef TB_SET
#define TB_SET(i) (g.tabSets.v[i])
#define TB_TABLE(i) (g.tabTables.v[i])
#define TB_DATA(i) (g.tabData.v[i])
#endif
#endif

SHARED_BEGIN

// The table of the (canonical) known direction vc: the nearest in theta (and phi if anisotropic).
SHARED_FN uint tabTableIndex(TabSet S, vec3 vc) {
  float theta = portableAtan2(sqrt(vc.x * vc.x + vc.y * vc.y), max(vc.z, 0.0f));
  uint k = min(uint(theta / S.data.y + 0.5f), S.info.y - 1u);
  uint j = 0u;
  if (S.info.z > 1u) {
    float phi = portableAtan2(abs(vc.y), abs(vc.x));
    j = min(uint(phi / S.data.z + 0.5f), S.info.z - 1u);
  }
  return S.info.x + k * S.info.z + j;
}

// Smallest i in [0, count) with cdf[base + i] > x (the cdf's last entry is 1 > x).
SHARED_FN uint tabSearch(uint base, uint count, float x) {
  uint lo = 0u;
  uint hi = count - 1u;
  for (uint it = 0u; it < TB_MAX_SEARCH; ++it) {
    if (lo >= hi) break;
    uint mid = (lo + hi) / 2u;
    if (TB_DATA(base + mid) > x) hi = mid;
    else lo = mid + 1u;
  }
  return lo;
}

// Probability of cell (i, j) of table T (from the CDF differences: exactly what the search draws).
SHARED_FN float tabCellProbability(TabSet S, TabTable T, uint i, uint j) {
  uint o = T.info.x;
  uint nu = S.grid.x;
  uint np = S.grid.y;
  float pr = TB_DATA(o + i) - (i > 0u ? TB_DATA(o + i - 1u) : 0.0f);
  uint c = o + nu + i * np;
  float pc = TB_DATA(c + j) - (j > 0u ? TB_DATA(c + j - 1u) : 0.0f);
  return pr * pc;
}

// Solid-angle density of table T's mixture at the canonical direction wc.
SHARED_FN float tabPdfCanonical(TabSet S, TabTable T, vec3 wc) {
  if (wc.z <= 0.0f) return 0.0f;
  if (T.info.y == 0u) return wc.z * NUSSELT_INV_PI;  // no mass: cosine only
  uint nu = S.grid.x;
  uint np = S.grid.y;
  float u = wc.x * wc.x + wc.y * wc.y;
  uint i = min(uint(u * float(nu)), nu - 1u);
  float phi = portableAtan2(wc.y, wc.x);
  if (phi < 0.0f) phi += NUSSELT_TWO_PI;
  uint j = min(uint(phi * (1.0f / NUSSELT_TWO_PI) * float(np)), np - 1u);
  float eps = S.data.x;
  float cell = tabCellProbability(S, T, i, j) * float(nu) * float(np);
  return ((1.0f - eps) * cell + eps) * wc.z * NUSSELT_INV_PI;
}

// ---- Public interface ---------------------------------------------------------------------------

// Density per unit solid angle with which tabSample draws w for the known direction v (local
// frame); 0 below the surface. For MIS.
SHARED_FN float tabPdf(uint set, vec3 v, vec3 w) {
  if (v.z <= 0.0f || w.z <= 0.0f) return 0.0f;
  TabSet S = TB_SET(set);
  vec4 fr = quadFrame((S.info.w & TB_SET_ANISOTROPIC) != 0u, v);
  TabTable T = TB_TABLE(tabTableIndex(S, quadToCanonical(fr, v)));
  return tabPdfCanonical(S, T, quadToCanonical(fr, w));
}

// The directional albedo (luminance) of the table used for v: the Russian-roulette continuation.
SHARED_FN float tabAlbedo(uint set, vec3 v) {
  TabSet S = TB_SET(set);
  vec4 fr = quadFrame((S.info.w & TB_SET_ANISOTROPIC) != 0u, v);
  return TB_TABLE(tabTableIndex(S, quadToCanonical(fr, v))).data.x;
}

// Draws w for the known direction v (v.z > 0) with density tabPdf (returned in pdf) from two
// uniform numbers in [0, 1): u.y picks the component (defensive cosine or table) and, rescaled,
// the column; u.x the row, rescaled, the position in the cell. Returns false (w = 0, pdf = 0) when
// v is below the surface or the sample lands on the rim (cos theta = 0).
SHARED_FN bool tabSample(uint set, vec3 v, vec2 u, OUT(vec3) w, OUT(float) pdf) {
  w = vec3(0.0f);
  pdf = 0.0f;
  if (v.z <= 0.0f) return false;
  TabSet S = TB_SET(set);
  vec4 fr = quadFrame((S.info.w & TB_SET_ANISOTROPIC) != 0u, v);
  TabTable T = TB_TABLE(tabTableIndex(S, quadToCanonical(fr, v)));
  float eps = T.info.y == 0u ? 1.0f : S.data.x;
  vec3 wc;
  if (u.y < eps) {
    wc = squareToCosineHemisphere(vec2(u.x, min(u.y / eps, NUSSELT_ONE_MINUS_EPS)));
    pdf = tabPdfCanonical(S, T, wc);
  } else {
    uint nu = S.grid.x;
    uint np = S.grid.y;
    uint o = T.info.x;
    float uy = clamp((u.y - eps) / (1.0f - eps), 0.0f, NUSSELT_ONE_MINUS_EPS);
    uint i = tabSearch(o, nu, u.x);
    float lo = i > 0u ? TB_DATA(o + i - 1u) : 0.0f;
    float pr = TB_DATA(o + i) - lo;
    if (!(pr > 0.0f)) return false;
    float x1 = clamp((u.x - lo) / pr, 0.0f, NUSSELT_ONE_MINUS_EPS);
    uint c = o + nu + i * np;
    uint j = tabSearch(c, np, uy);
    float lc = j > 0u ? TB_DATA(c + j - 1u) : 0.0f;
    float pc = TB_DATA(c + j) - lc;
    if (!(pc > 0.0f)) return false;
    float x2 = clamp((uy - lc) / pc, 0.0f, NUSSELT_ONE_MINUS_EPS);
    float uu = (float(i) + x1) / float(nu);
    float phi = NUSSELT_TWO_PI * (float(j) + x2) / float(np);
    float r = sqrt(uu);
    wc = vec3(r * cos(phi), r * sin(phi), sqrt(max(1.0f - uu, 0.0f)));
    pdf = ((1.0f - eps) * pr * pc * float(nu) * float(np) + eps) * wc.z * NUSSELT_INV_PI;
  }
  if (!(wc.z > 0.0f) || !(pdf > 0.0f)) {
    pdf = 0.0f;
    return false;
  }
  w = quadFromCanonical(fr, wc);
  return true;
}

SHARED_END
#endif
