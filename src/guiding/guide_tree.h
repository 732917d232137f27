// guide_tree.h: the path guide's CPU side (issue 16, docs/guiding.md): a binary tree over space
// whose leaves own directional quadtrees over the sphere (Mueller, Gross and Novak, "Practical
// Path Guiding", EGSR 2017), trained from splats of incident radiance, refined between training
// iterations and flattened into the arrays of shaders/shared/guiding_layout.h, which the shade
// stage samples with shaders/shared/guiding.h.
//
// Each leaf keeps two quadtrees: `sampling` (what the GPU samples during an iteration) and
// `building` (what the iteration's splats go into). At the end of iteration k (endIteration):
//   1. sampling := building (its structure and energies);
//   2. a leaf that received more than c sqrt(2^k) splats is split in two at the midpoint of its
//      box's longest axis (recursively, the splat count halving), both halves keeping its trees;
//   3. building := sampling's structure refined by energy (a cell holding more than rho of its
//      tree's energy is split, down to maxDirDepth), energies zero;
// within the memory cap (the flat arrays' bytes, spatial and directional): spatial splits stop
// at the cap, and rho doubles until the refined trees fit.
// Before step 1, each leaf's selection probability alpha is learned from the iteration's vertices
// (observeSelection; settings.alpha < 0, the default): the second moment of a vertex's one-sample
// MIS estimate under each candidate alpha of kAlphaCandidates, estimated from the samples drawn
// with the alpha the iteration used, and the guide is used (alpha = the best candidate) only
// where it lowers that moment significantly against alpha = 0 (BRDF sampling alone).
// The splats are box-filtered (settings dirFilter, on by default: shared among the directional
// cells a box of the landing cell's size overlaps; spatialFilter, off: among the regions a box of
// the vertex's region's size overlaps), and flatten can mix a uniform density into every trained
// guide (settings floor, 0 by default). docs/guiding.md, "Splat filtering".
// Everything runs in a fixed order: the same splats give the same trees, bit for bit.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "../../shaders/shared/guiding.h"

namespace nusselt::guiding {

// GuideSettings::alpha for a selection probability learned per region.
constexpr float kGuideAlphaAuto = -1.0f;
// The alphas a region can learn: 0 (BRDF sampling alone: the fallback) and the guide's clamped
// range [0.05, 0.95] in steps that are finer near the ends (where the second moment changes
// fastest: as 1 / (1 - alpha) where the guide has no mass, as 1 / alpha where only it has).
constexpr std::array<float, 13> kAlphaCandidates = {0.0f, 0.05f, 0.1f, 0.15f, 0.2f, 0.3f, 0.4f,
                                                    0.5f, 0.6f,  0.7f, 0.8f, 0.9f,  0.95f};

struct GuideSettings {
  // c of the spatial split rule (Mueller et al.: 12000): a leaf splits once it received more than
  // c sqrt(2^k) splats in iteration k (k = 0, 1, ...): the splats per leaf grow with the square
  // root of the samples, so leaves get both smaller and better trained as training goes on.
  double spatialThreshold = 12000;
  // rho (Mueller et al.: 0.01): a directional cell holding more than this share of its tree's
  // energy is split: at most about 4 / rho leaves of comparable energy per tree.
  double dirThreshold = 0.01;
  // Depth of the finest directional cell (2^-20 of the map's side).
  std::uint32_t maxDirDepth = GUIDE_MAX_DIR_DEPTH;
  // Depth of the deepest spatial node (its descent loop allows GUIDE_MAX_SPATIAL_DEPTH).
  std::uint32_t maxSpatialDepth = 48;
  // Bytes of the flat arrays (GuideSpatialNode + GuideDirNode) at most: 16 MiB by default.
  std::uint64_t memoryCap = 16ull << 20;
  // Probability of choosing the guide in a region that has learned something (one-sample MIS
  // with the BRDF sampler): a fixed value in [0, 1), or kGuideAlphaAuto: learned per region.
  float alpha = kGuideAlphaAuto;
  // Learned alpha: the vertices a region needs in an iteration to change its alpha, and the z of
  // the one-sided test that the guide's best alpha lowers the second moment against alpha = 0
  // (3.09: significance 0.001 per candidate, at most 12 x 0.001 over the candidates).
  double alphaMinVertices = 64;
  double alphaZ = 3.09;
  // Score the candidates against the guide the alpha will sample (this iteration's tree), each
  // vertex with its own splat taken out of it (leave-one-out: the tree was trained on the very
  // vertices that score it), instead of against the guide the vertices were drawn with (the
  // previous iteration's, trained on half the paths). Not with the spatial filter (a splat then
  // reaches other regions' trees): there the drawn-with guide scores. docs/guiding.md, "Where the
  // learned alpha falls back".
  bool alphaLeaveOneOut = true;
  // Leave-one-out: vertices kept per region and iteration at most (a systematic sample of the
  // region's vertices in path order: past twice the cap, every other one is dropped and the
  // stride doubles), bounding the memory (32 bytes each) and the scoring's time. The cap is
  // alphaKeep, lowered to alphaKeptTotal / regions (not below alphaKeepMin) when there are many
  // regions: the kept vertices never exceed 2 x max(alphaKeptTotal, alphaKeepMin x regions)
  // (256 MiB by default, and 64 KiB per region beyond 4096 regions).
  std::uint32_t alphaKeep = 16384;
  std::uint64_t alphaKeptTotal = 1ull << 22;
  std::uint32_t alphaKeepMin = 1024;
  // Directional splat filter (docs/guiding.md, "Splat filtering"): each splat is spread over a
  // box of the map the size of the building tree's leaf cell it lands in, centred on its point
  // (wrapping around in phi, clipped at the poles' edges and renormalised), its value shared among
  // the leaf cells the box overlaps in proportion to the overlapped area (Mueller et al.'s box
  // filter). False: the whole value goes to the one cell holding the point.
  bool dirFilter = true;
  // Spatial splat filter: each splat is shared among the regions that a box of its own region's
  // size, centred on the vertex (clipped to the root box and renormalised), overlaps, in
  // proportion to the overlapped volume (the deterministic expectation of Mueller et al.'s
  // jittered position). The splat counts of the split rule stay with the vertex's own region.
  bool spatialFilter = false;
  // Weight of the uniform sphere density mixed into every trained region's guide (flatten): the
  // density sampled is (1 - floor) x the tree's + floor / (4 pi), so no direction has density 0.
  double floor = 0.0;
  // Spatial roots: GUIDE_ORIENTATIONS, one tree over the box per orientation class of the
  // vertices (guideOrientation: a region's surfaces face one way, docs/guiding.md, "Regions by
  // orientation"), or 1 (every vertex under one root, whatever its normal).
  std::uint32_t orientations = GUIDE_ORIENTATIONS;
  // What a training splat carries (the shade stage's record value, guiding_layout.h, record b;
  // GpuGuide.info.w): the incident radiance over the sample's density, L_i / p (false), or the
  // product with the training vertex's BSDF and cosine, L_i f cos / p (true). The tree itself
  // splats either the same way; the product is what the sampler would ideally follow, averaged
  // over the region's vertices and outgoing directions (docs/guiding.md, "What the guide learns").
  bool product = true;
};

// A quadtree over the map [0, 1)^2; node 0 is the root. energy[c] of a node = the energy of
// child c's whole cell; child[c] = its node index, 0 for a leaf cell.
class DirTree {
 public:
  struct Node {
    std::array<double, 4> energy{};
    std::array<std::uint32_t, 4> child{};
  };
  DirTree() : m_nodes(1) {}
  // Adds value (>= 0) to the finest cell holding p (and to every cell above it).
  void splat(glm::vec2 p, double value);
  // Box filter: value (>= 0) spread over the square box of side `side` centred on p, shared among
  // the leaf cells it overlaps by overlapped area (phi, the map's y, wraps around; the part of the
  // box outside u in [0, 1) is cut off and the rest renormalised): the tree's total grows by value,
  // exactly up to rounding. side = 0: splat(p, value).
  void splatBox(glm::vec2 p, double side, double value);
  // Side of the leaf cell holding p (1/2 in a tree of one node).
  double leafSide(glm::vec2 p) const;
  double total() const;
  // This tree's structure refined by its energy, with zero energies: a cell is split when it holds
  // more than `threshold` of the total and is shallower than maxDepth (a cell that was a leaf here
  // is taken to hold its energy uniformly). A tree without energy stays one node.
  DirTree refined(double threshold, std::uint32_t maxDepth) const;
  std::size_t nodeCount() const { return m_nodes.size(); }
  const std::vector<Node>& nodes() const { return m_nodes; }
  // Depth of the deepest leaf cell (the root's children are at depth 1).
  std::uint32_t depth() const;
  // Density per unit area of the map at p (as guideSquarePdf on the flattened tree, in double)
  // of this tree with one splatBox(q, side, value) taken out (splat(q, value) for side 0): the
  // leave-one-out density of the learned alpha. 0 where the rest has no energy.
  double pdfWithout(glm::vec2 p, glm::vec2 q, double side, double value) const;

 private:
  // The descent to p's leaf, the same cell geometry as guideSquarePdf (dyadic, exact in floats):
  // visit(node, child, the child cell's corner x0, y0 and side) at every level, the leaf's last;
  // returns the leaf cell's side.
  template <class Visit>
  double descend(glm::vec2 p, Visit&& visit) const {
    std::uint32_t node = 0;
    float x0 = 0.0f, y0 = 0.0f, size = 1.0f;
    for (std::uint32_t d = 0; d <= GUIDE_MAX_DIR_DEPTH; ++d) {
      size *= 0.5f;
      std::uint32_t c = 0;
      if (p.x >= x0 + size) {
        c += 1;
        x0 += size;
      }
      if (p.y >= y0 + size) {
        c += 2;
        y0 += size;
      }
      visit(node, c, x0, y0, size);
      if (m_nodes[node].child[c] == 0) break;
      node = m_nodes[node].child[c];
    }
    return size;
  }
  void splatBoxInto(std::uint32_t node, double x0, double y0, double size, double bx0, double bx1, double by0,
                    double by1, double valuePerArea);
  std::vector<Node> m_nodes;
};

// A region's vertices of one iteration, for its alpha: per candidate c of kAlphaCandidates the sum
// over the vertices of d_c = y^2 p_mix (1 / p_bsdf - 1 / p_c) and of d_c^2 (y: the vertex's
// estimate through its sample, p_mix: the density it was drawn with, p_c: the mixture's density
// at alpha_c), whose mean estimates how much the second moment of y falls when alpha_c replaces
// BRDF sampling alone.
struct SelectionStats {
  std::array<double, kAlphaCandidates.size()> gain{}, gainSq{};
  double vertices = 0;
};

struct IterationReport {
  std::uint32_t iteration = 0;
  std::uint64_t splats = 0;         // splats of the iteration
  std::uint32_t leaves = 0;         // spatial leaves after it
  std::uint64_t dirNodes = 0;       // directional nodes the GPU samples from
  std::uint64_t bytes = 0;          // flat arrays' bytes (what the cap bounds)
  double dirThreshold = 0;          // rho used (raised above the setting when the cap bit)
  bool capped = false;              // the memory cap stopped a split or raised rho
  std::uint32_t guidedLeaves = 0;   // regions sampling the guide (alpha > 0 and a trained tree)
  double meanAlpha = 0;             // their mean alpha
  bool photons = false;             // the photon pre-pass's splats (before iteration 0)
};

class GuideTree {
 public:
  // The root box: [lo, hi] (the scene's bounds, made non-degenerate), one root per orientation
  // class (settings.orientations).
  GuideTree(glm::vec3 lo, glm::vec3 hi, const GuideSettings& settings);

  // One splat: value (>= 0) = the radiance estimate arriving at x, a vertex of orientation class o
  // (guideOrientation of its normal), from direction d divided by the density per steradian with
  // which d was sampled; counts one sample of (x, o)'s leaf.
  // With the settings' filters: shared among the regions around x (spatialFilter) and the cells
  // around d (dirFilter); the splat counts of x's own leaf.
  // count: what the splat adds to its leaf's count for the split rule (1; the photon pre-pass's
  // splats count less: trainPhotons).
  void splat(glm::vec3 x, std::uint32_t o, glm::vec3 d, double value, double count = 1.0) {
    splatAt(findLeaf(x, o), x, o, d, value, count);
  }
  // The same for a vertex known to lie in leaf `leaf` (findLeaf(x, o)).
  void splatAt(std::uint32_t leaf, glm::vec3 x, std::uint32_t o, glm::vec3 d, double value, double count = 1.0);
  // Whether a splat changes nothing outside its own leaf (no spatial filter, or no root split yet:
  // each orientation class still one leaf, and the filter stays within a class):
  // then the splats of different leaves can be applied in parallel (splatPaths), each leaf's in
  // their order, giving the same trees bit for bit.
  bool splatsStayInTheirLeaf() const { return !m_settings.spatialFilter || m_nodes.size() == m_settings.orientations; }
  // splatAt for a tree whose splats stay in their leaf, touching leaf `leaf` only: the splat is not
  // counted in the iteration's splats (addSplats adds them), so that threads owning different
  // leaves can call it at the same time.
  void splatInLeaf(std::uint32_t leaf, glm::vec3 d, double value, double count = 1.0);
  void addSplats(std::uint64_t n) { m_splats += n; }
  // A vertex of leaf `leaf` sampled by the mixture: y = its estimate through the sample (the
  // radiance it carried, >= 0), pdfGuide and pdfBsdf = the guide's and the BRDF sampler's
  // densities at the sampled direction, alpha = the selection probability it was drawn with.
  void observeSelection(std::uint32_t leaf, double y, double pdfGuide, double pdfBsdf, double alpha);
  // The same for a vertex whose sample, in direction d, splatted `value` into the leaf's building
  // tree: with settings.alphaLeaveOneOut kept, to be scored at the iteration's end against that
  // tree without its own splat; else observeSelection.
  void observeSelectionAt(std::uint32_t leaf, glm::vec3 d, double value, double y, double pdfGuide, double pdfBsdf,
                          double alpha);
  // The end of training iteration `iteration` (0, 1, ...): build, refine, report.
  IterationReport endIteration(std::uint32_t iteration);

  // The flat arrays of the sampling trees (guiding_layout.h); leaf alpha = the leaf's alpha
  // (settings.alpha when fixed) where the tree has energy, 0 elsewhere.
  void flatten(std::vector<shared::GuideSpatialNode>& spatial, std::vector<shared::GuideDirNode>& dir) const;
  // Bytes of the flat arrays.
  std::uint64_t bytes() const;
  std::uint32_t leafCount() const { return static_cast<std::uint32_t>(m_leaves.size()); }
  // The leaf (index into the leaves) whose box holds x under the root of orientation class o: the
  // same float arithmetic as guideLeafInfo.
  std::uint32_t findLeaf(glm::vec3 x, std::uint32_t o) const;
  const DirTree& samplingTree(std::uint32_t leaf) const { return m_leaves[leaf].sampling; }
  const DirTree& buildingTree(std::uint32_t leaf) const { return m_leaves[leaf].building; }
  double leafSamples(std::uint32_t leaf) const { return m_leaves[leaf].samples; }
  // The leaf's selection probability (before the tree check of flatten), and the vertices its
  // last learning step saw (0: never learned; a split leaf's halves get half each).
  float leafAlpha(std::uint32_t leaf) const { return m_leaves[leaf].alpha; }
  double leafAlphaVertices(std::uint32_t leaf) const { return m_leaves[leaf].alphaVertices; }
  const SelectionStats& leafSelection(std::uint32_t leaf) const { return m_leaves[leaf].selection; }
  // Vertices kept for the leave-one-out scoring so far in this iteration, over all regions.
  std::uint64_t keptVertices() const;
  // The orientation class of the leaf's vertices (its root's).
  std::uint32_t leafOrientation(std::uint32_t leaf) const { return m_leaves[leaf].orientation; }
  // The leaf's box.
  void leafBounds(std::uint32_t leaf, glm::vec3& lo, glm::vec3& hi) const;
  glm::vec3 boundsMin() const { return m_lo; }
  glm::vec3 boundsMax() const { return m_hi; }
  const GuideSettings& settings() const { return m_settings; }

 private:
  struct SpatialNode {
    std::uint32_t axis = GUIDE_SPATIAL_LEAF;  // 0..2 inner, GUIDE_SPATIAL_LEAF leaf
    std::uint32_t child = 0;                  // inner: first child node
    std::uint32_t leaf = 0;                   // leaf: index into m_leaves
    std::uint32_t depth = 0;
    glm::vec3 lo{0.0f}, hi{0.0f};
  };
  struct Leaf {
    DirTree sampling, building;
    double samples = 0;
    float alpha = 0;  // learned: 0 until the region's guide proves itself
    double alphaVertices = 0;
    SelectionStats selection;
    // Leave-one-out (GuideSettings::alphaLeaveOneOut): the iteration's kept vertices, 1 in
    // keepStride of those seen (keepSeen).
    struct Kept {
      glm::vec2 p;     // the sampled direction's map point
      double value;    // its splat's value (exactly what the tree received: taken out again)
      float y;         // its estimate y (0: nothing came back)
      float pMix, pBsdf;  // the densities it was drawn with (mixture) and of the BRDF sampler
    };
    std::vector<Kept> kept;
    std::uint64_t keepSeen = 0, keepStride = 1;
    bool scoredLeaveOneOut = false;  // this iteration's stats score the building tree (scoreKept)
    std::uint32_t orientation = 0;  // the orientation class whose root it descends from
  };
  void learnAlphas();
  void scoreKept();
  bool leaveOneOut() const { return m_settings.alphaLeaveOneOut && !m_settings.spatialFilter && m_settings.alpha < 0; }
  // The per-region cap of kept vertices for the current number of regions (GuideSettings::alphaKeep).
  std::uint32_t keepCap() const;
  // value into leaf's building tree at direction d (its directional filter if set).
  void splatDirection(std::uint32_t leaf, glm::vec3 d, double value);
  // The spatial node (a leaf) whose box holds x under the root of orientation class o.
  std::uint32_t findNode(glm::vec3 x, std::uint32_t o) const;
  float leafGuideAlpha(const Leaf& l) const { return m_settings.alpha >= 0 ? m_settings.alpha : l.alpha; }
  std::uint64_t bytesOf(std::size_t spatialNodes, std::uint64_t dirNodes) const;

  GuideSettings m_settings;
  glm::vec3 m_lo, m_hi;
  std::vector<SpatialNode> m_nodes;
  std::vector<Leaf> m_leaves;
  std::uint64_t m_splats = 0;
  std::uint32_t m_keepCap = 1;  // keepCap() for this iteration's regions
};

// Splats the training records of a chunk of `paths` paths (guiding_layout.h: recordsPerPath records
// of GUIDE_RECORD_VEC4S vec4 per path, at guideRecordIndex) with their final radiance (pathRadiance, rgb) into the tree,
// paths in order, and gives each mixture vertex to observeSelection. Returns the number of splats.
// With threads > 1 (0: the machine's cores) and splats that stay in their leaf, the leaves are
// shared among threads, each applying its leaves' splats in path order: the same trees bit for bit.
std::uint64_t splatPaths(GuideTree& tree, const glm::vec4* records, std::uint32_t recordsPerPath,
                         const glm::vec4* pathRadiance, std::uint32_t paths, unsigned threads = 0);

// The photon pre-pass (docs/guiding.md, "Photon pre-pass"): one photon's arrival after a bounce.
struct PhotonSplat {
  glm::vec3 x;      // where it arrived
  std::uint32_t orientation = 0;  // the orientation class of the surface's side it arrived on
  glm::vec3 d;      // unit direction towards where it came from
  float value = 0;  // luminance of its power
};
// Appends the photon records of a chunk of `photons` photons (guiding_layout.h, "Photon records":
// recordsPerPath records per photon, at guideRecordIndex) to out, photons in order, records k = 1, 2, ... in order.
void appendPhotons(const glm::vec4* records, std::uint32_t recordsPerPath, std::uint32_t photons,
                   std::vector<PhotonSplat>& out);
// The photons' guide: `rounds` times, every splat in order into the building trees, then
// endIteration(0) (spatial split by their count, directional refinement by their energy): the
// sampling trees end as the photons' energy in a structure refined rounds - 1 times by it (a
// single round leaves them at the initial structure, one node per region). Each splat counts
// `count` towards the spatial split rule. One report per round, photons = true.
std::vector<IterationReport> trainPhotons(GuideTree& tree, const std::vector<PhotonSplat>& splats,
                                          std::uint32_t rounds, double count = 1.0);

}  // namespace nusselt::guiding
