// quadtree_layout.h: the flattened disc quadtrees of the generic sampler (Montes et al. 2008),
// as the CPU writes them and the GPU reads them. All trees of a render share four buffers:
//   QuadSet   one per (material) that is sampled by quadtrees: its tables and their grid
//   QuadTable one per tree (incident direction): root node and total mass (the albedo)
//   QuadNode  inner nodes: the masses of the four children and links to them
//   QuadLeaf  leaves: the bound M of f over the leaf, its mass, its proposal
#ifndef NUSSELT_QUADTREE_LAYOUT_H
#define NUSSELT_QUADTREE_LAYOUT_H
#include "prelude.h"
SHARED_BEGIN

// child[c] with this bit set is a leaf index; otherwise an inner node index.
#define QT_LEAF_BIT 0x80000000u
// A child with no mass (outside the disc, or f = 0 there) is never chosen; it links here.
#define QT_EMPTY 0xffffffffu

// The four children of a node over [x0, x1] x [y0, y1] with midpoints xm, ym:
// c = 0: [x0, xm] x [y0, ym], 1: [xm, x1] x [y0, ym], 2: [x0, xm] x [ym, y1], 3: [xm, x1] x [ym, y1].
struct QuadNode {
  vec4 mass;    // integral of f over each child (disc measure)
  uvec4 child;  // inner node index, QT_LEAF_BIT | leaf index, or QT_EMPTY
};
STATIC_ASSERT_SIZE(QuadNode, 32);

// data = (A: the envelope's constant part, mass: integral of f over the leaf and the disc,
//         proposal kind (QT_PROPOSAL_*, as a float), rim exponent s);
// box = rim proposal only: the polar box of (leaf square & disc): (cos theta at its inner
//       radius, first azimuth, azimuth width, B: the envelope's cos^-s coefficient).
// Envelope e = A (+ B cos^-s for rim leaves) >= f over (leaf & disc).
#define QT_PROPOSAL_UNIFORM 0u  // uniform point in the leaf square, accept with f / A
// Leaves cut by the rim: proposal over the polar box of (square & disc), r in [r_a, 1],
// phi in [phi_a, phi_a + dphi], with disc density ~ A + B cos^-s (s = 0 and B = 0 for models
// bounded on the disc; s > 0 for f ~ cos^-s at the horizon: ward92 1/2, duer 1, minnaert 1-k,
// schlick (multiple) 1, beard_maxwell 1, strauss 1); points outside the square are discarded
// before f is evaluated; accept with f / e. docs/sampler.md.
#define QT_PROPOSAL_RIM 1u
struct QuadLeaf {
  vec4 data;
  vec4 box;
};
STATIC_ASSERT_SIZE(QuadLeaf, 32);

// info = (root node or QT_LEAF_BIT | leaf, bits of cos phi, bits of sin phi, 0);
// data = (total mass = directional albedo of the luminance of f, cos theta of the table's fixed
// direction, phi of it, sin theta). The fixed direction is quadTableDirection(): the builder and
// the sampler use the same float vector.
struct QuadTable {
  uvec4 info;
  vec4 data;
};
STATIC_ASSERT_SIZE(QuadTable, 32);

// Set flags: anisotropic sets tabulate phi in [0, 90 deg] and use the mirror symmetries x -> -x,
// y -> -y (applied to both directions); isotropic sets rotate the known direction to phi = 0.
#define QT_SET_ANISOTROPIC 1u
// Trial cap of the in-leaf rejection loop (lavapipe truncates loops silently: every loop is
// bounded). A trial is one proposal draw: discarded outside (leaf & disc) with probability about
// 1/2 at most, then accepted with probability >= 1/n_max = 1/2 in uncapped leaves, so a failure
// has probability <= (3/4)^256 = 1e-32 there; capped leaves (measured, docs/sampler.md) can fail.
#define QT_MAX_TRIALS 256u
// Bound of the tree descent loop (the builder's depth cap is far below).
#define QT_MAX_DESCENT 32u
// Tables of a set: table(k_theta, j_phi) = first + k_theta * phiTables + j_phi.
// info = (first table, tables along theta, tables along phi (1: isotropic), flags);
// data = (defensive cosine fraction epsilon, theta step (radians), phi step (radians), 0)
struct QuadSet {
  uvec4 info;
  vec4 data;
};
STATIC_ASSERT_SIZE(QuadSet, 32);

SHARED_END
#endif
