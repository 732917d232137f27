// quadtree_layout.h: the flattened disc quadtrees of the generic sampler (Montes et al. 2008),
// as the CPU writes them and the GPU reads them. All trees of a render share four buffers:
//   QuadSet   one per (material) that is sampled by quadtrees: its tables and their grid
//   QuadTable one per tree (incident direction): root node and total mass (the albedo)
//   QuadNode  inner nodes: the masses of the four children and links to them
//   QuadLeaf  leaves: the envelope of f over the leaf, its mass, its proposal
#ifndef NUSSELT_QUADTREE_LAYOUT_H
#define NUSSELT_QUADTREE_LAYOUT_H
#include "prelude.h"
SHARED_BEGIN

// child[c] with this bit set is a leaf index; otherwise an inner node index.
#define QT_LEAF_BIT 0x80000000u
// A child with no mass (outside the disc, or f = 0 there) is never chosen; it links here.
#define QT_EMPTY 0xffffffffu

// Geometry of a tree (docs/sampler.md): the disc is split into an inner disc r^2 < QT_INNER_R2
// (cos theta > QT_RIM_COS), covered by square cells, and the rim annulus cos theta < QT_RIM_COS,
// covered by polar cells [c0, c1] x [phi0, phi1] (c = cos theta), which resolve lobes that meet
// the horizon (there a lobe of angular width d is only ~d^2 / 2 wide in the disc's radius).
// The table's root node has these children:
//   isotropic sets (f(., v) symmetric in w.y for v at azimuth 0: only the half disc y >= 0 is
//     stored, and the descent mirrors with probability 1/2):
//     0: square [-1, 0] x [0, 1], 1: square [0, 1] x [0, 1], 2: polar phi in [0, pi], 3: empty;
//   anisotropic sets: 0: square [-1, 1]^2, 1: polar phi in [0, pi], 2: polar [pi, 2 pi], 3: empty.
// Below a square node the four children of [x0, x1] x [y0, y1] with midpoints xm, ym are
// c = 0: [x0, xm] x [y0, ym], 1: [xm, x1] x [y0, ym], 2: [x0, xm] x [ym, y1], 3: [xm, x1] x [ym, y1].
// Below a polar node the children are whatever the builder chose: polar leaves carry their own
// box, so the descent needs no polar geometry.
#define QT_RIM_COS 0.5f
#define QT_INNER_R2 0.75f
struct QuadNode {
  vec4 mass;    // integral of f over each child (disc measure)
  uvec4 child;  // inner node index, QT_LEAF_BIT | leaf index, or QT_EMPTY
};
STATIC_ASSERT_SIZE(QuadNode, 32);

// A leaf samples its region with rejection against an envelope e >= f (a true bound, measured:
// docs/sampler.md): a point is proposed with density proportional to e, points outside the
// region are discarded before f is evaluated, the others are accepted with probability f / e.
// data = (A, mass: integral of f over the leaf's region, proposal kind (QT_PROPOSAL_*, as a
//         float), s: the rim exponent of the cos^-s part);
// env  = (k1, k2: log-slopes of the exponential part across the proposal domain, B: the
//         coefficient of the cos^-s part, 0);
// box  = polar kinds: (c0, c1, t0, t1), cos theta in [c0, c1], azimuth phi = pi t, t in [t0, t1]
//        (units of pi, so that the seams at phi = 0, pi are exact: quadCosSinPi).
// In normalized proposal coordinates t1, t2 in [0, 1]:
//   e = A exp(k1 (t1 - 1/2) + k2 (t2 - 1/2)) + B cos^-s.
// QT_PROPOSAL_SQUARE: the descent's square, t = ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0)); B = 0.
// QT_PROPOSAL_POLAR: the polar box, t = ((c^2 - c0^2) / (c1^2 - c0^2), (phi / pi - t0) / (t1 - t0))
//   (uniform t is uniform on the disc); the cos^-s part only in cells that touch the horizon
//   (c0 = 0) of models unbounded there (f ~ cos^-s: ward92 1/2, duer 1, minnaert 1 - k, schlick
//   with multiple = 1: 1, beard_maxwell 1, strauss 1).
// QT_PROPOSAL_POLAR_CUT: a square cell cut by the inner circle: the polar box of
//   (square & inner disc), points outside the descent's square discarded.
// Log-slopes below this are stored as 0 (uniform along that axis: quadExpSample's formulas would
// lose precision for tiny slopes).
#define QT_MIN_SLOPE 0.05f
#define QT_PROPOSAL_SQUARE 0u
#define QT_PROPOSAL_POLAR 1u
#define QT_PROPOSAL_POLAR_CUT 2u
struct QuadLeaf {
  vec4 data;
  vec4 env;
  vec4 box;
};
STATIC_ASSERT_SIZE(QuadLeaf, 48);

// info = (root node (QT_EMPTY when f = 0 for this direction), bits of cos phi, bits of sin phi, 0;
// the roughness bins' tables: their Fresnel moments, bsdf_sampling.h binFresnelMoments);
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
// Transmitting models (<NAME>_TRANSMITS, ModelSpec::transmits): every table has a second tree over
// the LOWER disc (the projection of the lower hemisphere, |cos theta| its Jacobian), stored as a
// second block of tables right after the first: lower(k, j) = first + thetaTables * phiTables +
// k * phiTables + j, with the same known direction. The sampler picks the lower disc with
// probability a_low / (a_up + a_low) and its pdf is f |cos| / (a_up + a_low) on either side.
#define QT_SET_TRANSMITS 2u
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

// Roughness bins (issue 18; bsdf_sampling.h, "Binned sampling"): the quadtree sets of gltf_pbr with
// baseColor 1, metallic 1 (the pure GGX/Smith lobe, F = 1) at roughness r_j = (j / (count - 1))^spacing,
// j = 0 .. count - 1, sets first .. first + count - 1; shared by every gltf_pbr material whose
// textures vary its parameters. count = 0: no bins (then nothing reads them).
struct RoughnessBins {
  uint first;
  uint count;
  float spacing;
  uint reserved;
};
STATIC_ASSERT_SIZE(RoughnessBins, 16);

SHARED_END
#endif
