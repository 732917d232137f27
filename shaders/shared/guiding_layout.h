// guiding_layout.h: the path guide's flat arrays (issue 16, docs/guiding.md), as the CPU writes
// them (src/guiding/guide_tree.cpp) and the shade stage reads them (guiding.h).
//
// A binary tree over space (the scene's bounds, each node split at the midpoint of its box's
// longest axis: Mueller, Gross and Novak, "Practical Path Guiding for Efficient Light-Transport
// Simulation", EGSR 2017, section 3) whose leaves each own a directional quadtree over the whole
// sphere in the cylindrical equal-area map
//   (u, v) = ((cos theta + 1) / 2, phi / (2 pi)),  cos theta = d.z, phi = atan2(d.y, d.x),
// whose Jacobian is constant: d omega = 4 pi du dv. A quadtree cell's share of the unit square is
// then its share of the sphere's solid angle, in world space (the BRDF trees' hemisphere disc is
// a local frame of one surface and does not fit a region of space with many normals).
#ifndef NUSSELT_GUIDING_LAYOUT_H
#define NUSSELT_GUIDING_LAYOUT_H
#include "prelude.h"
SHARED_BEGIN

// Orientation classes of a vertex (guideOrientation: the axis and sign of the largest component of
// its geometric normal, on the side the path is on: +x, -x, +y, -y, +z, -z). With info.z =
// GUIDE_ORIENTATIONS the spatial tree has one root per class (nodes 0 .. 5, each over the whole
// box): a region holds surfaces of one orientation, so its guide learns one hemisphere's light
// and sends no samples below its surfaces (docs/guiding.md, "Regions by orientation").
#define GUIDE_ORIENTATIONS 6u

// Spatial node kinds: 0, 1, 2 = inner node split along x, y, z; this value = leaf.
#define GUIDE_SPATIAL_LEAF 3u
// Loop bounds of the descents (lavapipe truncates loops silently: every loop is bounded). The
// builder never builds deeper (GuideSettings caps the directional depth at GUIDE_MAX_DIR_DEPTH).
#define GUIDE_MAX_SPATIAL_DEPTH 64u
#define GUIDE_MAX_DIR_DEPTH 20u
// Path vertices whose training record is kept (records per path = this + 1: the last one holds
// only the radiance on arrival that its predecessor needs). Deeper vertices are not splatted:
// they carry little of the image and the record buffer grows with them.
#define GUIDE_MAX_RECORD_VERTICES 8u

// info = (axis 0..2, first child (the second is first + 1: x[axis] >= split), bits of the split
//         coordinate (the midpoint of the node's box along axis), 0) for inner nodes;
//        (GUIDE_SPATIAL_LEAF, root of the leaf's directional quadtree (GuideDirNode index),
//         bits of the selection probability alpha of the guide in this region (0: not guided),
//         0) for leaves.
struct GuideSpatialNode {
  uvec4 info;
};
STATIC_ASSERT_SIZE(GuideSpatialNode, 16);

// A directional quadtree node over the square [x0, x1] x [y0, y1] of the map (root: [0, 1]^2);
// children c = 0: [x0, xm] x [y0, ym], 1: [xm, x1] x [y0, ym], 2: [x0, xm] x [ym, y1],
// 3: [xm, x1] x [ym, y1]. mass[c] = the learned energy of child c's cell (>= 0); child[c] = the
// child's node index, 0 when the child is a leaf (no root is ever a child, so 0 is free).
struct GuideDirNode {
  vec4 mass;
  uvec4 child;
};
STATIC_ASSERT_SIZE(GuideDirNode, 32);

#ifndef __cplusplus
layout(buffer_reference, std430, buffer_reference_align = 16) buffer GuideSpatialNodes { GuideSpatialNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer GuideDirNodes { GuideDirNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer GuideRecords { vec4 v[]; };
#define GUIDE_BUFREF(T) T
#else
#define GUIDE_BUFREF(T) std::uint64_t
#endif

// Training records (written by the shade and escape stages while info.x > 0): per path
// info.x records of GUIDE_RECORD_VEC4S vec4s, record k of path p of a chunk of n paths at
// guideRecordIndex(p, k, n) (bounce-major: a stage's invocations, which shade one bounce of
// consecutive paths, write consecutive records; the reader walks info.x sequential streams):
//   a = (position of vertex k (xyz), luminance of the path's radiance when its ray arrived at
//        vertex k, before anything vertex k adds; -1: the ray left the scene without an
//        environment, so nothing arrived);
//   b = (sampled direction (world, unit), the value v that the radiance arriving through the
//        sample is divided by: with info.w = 0 (the guide learns radiance) the luminance of the
//        throughput after the sample x the density of the sample per steradian, with info.w = 1
//        (it learns the product L_i f cos) that luminance over the luminance of the sample's
//        factor f cos / p; 0: the path ended at vertex k; -1: it went on from a vertex whose
//        sample is not splatted (a delta lobe, or a factor without luminance));
//   c = (the guide's density per steradian at the sampled direction (-1: the vertex does not
//        sample the mixture, a combined material), the BRDF sampler's density there, the
//        selection probability alpha the sample was drawn with, the vertex's orientation class
//        (guideOrientation)); read only when b.w > 0.
// The radiance that reached vertex k from its sampled direction is then (path radiance at the
// end - a.w of record k + 1) / (luminance of the throughput), and the splat, that divided by the
// density (L_i / p) or times the factor (L_i f cos / p), is (path radiance at the end - a.w of
// record k + 1) / b.w (src/guiding/guide_tree.cpp, splatPaths); c lets the trainer estimate, per
// region, the second moment the vertex's estimate would have under another alpha (GuideTree,
// observeSelection).
// Photon records (the photon pre-pass, info.y = 1; the same buffer and slots, path = photon):
// record k of photon p, written by the shade stage where the photon's ray of bounce k arrived
// (k >= 1: after at least one bounce off a surface, indirect light; k = 0, direct light, is NEE's):
//   a = (position (xyz), luminance of the photon's power on arrival);
//   b = (unit world direction towards where it came from, 1 + the orientation class of the
//        surface on the side it arrived from); b.w = 0: no record.
#define GUIDE_RECORD_VEC4S 3u
// The first vec4 of record k of path p (chunk-local) in a chunk of `paths` paths.
SHARED_FN uint guideRecordIndex(uint path, uint k, uint paths) { return (k * paths + path) * GUIDE_RECORD_VEC4S; }
// boundsMin, boundsMax: the spatial tree's root box (w unused);
// info = (records per path, 0: not recording; 1: the photon pre-pass, else 0; spatial roots:
//         GUIDE_ORIENTATIONS (one per orientation class) or 1 (every vertex at node 0); 1: the
//         records' b.w makes the splats L_i f cos / p, 0: L_i / p (GuideSettings::product)).
struct GpuGuide {
  vec4 boundsMin;
  vec4 boundsMax;
  uvec4 info;
  GUIDE_BUFREF(GuideSpatialNodes) spatial;
  GUIDE_BUFREF(GuideDirNodes) dir;
  GUIDE_BUFREF(GuideRecords) records;
  uint reserved0;
  uint reserved1;
};
STATIC_ASSERT_SIZE(GpuGuide, 80);
#ifndef __cplusplus
layout(buffer_reference, std430, buffer_reference_align = 16) buffer GpuGuides { GpuGuide v[]; };
#endif

SHARED_END
#endif
