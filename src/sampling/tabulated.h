// tabulated.h: the CPU builder of the `tabulated` sampling strategy's tables (one TabSet per distinct
// material, nearest-table piecewise-constant disc densities; shaders/shared/tabulated.h samples them)
// and the scope that lets C++ call the shared sampler (tabSample, tabPdf, tabAlbedo) on them.
// docs/strategies.md describes the method and the memory budget.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "../../shaders/shared/tabulated.h"

namespace nusselt::sampling {

struct TabulatedSettings {
  std::uint32_t thetaTables = 90;  // tables at theta_k = k * 90 deg / thetaTables (as the quadtree)
  std::uint32_t phiTables = 4;     // anisotropic sets only: phi_j = j * 90 deg / (phiTables - 1)
  // Memory budget of ONE table (its header and CDFs), in bytes: the grid is the largest nu x 2nu
  // that fits. The default 64 KiB (nu = 90 rings x 180 sectors) lies between the quadtree's
  // per-tree size for lobes like phong (~9 KiB) and ward (~40 KiB) and strauss (~1.4 MiB); to
  // match a material's quadtree, pass bytesPerTableLike(its MaterialStats.bytes, trees).
  std::uint64_t bytesPerTable = 64 * 1024;
  float defensive = 0.05f;         // defensive cosine fraction epsilon (support everywhere f > 0)
  unsigned threads = 0;            // 0: std::thread::hardware_concurrency()
  // Tests only: when not empty, only these theta indices are built (all their phi tables); the
  // others have no mass (sampling there is pure cosine, still unbiased).
  std::vector<std::uint32_t> onlyThetaTables;
};

// Per-table budget equal to a quadtree's: its total bytes over its tree count (at least 1 KiB).
std::uint64_t bytesPerTableLike(std::uint64_t quadtreeBytes, std::uint32_t trees);

// Rows nu and columns np = 2 nu of the grid that fits bytesPerTable (nu >= 2).
void tabulatedGrid(std::uint64_t bytesPerTable, std::uint32_t& nu, std::uint32_t& np);

struct TabulatedTables {
  std::vector<shared::TabSet> sets;
  std::vector<shared::TabTable> tables;
  std::vector<float> data;
  double seconds = 0;       // wall time of the build
  std::uint64_t evaluations = 0;
  std::uint64_t bytes() const;
};

// For each material its TabSet index (INVALID_INDEX for delta models) in setIndexPerMaterial.
// Identical (model, params) share one set. Tables are built in parallel (no disk cache: a set of
// 90 tables takes about 6 M evaluations of f).
TabulatedTables buildTabulatedTables(const std::vector<std::pair<std::uint32_t, shared::BrdfParams>>& materials,
                                     const TabulatedSettings& settings, std::vector<std::uint32_t>& setIndexPerMaterial);

// While alive, tabSample / tabPdf / tabAlbedo called from this thread read `tables`.
class TabHostScope {
 public:
  explicit TabHostScope(const TabulatedTables& tables);
  ~TabHostScope();
  TabHostScope(const TabHostScope&) = delete;
  TabHostScope& operator=(const TabHostScope&) = delete;

 private:
  shared::TabHost m_host;
  shared::TabHost* m_previous;
};

}  // namespace nusselt::sampling
