// distribution2d.h: a piecewise-constant 2-D distribution over [0,1)^2 on a grid of nx x ny
// cells, sampled by inverting a marginal CDF (over rows) and the conditional CDF of the chosen
// row (pbrt-v3 Distribution2D; Pharr, Jakob, Humphreys, "Physically Based Rendering", 3rd ed.,
// section 13.6.7). Shared by the CPU (builder, tests) and the GPU (environment light).
//
// Data (one float array, `d` below), for weights f(x, y) >= 0 of cell x of row y:
//   [y * (nx + 1) + x], x = 0..nx: the conditional CDF of row y (0 first, 1 last; a row without
//                                  mass gets the uniform CDF),
//   [ny * (nx + 1) + y], y = 0..ny: the marginal CDF over rows (0 first, 1 last).
// Cell probabilities are differences of these CDFs, so the density evaluated (dist2dPdf) is
// exactly the one the search draws from, whatever the rounding of the build. Density per unit
// area of [0,1)^2: P(row) P(cell | row) nx ny.
//
// Buffer access: GLSL passes a Floats buffer reference (layout.h), C++ a const float pointer.
#ifndef NUSSELT_DISTRIBUTION2D_H
#define NUSSELT_DISTRIBUTION2D_H
#include "layout.h"  // GLSL: the Floats buffer reference

#ifdef __cplusplus
SHARED_BEGIN
typedef const float* Dist2dData;
SHARED_END
#define DIST2D_AT(d, i) (d[i])
#else
#define Dist2dData Floats
#define DIST2D_AT(d, i) (d.v[i])
#endif

SHARED_BEGIN

// Binary searches: enough for 2^32 entries (a loop bound, not a tunable).
#define DIST2D_MAX_SEARCH 33u

// Floats the data of an nx x ny distribution takes.
SHARED_FN uint dist2dSize(uint nx, uint ny) { return ny * (nx + 1u) + ny + 1u; }

// Largest i in [0, n) with cdf[base + i] <= x, for a CDF of n + 1 entries (cdf[base] = 0 <= x <
// 1 = cdf[base + n]); entries with zero probability are never returned when x < 1.
SHARED_FN uint dist2dSearch(Dist2dData d, uint base, uint n, float x) {
  uint lo = 0u;
  uint hi = n;  // invariant: cdf[lo] <= x < cdf[hi]
  for (uint it = 0u; it < DIST2D_MAX_SEARCH; ++it) {
    if (lo + 1u >= hi) break;
    uint mid = (lo + hi) / 2u;
    if (DIST2D_AT(d, base + mid) <= x) lo = mid;
    else hi = mid;
  }
  return lo;
}

// Probability of cell (x, y): P(row y) P(x | y).
SHARED_FN float dist2dCellProbability(Dist2dData d, uint nx, uint ny, uint x, uint y) {
  uint m = ny * (nx + 1u);
  float pRow = DIST2D_AT(d, m + y + 1u) - DIST2D_AT(d, m + y);
  uint c = y * (nx + 1u);
  float pCell = DIST2D_AT(d, c + x + 1u) - DIST2D_AT(d, c + x);
  return pRow * pCell;
}

// Density per unit area at the point p of [0,1)^2 (0 outside).
SHARED_FN float dist2dPdf(Dist2dData d, uint nx, uint ny, vec2 p) {
  if (!(p.x >= 0.0f && p.x < 1.0f && p.y >= 0.0f && p.y < 1.0f)) return 0.0f;
  uint x = min(uint(p.x * float(nx)), nx - 1u);
  uint y = min(uint(p.y * float(ny)), ny - 1u);
  return dist2dCellProbability(d, nx, ny, x, y) * float(nx) * float(ny);
}

// A point of [0,1)^2 from u in [0,1)^2, with its density per unit area (0: the distribution has
// no mass; the point is then meaningless). cell = (x, y) of the point.
SHARED_FN vec2 dist2dSample(Dist2dData d, uint nx, uint ny, vec2 u, OUT(float) pdf, OUT(uvec2) cell) {
  uint m = ny * (nx + 1u);
  uint y = dist2dSearch(d, m, ny, u.y);
  float r0 = DIST2D_AT(d, m + y);
  float pRow = DIST2D_AT(d, m + y + 1u) - r0;
  uint c = y * (nx + 1u);
  uint x = dist2dSearch(d, c, nx, u.x);
  float c0 = DIST2D_AT(d, c + x);
  float pCell = DIST2D_AT(d, c + x + 1u) - c0;
  pdf = pRow * pCell * float(nx) * float(ny);
  cell = uvec2(x, y);
  // Position inside the cell: the remainder of u, rescaled (kept inside the cell against rounding).
  float fy = pRow > 0.0f ? clamp((u.y - r0) / pRow, 0.0f, NUSSELT_ONE_MINUS_EPS) : 0.5f;
  float fx = pCell > 0.0f ? clamp((u.x - c0) / pCell, 0.0f, NUSSELT_ONE_MINUS_EPS) : 0.5f;
  return vec2((float(x) + fx) / float(nx), (float(y) + fy) / float(ny));
}

SHARED_END
#endif
