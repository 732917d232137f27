// quadtree_build.h: the CPU construction of one disc quadtree (Montes et al. 2008, split rule
// n_max I_i / V_i >= 1, V_i the integral of the leaf's envelope) for one known direction v.
// docs/sampler.md explains every choice.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "../../shaders/shared/quadtree.h"
#include "../brdf/model_spec.h"

namespace nusselt::quadtree {

struct BuildSettings {
  float nMax = 2.0f;           // split while n_max I / V < 1: every uncapped leaf accepts >= 1/n_max
  std::uint32_t maxDepth = 14; // depth cap (root = 0); capped leaves keep their proposal (measured)
  float boundMargin = 1.1f;    // envelope >= margin * f at every point of the leaf's dense point set
  double relTol = 1e-6;        // leaf integral: |Q(node) - sum Q(children)| <= max(relTol Q, absTol a)
                               // (1e-5 let two rules agree on a streak both missed: ashikhmin hard, 2e-4)
  double absTol = 2e-7;
  double tailTol = 1e-7;        // cells with mass <= tailTol a become leaves whatever their acceptance
  // The lower disc of a transmitting model (ModelSpec::transmits): the tree is built over the
  // projection of the LOWER hemisphere, a disc point (x, y) standing for w = (x, y, -sqrt(1 - r^2)),
  // with density luminance(f(w, v)) (|cos| is the disc's Jacobian as above). Not part of the cache
  // key: a material's lower trees are stored beside its upper ones (sampler_tables.cpp).
  bool lowerDisc = false;
};

// What the model needs from the builder (rim exponent, anisotropy): declared by each model in
// its header (ModelSpec::traits, src/brdf/model_spec.h); defaults when it declares none.
using ModelTraits = ::nusselt::ModelTraits;
ModelTraits modelTraits(std::uint32_t model, const shared::BrdfParams& params);

struct TreeStats {
  std::uint32_t nodes = 0, leaves = 0, emptyChildren = 0;
  std::uint32_t cappedLeaves = 0;  // leaves at the depth cap that fail the split rule
  std::uint32_t tailLeaves = 0;    // negligible-mass leaves that fail the split rule
  double lowAcceptanceMass = 0;    // mass of the leaves that fail the split rule (capped + tail)
  std::uint32_t rimLeaves = 0;     // leaves with a polar proposal (the rim annulus, squares cut by the inner circle)
  std::uint32_t expLeaves = 0;     // leaves whose envelope has an exponential slope
  std::uint32_t singularLeaves = 0;  // leaves whose envelope has a cos^-s part
  std::uint32_t maxDepth = 0;
  double minAcceptance = 1.0;      // min over non-tail leaves of the acceptance I / V
  std::uint64_t evaluations = 0;
  std::uint64_t certifyBoxes = 0;  // merl: boxes whose exact bound the proof of the envelopes computed
};

// One tree in local indices (node 0 is the root unless root is a leaf): child links index
// `nodes` or QT_LEAF_BIT | index into `leaves`.
struct Tree {
  std::vector<shared::QuadNode> nodes;
  std::vector<shared::QuadLeaf> leaves;
  std::uint32_t root = QT_EMPTY;
  double mass = 0;  // integral of luminance(f(., v)) over the disc (sum of the leaf masses)
  TreeStats stats;
};

// Builds the tree for the known direction v (canonical frame). model must not be a delta model.
// Isotropic models (modelTraits) need v.y = 0 and get the half-disc tree of quadtree_layout.h.
Tree buildTree(std::uint32_t model, const shared::BrdfParams& params, shared::vec3 v, const BuildSettings& settings);

// Calls fn(leaf index, leaf, x0, y0, size) for every leaf reachable from `root` in the flattened
// arrays (quadtree_layout.h geometry): (x0, y0, size) is the leaf's square from the descent, which
// polar leaves ignore (they carry their box).
void forEachLeaf(const shared::QuadNode* nodes, const shared::QuadLeaf* leaves, std::uint32_t root, bool anisotropic,
                 const std::function<void(std::uint32_t, const shared::QuadLeaf&, double, double, double)>& fn);

// The envelope of every leaf of `tree` checked against f on a grid x grid lattice of its proposal
// domain (points outside the leaf's region skipped): the largest f / e, and the leaves (and their
// mass) where it exceeds 1. Leaves of mass below 1e-20 of the total are skipped (never sampled).
struct EnvelopeAudit {
  double worst = 0;
  std::uint32_t leaves = 0, leavesAbove = 0;
  double massAbove = 0;
  std::uint64_t evaluations = 0;
};
// lowerDisc: the tree is a lower-disc tree (BuildSettings::lowerDisc).
EnvelopeAudit auditEnvelopes(std::uint32_t model, const shared::BrdfParams& params, shared::vec3 v, const Tree& tree, int grid,
                             bool lowerDisc = false);
// The same on flattened arrays (one table of a SamplerTables: its root and total mass).
EnvelopeAudit auditEnvelopes(std::uint32_t model, const shared::BrdfParams& params, shared::vec3 v, const shared::QuadNode* nodes,
                             const shared::QuadLeaf* leaves, std::uint32_t root, double mass, int grid,
                             bool lowerDisc = false);

}  // namespace nusselt::quadtree
