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

// data = (M: upper bound of f over the leaf, mass: integral of f over the leaf,
//         proposal kind (QT_PROPOSAL_*), proposal parameter)
#define QT_PROPOSAL_UNIFORM 0u  // uniform point in the leaf, accept with f / M
struct QuadLeaf {
  vec4 data;
};
STATIC_ASSERT_SIZE(QuadLeaf, 16);

// info = (root node or QT_LEAF_BIT | leaf, 0, 0, 0); data = (total mass = directional albedo of
// the luminance of f, cos theta of the table's fixed direction, phi of it, 0)
struct QuadTable {
  uvec4 info;
  vec4 data;
};
STATIC_ASSERT_SIZE(QuadTable, 32);

// info = (first table, tables along theta, tables along phi (1: isotropic), flags);
// data = (defensive cosine fraction epsilon, theta step (radians), phi step (radians), 0)
struct QuadSet {
  uvec4 info;
  vec4 data;
};
STATIC_ASSERT_SIZE(QuadSet, 32);

SHARED_END
#endif
