// guiding.h: the path guide's look-ups (issue 16, docs/guiding.md), shared by the CPU (tests,
// the trainer's splats) and the GPU (shade stage): the equal-area map of the sphere, the spatial
// descent, the directional quadtree's density per steradian and its sampling, and the one-sample
// MIS mixture with the BRDF sampler. Arrays: guiding_layout.h; builder: src/guiding/guide_tree.cpp.
//
// Buffer access: GLSL passes the GpuGuide (its buffer references), C++ a GuideHostView (the struct
// plus host pointers to the arrays), as envmap.h does.
#ifndef NUSSELT_GUIDING_H
#define NUSSELT_GUIDING_H
#include "guiding_layout.h"
#include "rng.h"
#include "mass_descent.h"

#ifdef __cplusplus
SHARED_BEGIN
struct GuideHostView {
  GpuGuide g{};
  const GuideSpatialNode* spatial = nullptr;
  const GuideDirNode* dir = nullptr;
};
typedef GuideHostView GuideView;
SHARED_END
#define GUIDE_VIEW_INFO(G) (G.g)
#define GUIDE_SPATIAL(G, i) (G.spatial[i])
#define GUIDE_DIR(G, i) (G.dir[i])
#else
#define GuideView GpuGuide
#define GUIDE_VIEW_INFO(G) (G)
// 64-bit loads (layout.h): the descents read a node per lane.
#define GUIDE_SPATIAL(G, i) GuideSpatialNode(loadUVec4(G.spatial, i))
#define GUIDE_DIR(G, i) guideDirNode(Wide(G.dir), i)
GuideDirNode guideDirNode(Wide w, uint i) { return GuideDirNode(wideVec4(w.v[2u * i]), wideUVec4(w.v[2u * i + 1u])); }
#endif

SHARED_BEGIN

// The stream id of the guide's descents (rng.h, rngStreamKey; the quadtree sampler's is
// RNG_REJECTION_STREAM).
#define RNG_GUIDE_STREAM 0x40000000u
#define NUSSELT_INV_4PI 0.07957747154594767f

// ---- The equal-area map of the sphere ----------------------------------------------------------

// Map point of a unit direction: (u, v) = ((d.z + 1) / 2, atan2(d.y, d.x) / (2 pi) mod 1), in
// [0, 1)^2 (Lambert's cylindrical equal-area projection: d omega = 4 pi du dv).
SHARED_FN vec2 guideDirectionToSquare(vec3 d) {
  float u = clamp(0.5f * (d.z + 1.0f), 0.0f, NUSSELT_ONE_MINUS_EPS);
  float v = portableAtan2(d.y, d.x) * (1.0f / NUSSELT_TWO_PI);
  if (v < 0.0f) v += 1.0f;
  return vec2(u, clamp(v, 0.0f, NUSSELT_ONE_MINUS_EPS));
}

// The unit direction at map point p (inverse of guideDirectionToSquare).
SHARED_FN vec3 guideSquareToDirection(vec2 p) {
  float z = clamp(2.0f * p.x - 1.0f, -1.0f, 1.0f);
  float r = cosFromSin(z);
  float phi = NUSSELT_TWO_PI * p.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// ---- Space ----------------------------------------------------------------------------------------

// The orientation class (guiding_layout.h, GUIDE_ORIENTATIONS) of a vertex whose geometric normal,
// on the side the path is on, is n: 2 x the axis of its largest component (the first of equal
// ones) + 1 if that component is negative.
SHARED_FN uint guideOrientation(vec3 n) {
  vec3 a = abs(n);
  uint axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
  float c = axis == 0u ? n.x : (axis == 1u ? n.y : n.z);
  return 2u * axis + (c < 0.0f ? 1u : 0u);
}

// The spatial root of orientation class o in a tree of `roots` roots (GpuGuide.info.z).
SHARED_FN uint guideSpatialRoot(uint roots, uint o) { return roots > 1u ? min(o, roots - 1u) : 0u; }

// info of the spatial leaf whose box holds x, under the root of orientation class o
// (guiding_layout.h: (GUIDE_SPATIAL_LEAF, root, alpha bits, 0)). Points outside the root box go
// to the nearest leaf along each split. A tree
// deeper than the loop bound (never built) gives an unguided region (alpha 0). Each inner node
// holds its split coordinate (the midpoint of its box, as GuideTree::findNode computes it): the
// descent keeps no box and indexes no array by a variable.
SHARED_FN uvec4 guideLeafInfo(GuideView G, vec3 x, uint o) {
  uint node = guideSpatialRoot(GUIDE_VIEW_INFO(G).info.z, o);
  for (uint d = 0u; d < GUIDE_MAX_SPATIAL_DEPTH; ++d) {
    uvec4 info = GUIDE_SPATIAL(G, node).info;
    if (info.x == GUIDE_SPATIAL_LEAF) return info;
    float xa = info.x == 0u ? x.x : (info.x == 1u ? x.y : x.z);
    node = info.y + (xa < uintBitsToFloat(info.z) ? 0u : 1u);
  }
  return uvec4(GUIDE_SPATIAL_LEAF, 0u, 0u, 0u);
}

// ---- Directions -----------------------------------------------------------------------------------

// The directional quadtree's one descent, which serves both its look-up and its sampling, so that
// a shade stage whose lanes do either (guided samples, and the guide's density at BSDF samples)
// walks the tree once. Returns the density per unit area of the map (the product over the descent
// of 4 x child's mass / node's mass; 0 where a cell has no mass or the tree has none) at p:
// - draw false: p in [0, 1)^2 is given, the descent follows it;
// - draw true: a cell is drawn in proportion to the masses (mass_descent.h: uDescent, rescaled
//   at each level; its fresh numbers come from the stream of uDescent and uCell, rng.h) and p is
//   set to the point uCell of that cell (a function of the numbers alone). The density returned
//   is the cell's: the one a look-up of p gives, computed by the same operations (bit for bit).
SHARED_FN float guideSquareDescend(GuideView G, uint root, bool draw, float uDescent, vec2 uCell, INOUT(vec2) p) {
  uint node = root;
  float x0 = 0.0f;
  float y0 = 0.0f;
  float size = 1.0f;
  float pdf = 1.0f;
  MassDescent m = massDescentStart(uDescent);
  uvec4 stream = rngStreamKey(uDescent, uCell.x, floatBitsToUint(uCell.y), RNG_GUIDE_STREAM);
  for (uint d = 0u; d <= GUIDE_MAX_DIR_DEPTH; ++d) {
    GuideDirNode N = GUIDE_DIR(G, node);
    float total = N.mass.x + N.mass.y + N.mass.z + N.mass.w;
    if (!(total > 0.0f)) return 0.0f;
    size *= 0.5f;
    uint c;
    if (draw) {
      float share;
      c = massDescendStep(N.mass, stream, m, share);
    } else {
      c = (p.x >= x0 + size ? 1u : 0u) + (p.y >= y0 + size ? 2u : 0u);
    }
    if ((c & 1u) != 0u) x0 += size;
    if ((c & 2u) != 0u) y0 += size;
    pdf *= 4.0f * N.mass[c] / total;
    if (N.child[c] == 0u) {
      // The point of the cell, kept below its upper edges (x0 + u size can round up to them):
      // a look-up of p then takes this very cell.
      if (draw)
        p = vec2(min(x0 + uCell.x * size, uintBitsToFloat(floatBitsToUint(x0 + size) - 1u)),
                 min(y0 + uCell.y * size, uintBitsToFloat(floatBitsToUint(y0 + size) - 1u)));
      return pdf;
    }
    node = N.child[c];
  }
  return 0.0f;
}

// Density per unit area of the map at p in [0, 1)^2 of the quadtree rooted at `root`.
SHARED_FN float guideSquarePdf(GuideView G, uint root, vec2 p) {
  return guideSquareDescend(G, root, false, 0.0f, vec2(0.0f), p);
}

// Density per steradian with which guideDirSample draws the unit direction d.
SHARED_FN float guideDirPdf(GuideView G, uint root, vec3 d) {
  return guideSquarePdf(G, root, guideDirectionToSquare(d)) * NUSSELT_INV_4PI;
}

// Draws a unit direction d (world) with density guideDirPdf from the quadtree rooted at `root`
// (guideSquareDescend). pdf: the density per steradian of its cell. False when the tree has no mass.
SHARED_FN bool guideDirSample(GuideView G, uint root, float uDescent, vec2 uCell, OUT(vec3) d, OUT(float) pdf) {
  vec2 p = vec2(0.0f);
  pdf = guideSquareDescend(G, root, true, uDescent, uCell, p) * NUSSELT_INV_4PI;
  d = pdf > 0.0f ? guideSquareToDirection(p) : vec3(0.0f, 0.0f, 1.0f);
  return pdf > 0.0f;
}

// ---- One-sample MIS with the BRDF sampler ---------------------------------------------------------
// The guide is chosen with probability alpha, the material's own sampler otherwise; the sample's
// weight f cos / p uses the mixture's density (Veach's one-sample model, section 9.2.4), the MIS
// weights against light sampling the BRDF sampler's (shade_body.glsl, shadeMisPdf). The BRDF
// sampler's density is positive wherever f cos is (every strategy of bsdf_sampling.h is unbiased
// on its own), so the mixture is too for alpha < 1: the guide needs no floor of its own, and a
// cell the training never reached is still sampled through the BRDF.
SHARED_FN float guideMixturePdf(float alpha, float pdfGuide, float pdfBsdf) {
  return alpha * pdfGuide + (1.0f - alpha) * pdfBsdf;
}

SHARED_END

// ---- The shade and escape stages' side (GLSL): the guide at a vertex, training records -------------
#if !defined(__cplusplus) && !defined(NUSSELT_STANDALONE_KERNEL)
// The guide's region at a surface point: its quadtree's root and the selection probability
// alpha of the guide there (0: the region has learned nothing and is not guided).
struct GuideVertex {
  uint root;
  float alpha;
};

#if NUSSELT_SCENE_FEATURES
// The region of a vertex at x whose geometric normal on the path's side is ng.
GuideVertex guideVertex(vec3 x, vec3 ng) {
  uvec4 info = guideLeafInfo(g.guide.v[0], x, guideOrientation(ng));
  GuideVertex v;
  v.root = info.y;
  v.alpha = uintBitsToFloat(info.z);
  return v;
}

// The guide's descent at a vertex of region v (guideSquareDescend): guided, a direction drawn from
// the guide (w set; uDescent = the descent's number, the point in its cell from the bounce's
// RNG_DIM_GUIDE_CELL); otherwise the look-up of the given world direction w. Returns the guide's
// density per steradian at w (0: the region has no mass there; a guided sample then fails).
float guideDescend(GuideVertex v, bool guided, float uDescent, PathKey k, uint bounce, inout vec3 w) {
  vec2 uCell = pathSample2(k, rngDimension(bounce, RNG_DIM_GUIDE_CELL));
  vec2 p = guided ? vec2(0.0f) : guideDirectionToSquare(w);
  float pdf = guideSquareDescend(g.guide.v[0], v.root, guided, uDescent, uCell, p) * NUSSELT_INV_4PI;
  if (guided && pdf > 0.0f) w = guideSquareToDirection(p);
  return pdf;
}

// Whether this pass writes training records (the guide's info.x).
bool guideRecording() { return g.guide.v[0].info.x > 0u; }

// Whether the training records carry the product L_i f cos (the guide's info.w; else L_i alone:
// guiding::GuideSettings::product).
bool guideLearnsProduct() { return g.guide.v[0].info.w != 0u; }

// Whether this pass traces photons (the guide's info.y: the photon pre-pass, docs/guiding.md): the
// paths start at light samples (photon.comp), the shade stages write photon records and neither
// gather emission nor sample lights, the escape stage does nothing.
bool guidePhotons() { return g.guide.v[0].info.y != 0u; }

// Photon record k = bounce of this photon (guiding_layout.h, "Photon records"): it arrived at x,
// on the side of the surface whose geometric normal is ng, from the world direction wFrom (unit,
// towards where it came from) carrying power of luminance value (> 0).
void guideRecordPhoton(uint path, uint bounce, vec3 x, vec3 ng, vec3 wFrom, float value) {
  uint n = g.guide.v[0].info.x;
  if (bounce >= n) return;
  GuideRecords R = g.guide.v[0].records;
  uint i = guideRecordIndex(path, bounce, g.chunkPaths);
  storeVec4(R, i, vec4(x, value));
  storeVec4(R, i + 1u, vec4(wFrom, 1.0f + float(guideOrientation(ng))));
}

// A camera path's first record reads "ended at vertex 0" until a stage writes its arrival there
// (a camera ray that leaves a scene without environment never reaches one). With the resets of
// guideRecordSample, every record the trainer reads is written in the pass that reads it: the
// record buffer needs no clearing between passes.
void guideRecordStart(uint path) {
  if (g.guide.v[0].info.x == 0u) return;
  GuideRecords R = g.guide.v[0].records;
  storeVec4(R, guideRecordIndex(path, 0u, g.chunkPaths) + 1u, vec4(0.0f));
}

// Training record k = bounce of this path (guiding_layout.h): its ray arrived at x with the path
// radiance as it stands (call before the stage adds anything); the path ends here unless
// guideRecordSample follows.
void guideRecordArrival(uint path, uint bounce, vec3 x) {
  uint n = g.guide.v[0].info.x;
  if (bounce >= n) return;
  GuideRecords R = g.guide.v[0].records;
  uint i = guideRecordIndex(path, bounce, g.chunkPaths);
  storeVec4(R, i, vec4(x, luminance(loadVec4(g.pathRadiance, path).xyz)));
  storeVec4(R, i + 1u, vec4(0.0f));
}

// The path goes on from vertex `bounce` (geometric normal ng on the path's side) in the world
// direction wi; value = the record's b.w (guiding_layout.h: what the radiance arriving through
// the sample is divided by to give the splat), or -1 (not splatted: a delta sample, or a factor
// without luminance); selection = (guide density, BRDF-sampler density, alpha) of the sample
// (guiding_layout.h, c).
// The next record reads "nothing arrived (-1), ended there" until a stage writes its arrival (a
// ray that leaves a scene without environment, or a path the next bounce ends, never gets one).
void guideRecordSample(uint path, uint bounce, vec3 ng, vec3 wi, float value, vec3 selection) {
  uint n = g.guide.v[0].info.x;
  if (bounce >= n) return;
  GuideRecords R = g.guide.v[0].records;
  uint i = guideRecordIndex(path, bounce, g.chunkPaths);
  storeVec4(R, i + 1u, vec4(wi, value > 0.0f ? value : -1.0f));  // 0 would read as "ended here"
  storeVec4(R, i + 2u, vec4(selection, float(guideOrientation(ng))));
  if (bounce + 1u < n) {
    uint j = guideRecordIndex(path, bounce + 1u, g.chunkPaths);
    storeVec4(R, j, vec4(0.0f, 0.0f, 0.0f, -1.0f));
    storeVec4(R, j + 1u, vec4(0.0f));
  }
}
#else
// A module without guiding (NUSSELT_SCENE_FEATURES 0, stage_common.glsl): empty stand-ins.
GuideVertex guideVertex(vec3 x, vec3 ng) { return GuideVertex(0u, 0.0f); }
float guideDescend(GuideVertex v, bool guided, float uDescent, PathKey k, uint bounce, inout vec3 w) { return 0.0f; }
bool guideRecording() { return false; }
bool guideLearnsProduct() { return false; }
bool guidePhotons() { return false; }
void guideRecordPhoton(uint path, uint bounce, vec3 x, vec3 ng, vec3 wFrom, float value) {}
void guideRecordArrival(uint path, uint bounce, vec3 x) {}
void guideRecordStart(uint path) {}
void guideRecordSample(uint path, uint bounce, vec3 ng, vec3 wi, float value, vec3 selection) {}
#endif
#endif

#endif
