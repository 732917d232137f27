// sampler_tables.h: the generic sampler's trees for the materials of a render, built on the CPU
// in parallel (only for the materials used), cached on disk, flattened into the four buffers of
// shaders/shared/quadtree_layout.h; and the scope that lets C++ call the shared sampling code of
// shaders/shared/quadtree.h (quadSample, quadPdf, quadAlbedo) on those arrays.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "../../shaders/shared/quadtree.h"

namespace nusselt::quadtree {

struct QuadtreeSettings {
  std::uint32_t thetaTables = 90;  // tables at theta_k = k * 90 deg / thetaTables (paper: 90)
  std::uint32_t phiTables = 16;    // anisotropic models only: phi_j = j * 90 deg / (phiTables - 1)
  float nMax = 2.0f;               // split rule of the paper: every uncapped leaf accepts >= 1/nMax
  std::uint32_t maxDepth = 14;     // depth cap (cells of 2^-13 at the cap); see docs/sampler.md
  float defensive = 0.1f;          // cosine fraction between tables (none exactly on a table)
  bool useCache = true;            // $NUSSELT_CACHE_DIR, else $XDG_CACHE_HOME/nusselt, else ~/.cache/nusselt
  unsigned threads = 0;            // 0: std::thread::hardware_concurrency()
  // Tests only: when not empty, only these theta indices are built (all their phi tables); the
  // other tables stay empty (mass 0: sampling there fails). Never cached.
  std::vector<std::uint32_t> onlyThetaTables;
  // Called once, before any tree is built, when some materials' trees are not in the cache (a
  // build can take minutes): how many materials and tables will be built. May be empty.
  std::function<void(std::size_t materials, std::size_t tables)> beforeBuild;
};

struct MaterialStats {
  std::uint32_t model = 0;
  std::uint32_t set = INVALID_INDEX;
  std::uint32_t trees = 0, nodes = 0, leaves = 0, cappedLeaves = 0, rimLeaves = 0, maxDepth = 0;
  std::uint32_t tailLeaves = 0, expLeaves = 0;  // negligible-mass leaves below 1/n_max; exponential envelopes
  double minAcceptance = 1;
  std::uint64_t bytes = 0;
  std::uint64_t evaluations = 0;
  std::uint64_t certifyBoxes = 0;  // merl: boxes bounded by the proof of the envelopes (TreeStats)
  bool cacheHit = false;
  double buildSeconds = 0;  // CPU seconds summed over its trees (0 on a cache hit)
};

struct SamplerTables {
  std::vector<shared::QuadSet> sets;
  std::vector<shared::QuadTable> tables;
  std::vector<shared::QuadNode> nodes;
  std::vector<shared::QuadLeaf> leaves;
  std::vector<MaterialStats> materials;  // one per distinct material built (= per set)
  double seconds = 0;                    // wall time of buildSamplerTables
  std::uint32_t cacheHits = 0, cacheMisses = 0, cacheRejected = 0;  // rejected: corrupt/stale
  std::uint64_t bytes() const;
};

// For each material its QuadSet index (INVALID_INDEX for delta models) in setIndexPerMaterial.
// Identical (model, params) share one set. Trees are built in parallel and cached.
SamplerTables buildSamplerTables(const std::vector<std::pair<std::uint32_t, shared::BrdfParams>>& materials,
                                 const QuadtreeSettings& settings, std::vector<std::uint32_t>& setIndexPerMaterial);

// Whether f(w, v) of a non-delta, non-transmitting model is the same rgb value for every sampled
// direction w at each known direction v, on a probe of 32 known directions x 1024 sampled ones
// (polar angles up to 89.1 degrees, azimuths over the whole circle): lambert, oren_nayar with
// sigma = 0, a measured (merl) table of one constant value. The quadtree of such a BRDF is the uniform density on the unit disc,
// which cosine-weighted hemisphere sampling draws exactly with no tree, no rejection and no table
// look-up (the Nusselt analog), so renders give such materials no tables and sample them by cosine
// (docs/sampler.md, "Constant BRDFs"). A model that passed the probe but varied elsewhere would
// still be sampled without bias (cosine sampling with its own pdf), only less closely to f cos.
bool constantInSampledDirection(std::uint32_t model, const shared::BrdfParams& params);

// The cache directory in use ("" when none is writable).
std::string cacheDirectory();

// While alive, quadSample / quadPdf / quadAlbedo called from this thread read `tables` and count
// into `counters` (boundViolations, trialFailures, trials, samples).
class QuadHostScope {
 public:
  explicit QuadHostScope(const SamplerTables& tables);
  ~QuadHostScope();
  QuadHostScope(const QuadHostScope&) = delete;
  QuadHostScope& operator=(const QuadHostScope&) = delete;
  const shared::QuadHost& counters() const { return m_host; }
  // Per-leaf counters (arrays of tables.leaves.size(), owned by the caller), or nullptr.
  void countPerLeaf(std::uint64_t* evaluations, std::uint64_t* accepted) {
    m_host.leafEvaluations = evaluations;
    m_host.leafAccepted = accepted;
  }

 private:
  shared::QuadHost m_host;
  shared::QuadHost* m_previous;
};

}  // namespace nusselt::quadtree
