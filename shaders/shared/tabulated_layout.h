// tabulated_layout.h: the tables of the `tabulated` BSDF sampling strategy (SAMPLER_TABULATED), as
// the CPU writes them (src/sampling/tabulated.cpp) and the shared sampler reads them
// (shaders/shared/tabulated.h). All tables of a render share three buffers:
//   TabSet    one per material sampled by tables: its tables, their grid and cell counts
//   TabTable  one per tabulated known direction (incident polar angle, and azimuth when anisotropic)
//   floats    the CDFs of every table, one array (the existing Floats buffer reference type)
// docs/strategies.md describes the method.
#ifndef NUSSELT_TABULATED_LAYOUT_H
#define NUSSELT_TABULATED_LAYOUT_H
#include "prelude.h"
SHARED_BEGIN

// Set flags: as QT_SET_ANISOTROPIC (the known direction is reflected into the first quadrant and
// phi tables cover [0, 90 deg]); isotropic sets rotate it to azimuth 0.
#define TB_SET_ANISOTROPIC 1u
// Bound of the binary searches (lavapipe truncates loops silently: every loop is bounded); 2^32
// cells per row or rows per table would be needed to reach it.
#define TB_MAX_SEARCH 32u

// Tables of a set: table(k_theta, j_phi) = first + k_theta * phiTables + j_phi.
// info = (first table, tables along theta, tables along phi (1: isotropic), flags);
// grid = (rows nu (equal-area rings in u = sin^2 theta of the sampled direction), columns np
//         (sectors in phi over [0, 2 pi)), 0, 0);
// data = (defensive cosine fraction epsilon, theta step (radians), phi step (radians), 0).
struct TabSet {
  uvec4 info;
  uvec4 grid;
  vec4 data;
};
STATIC_ASSERT_SIZE(TabSet, 48);

// info = (offset of its CDFs in the float array, 1 if the table has mass (else: cosine only), 0, 0);
// data = (directional albedo of the luminance of f estimated on the grid (Simpson), cos theta_k,
//         sin theta_k, phi_k) of the table's known direction (canonical frame).
// CDFs at offset o: marginal[i] = P(row <= i), i < nu (the last is exactly 1), then
// conditional[i * np + j] = P(column <= j | row i) (the last of each row exactly 1).
struct TabTable {
  uvec4 info;
  vec4 data;
};
STATIC_ASSERT_SIZE(TabTable, 32);

SHARED_END
#endif
