// roughness_bins.cpp: see roughness_bins.h.
#include "quadtree/roughness_bins.h"

#include "util/error.h"

namespace nusselt::quadtree {

using namespace shared;

std::vector<std::pair<std::uint32_t, BrdfParams>> roughnessBinMaterials(RoughnessBins B) {
  std::vector<std::pair<std::uint32_t, BrdfParams>> m;
  for (std::uint32_t j = 0; j < B.count; ++j) m.push_back({MODEL_GLTF_PBR, binParams(binRoughness(B, j))});
  return m;
}

SamplerTables buildRoughnessBinTables(RoughnessBins B, const QuadtreeSettings& settings) {
  if (B.first != 0u || B.count < 2u) throw Error("internal: roughness bins must be sets 0 .. K - 1, K >= 2");
  std::vector<std::uint32_t> idx;
  SamplerTables t = buildSamplerTables(roughnessBinMaterials(B), settings, idx);
  for (std::uint32_t j = 0; j < B.count; ++j)
    if (idx[j] != j) throw Error("internal: the roughness bins are not the first quadtree sets");
  return t;
}

}  // namespace nusselt::quadtree
