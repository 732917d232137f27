// roughness_bins.h: the roughness bins of binned sampling (shaders/shared/bsdf_sampling.h, "Binned
// sampling"; issue 18): the materials whose trees they are, for the render's table build
// (src/render/material_table.cpp), `nusselt sample --roughness-bins`, `nusselt bench bins` and the tests.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "../../shaders/shared/bsdf_sampling.h"
#include "quadtree/sampler_tables.h"

namespace nusselt::quadtree {

// The bins' materials in order: gltf_pbr's pure specular lobe (binParams) at binRoughness(B, j),
// j = 0 .. B.count - 1. Built first in a buildSamplerTables list, they are sets 0 .. B.count - 1.
std::vector<std::pair<std::uint32_t, shared::BrdfParams>> roughnessBinMaterials(shared::RoughnessBins B);

// Writes the Fresnel moments of every table of the bins' sets B.first .. into QuadTable.info.w
// (bsdf_sampling.h, binFresnelMoments, which binnedDiffuseChoice reads): A5, the albedo of bin j's
// lobe at the table's direction weighted by (1 - v.h)^5, by a quadrature over GGX's distribution
// of half vectors (64 x 64 points, which follow the lobe whatever its width, the near-mirror r = 0 bin included),
// and B5 = (1 / pi) * integral of (1 - v.h)^5 cos theta_i, by a quadrature over the cosine. Every
// table, built or not (onlyThetaTables), from its direction on the grid; on every core.
void setRoughnessBinMoments(SamplerTables& tables, shared::RoughnessBins B);

// The bins alone (B.first must be 0): their tables built with `settings`, with their moments.
SamplerTables buildRoughnessBinTables(shared::RoughnessBins B, const QuadtreeSettings& settings);

}  // namespace nusselt::quadtree
