// material_table.h: the materials as the GPU sees them, and what shading them takes: the shade
// slots (one specialised shade pipeline and queue per model, or per tuple of models of a combined
// material, that the scene uses), the GPU materials and components, and the sampling plan (the
// quadtree or tabulated sampler's tables of every non-delta material and component, built or
// loaded from the cache). Tables are built first; the materials are packed once, with their table
// sets, and uploaded once.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "../../shaders/shared/quadtree_layout.h"
#include "render/settings.h"
#include "scene/scene.h"
#include "vk/vk.h"

namespace nusselt {

namespace shared {
struct Globals;
}

// What building the sampling plan took (for the render summary and the benchmarks).
struct SamplerPlanSummary {
  double seconds = 0;  // building (or loading) the tables
  std::uint32_t tables = 0;
  std::uint64_t bytes = 0;
  std::uint32_t cacheHits = 0, cacheMisses = 0, cacheRejected = 0;
  // Binned sampling (RenderSettings::roughnessBins): the bins built (0: the scene has no material
  // that needs them, or no bins) and their sets' bytes (included in bytes).
  std::uint32_t roughnessBins = 0;
  std::uint64_t binBytes = 0;
  // Materials and components whose BRDF does not depend on the sampled direction (lambert): under
  // the quadtree they get no table and are sampled by cosine, the uniform disc their tree would be
  // (quadtree::constantInSampledDirection).
  std::uint32_t constantBrdfs = 0;
};

class MaterialTable {
 public:
  // Throws nusselt::Error for a material with too many components or a scene with more distinct
  // shade slots than MAX_MODEL_SLOTS.
  MaterialTable(vk::Context& ctx, const Scene& scene, const RenderSettings& settings);
  ~MaterialTable();
  MaterialTable(const MaterialTable&) = delete;
  MaterialTable& operator=(const MaterialTable&) = delete;

  // Key of each shade slot: {0, model} (single model) or {n, model_0, ..., model_{n-1}} (combined),
  // sorted, so single-model slots keep the order of their model ids.
  const std::vector<std::vector<std::uint32_t>>& slotKeys() const { return m_slotKeys; }
  // The slots' names: the model, or the component models joined by "+".
  const std::vector<std::string>& slotNames() const { return m_slotNames; }
  std::size_t materials() const { return m_materialCount; }
  const SamplerPlanSummary& samplerPlan() const { return m_plan; }
  std::uint64_t deviceBytes() const;

  // Material, component and sampler-table addresses and the material count in the globals.
  void fillGlobals(shared::Globals& g) const;

 private:
  vk::Context& m_ctx;
  std::vector<std::vector<std::uint32_t>> m_slotKeys;
  std::vector<std::string> m_slotNames;
  std::size_t m_materialCount = 0;
  SamplerPlanSummary m_plan;
  vk::Buffer m_materials, m_components;
  vk::Buffer m_quadSets, m_quadTables, m_quadNodes, m_quadLeaves;
  vk::Buffer m_tabSets, m_tabTables, m_tabData;
  vk::Buffer m_measured;  // measured BRDF tables (merl), MERL_TABLE_FLOATS floats each
  shared::RoughnessBins m_bins{0u, 0u, 1.0f, 0u};  // Globals.roughnessBins
  bool m_textured = false;  // some used material has a texture that applies, or alpha
  bool m_alpha = false;     // some used material has alphaMode MASK or BLEND
  vk::Buffer m_textures, m_texels, m_materialTextures;  // texture_table.h; one entry each without textures
};

}  // namespace nusselt
