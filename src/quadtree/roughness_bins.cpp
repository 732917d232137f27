// roughness_bins.cpp: see roughness_bins.h.
#include "quadtree/roughness_bins.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "util/error.h"

namespace nusselt::quadtree {

using namespace shared;

std::vector<std::pair<std::uint32_t, BrdfParams>> roughnessBinMaterials(RoughnessBins B) {
  std::vector<std::pair<std::uint32_t, BrdfParams>> m;
  for (std::uint32_t j = 0; j < B.count; ++j) m.push_back({MODEL_GLTF_PBR, binParams(binRoughness(B, j))});
  return m;
}

namespace {

constexpr std::uint32_t kMomentGrid = 64;  // points per axis of the moments' quadratures

// A5 of the pure lobe at roughness r for the known direction wo: midpoint rule over (u1, u2) mapped
// to half vectors by GGX's inverse CDF (tan^2 theta_h = alpha^2 u1 / (1 - u1)), each point the weight
// f cos / pdf of the sampled wi with f = gltf_pbr with baseColor 0, metallic 1 (F = (1 - v.h)^5).
double fresnelLobeAlbedo(float r, vec3 wo) {
  BrdfParams p = binParams(r);
  p.v[0] = vec4(0.0f, 0.0f, 0.0f, 1.0f);
  const float alpha = std::max(r * r, 1e-3f);
  double sum = 0;
  for (std::uint32_t i = 0; i < kMomentGrid; ++i)
    for (std::uint32_t k = 0; k < kMomentGrid; ++k) {
      const double u1 = (i + 0.5) / kMomentGrid, phi = 2 * M_PI * (k + 0.5) / kMomentGrid;
      const double t2 = double(alpha) * alpha * u1 / (1 - u1);
      const double ch = 1 / std::sqrt(1 + t2), sh = std::sqrt(std::max(0.0, 1 - ch * ch));
      const vec3 h(float(sh * std::cos(phi)), float(sh * std::sin(phi)), float(ch));
      const float oh = dot(wo, h);
      if (!(oh > 0.0f)) continue;
      const vec3 wi = 2.0f * oh * h - wo;
      if (!(wi.z > 0.0f)) continue;
      const double pdf = double(ggxD(h, alpha)) * ch / (4.0 * oh);
      if (!(pdf > 0)) continue;
      sum += double(luminance(gltfPbrEval(p, wi, wo))) * wi.z / pdf;
    }
  return sum / (double(kMomentGrid) * kMomentGrid);
}

// B5 for wo: midpoint rule over the cosine-weighted hemisphere.
double fresnelCosineMoment(vec3 wo) {
  double sum = 0;
  for (std::uint32_t i = 0; i < kMomentGrid; ++i)
    for (std::uint32_t k = 0; k < kMomentGrid; ++k) {
      const vec3 wi = squareToCosineHemisphere(vec2(float((i + 0.5) / kMomentGrid), float((k + 0.5) / kMomentGrid)));
      sum += std::pow(1.0 - double(brdfHalfCos(wi, wo)), 5.0);
    }
  return sum / (double(kMomentGrid) * kMomentGrid);
}

std::uint32_t unorm16(double x) { return std::uint32_t(std::lround(std::clamp(x, 0.0, 1.0) * 65535.0)); }

}  // namespace

void setRoughnessBinMoments(SamplerTables& tables, RoughnessBins B) {
  for (std::uint32_t j = 0; j < B.count; ++j) {
    const QuadSet& S = tables.sets.at(B.first + j);
    if ((S.info.w & (QT_SET_ANISOTROPIC | QT_SET_TRANSMITS)) != 0u)
      throw Error("internal: a roughness bin's set is not that of an isotropic reflecting lobe");
    if (S.info.y != tables.sets.at(B.first).info.y || S.data.y != tables.sets.at(B.first).data.y)
      throw Error("internal: the roughness bins' sets have different theta grids");
    for (std::uint32_t k = 0; k < S.info.y * S.info.z; ++k) tables.tables.at(S.info.x + k);  // in range
  }
  const QuadSet& S0 = tables.sets.at(B.first);
  auto direction = [&](std::uint32_t k) {
    const double theta = double(k) * S0.data.y;
    return vec3(float(std::sin(theta)), 0.0f, float(std::cos(theta)));
  };
  std::vector<double> b5(S0.info.y);  // B5 per theta table: the same for every bin
  for (std::uint32_t k = 0; k < S0.info.y; ++k) b5[k] = fresnelCosineMoment(direction(k));
  // A5 per (bin, table), on every core: each writes its own tables (a deterministic result).
  std::atomic<std::uint32_t> next{0};
  auto work = [&]() {
    for (std::uint32_t job; (job = next.fetch_add(1)) < B.count * S0.info.y;) {
      const std::uint32_t j = job / S0.info.y, k = job % S0.info.y;
      const QuadSet& S = tables.sets[B.first + j];
      const std::uint32_t packed = unorm16(fresnelLobeAlbedo(binRoughness(B, j), direction(k))) | (unorm16(b5[k]) << 16);
      for (std::uint32_t i = 0; i < S.info.z; ++i) tables.tables[S.info.x + k * S.info.z + i].info.w = packed;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < std::max(1u, std::thread::hardware_concurrency()); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

SamplerTables buildRoughnessBinTables(RoughnessBins B, const QuadtreeSettings& settings) {
  if (B.first != 0u || B.count < 2u) throw Error("internal: roughness bins must be sets 0 .. K - 1, K >= 2");
  std::vector<std::uint32_t> idx;
  SamplerTables t = buildSamplerTables(roughnessBinMaterials(B), settings, idx);
  for (std::uint32_t j = 0; j < B.count; ++j)
    if (idx[j] != j) throw Error("internal: the roughness bins are not the first quadtree sets");
  setRoughnessBinMoments(t, B);
  return t;
}

}  // namespace nusselt::quadtree
