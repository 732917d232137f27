// quadtree_build.h: the CPU construction of one disc quadtree (Montes et al. 2008, split rule
// n_max I_i / V_i >= 1) for one known direction v. docs/sampler.md explains every choice.
#pragma once
#include <cstdint>
#include <vector>

#include "../../shaders/shared/quadtree.h"

namespace nusselt::quadtree {

struct BuildSettings {
  float nMax = 2.0f;           // split while n_max I / V < 1: every uncapped leaf accepts >= 1/n_max
  std::uint32_t maxDepth = 14; // depth cap (root = 0); capped leaves keep their proposal (measured)
  float boundMargin = 1.1f;    // M = margin * max of f over the dense point set of the leaf
  double relTol = 1e-5;        // leaf integral: |Q(node) - sum Q(children)| <= max(relTol Q, absTol a)
  double absTol = 2e-7;
  double tailTol = 1e-7;        // cells with mass <= tailTol a become leaves whatever their acceptance
};

// What the model needs from the builder: the rim exponent s (f ~ cos^-s at the horizon; 0 when
// f is bounded on the disc) and whether it depends on the azimuth of v.
struct ModelTraits {
  float rimExponent = 0.0f;
  bool anisotropic = false;
};
ModelTraits modelTraits(std::uint32_t model, const shared::BrdfParams& params);

struct TreeStats {
  std::uint32_t nodes = 0, leaves = 0, emptyChildren = 0;
  std::uint32_t cappedLeaves = 0;  // leaves at the depth cap that fail the split rule
  std::uint32_t tailLeaves = 0;    // negligible-mass leaves that fail the split rule
  double lowAcceptanceMass = 0;    // mass of the leaves that fail the split rule (capped + tail)
  std::uint32_t rimLeaves = 0;     // QT_PROPOSAL_RIM leaves
  std::uint32_t maxDepth = 0;
  double minAcceptance = 1.0;      // min over non-tail leaves of the acceptance I / V
  std::uint64_t evaluations = 0;
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
Tree buildTree(std::uint32_t model, const shared::BrdfParams& params, shared::vec3 v, const BuildSettings& settings);

}  // namespace nusselt::quadtree
