// material_table.cpp: shade slots, the sampling plan and the GPU materials of a scene.
#include "render/material_table.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "../../shaders/shared/brdf/dispatch.h"
#include "../../shaders/shared/bsdf_sampling.h"
#include "../../shaders/shared/layout.h"
#include "brdf/albedo.h"
#include "brdf/merl.h"
#include "quadtree/roughness_bins.h"
#include "quadtree/sampler_tables.h"
#include "render/texture_table.h"
#include "sampling/tabulated.h"
#include "util/error.h"

namespace nusselt {

using shared::GpuComponent;
using shared::GpuMaterial;

namespace {

glm::vec4 v4(glm::vec3 v, float w = 0.0f) { return glm::vec4(v, w); }

// {0, model} for a single-model material, {n, model_0, ..., model_{n-1}} for a combined one (one
// pipeline per tuple of component models, in the material's order).
std::vector<std::uint32_t> slotKey(const Material& m) {
  if (!m.combined()) return {0u, m.model};
  std::vector<std::uint32_t> key{static_cast<std::uint32_t>(m.components.size())};
  for (const MaterialComponent& c : m.components) key.push_back(c.model);
  return key;
}

// A component's directional albedo at cos theta_o = i / (COMPONENT_ALBEDO_NODES - 1), for the
// choice of a component before anything is sampled (any positive function of wo keeps the
// estimator unbiased; the albedo keeps the weights near 1): its largest RGB channel under the
// throughput roulette (combined.h: no channel is amplified), its luminance under the albedo
// roulette. Floored at 1e-4 so that no component whose BRDF is not zero is ever left unsampled.
void tabulateComponentAlbedo(GpuComponent& c, bool maxChannel) {
  float table[COMPONENT_ALBEDO_NODES];
  for (std::uint32_t n = 0; n < COMPONENT_ALBEDO_NODES; ++n) {
    double cosTheta = std::max(double(n) / (COMPONENT_ALBEDO_NODES - 1), 0.02);
    double thetaDeg = std::acos(cosTheta) * 180.0 / M_PI;
    double a;
    if (shared::modelTransmits(c.info.x) && !shared::modelIsDelta(c.info.x)) {
      // A transmitting component scatters below the surface too: R + T (T with the BSDF's own
      // radiance scaling, as the quadtree's lower disc holds it).
      double rgb[3];
      directionalAlbedoRgb(c.info.x, c.params, thetaDeg, 0.0, rgb);
      const shared::vec3 wi(float(std::sin(thetaDeg * M_PI / 180.0)), 0.0f, float(cosTheta));
      for (int k = 0; k < 3; ++k)
        rgb[k] += hemisphereIntegral(
            [&](shared::vec3 w) { return double(shared::brdfEval(c.info.x, c.params, wi, shared::vec3(w.x, w.y, -w.z))[k]); },
            thetaDeg, 0.0, 1e-4);
      a = maxChannel ? std::max(rgb[0], std::max(rgb[1], rgb[2]))
                     : double(shared::luminance(shared::vec3(float(rgb[0]), float(rgb[1]), float(rgb[2]))));
    } else if (maxChannel) {
      double rgb[3];
      directionalAlbedoRgb(c.info.x, c.params, thetaDeg, 0.0, rgb);
      a = std::max(rgb[0], std::max(rgb[1], rgb[2]));
    } else {
      a = directionalAlbedo(c.info.x, c.params, thetaDeg);
    }
    table[n] = std::isfinite(a) ? std::max(float(a), 1e-4f) : 1e-4f;
  }
  c.albedoLo = glm::vec4(table[0], table[1], table[2], table[3]);
  c.albedoHi = glm::vec4(table[4], table[5], table[6], table[7]);
}

}  // namespace

MaterialTable::MaterialTable(vk::Context& ctx, const Scene& scene, const RenderSettings& settings) : m_ctx(ctx) {
  m_materialCount = scene.materials.size();
  std::vector<bool> used(std::max<std::size_t>(scene.materials.size(), 1), false);
  for (std::uint32_t m : scene.triangleMaterial) used.at(m) = true;

  // ---- The shade slots this render needs ----
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials[i];
    if (m.components.size() > MAX_COMPONENTS)
      throw Error("material " + m.name + ": " + std::to_string(m.components.size()) + " components, at most " +
                  std::to_string(MAX_COMPONENTS));
    // A transmitting non-delta model (rough_dielectric), alone or as a component of a combined
    // material, renders with the quadtree sampler, whose transmitting sets cover both hemispheres
    // (the shade stage continues paths and takes light samples below the surface, from either
    // side; a component's choice albedo counts R + T). Refused rather than rendered as its
    // reflection alone under the other strategies (they sample the upper hemisphere only).
    // docs/models.md, "rough_dielectric".
    auto refuseRoughTransmission = [&](std::uint32_t model) {
      if (shared::modelTransmits(model) && !modelById(model).delta && settings.sampler != SamplerKind::Quadtree)
        throw Error("material " + m.name + ": model " + modelById(model).name +
                    " transmits through a rough surface, which only the quadtree sampler samples (--sampler "
                    "quadtree); the " + std::string(enumName(kSamplerNames, settings.sampler)) +
                    " strategy samples the upper hemisphere only");
    };
    if (m.combined())
      for (const MaterialComponent& c : m.components) refuseRoughTransmission(c.model);
    else
      refuseRoughTransmission(m.model);
    std::vector<std::uint32_t> key = slotKey(m);
    if (std::find(m_slotKeys.begin(), m_slotKeys.end(), key) == m_slotKeys.end()) m_slotKeys.push_back(key);
  }
  std::sort(m_slotKeys.begin(), m_slotKeys.end());
  if (m_slotKeys.size() > MAX_MODEL_SLOTS)
    throw Error("the scene uses " + std::to_string(m_slotKeys.size()) +
                " distinct models and combinations of models, at most " + std::to_string(MAX_MODEL_SLOTS));
  for (const auto& key : m_slotKeys) {
    std::string name;
    for (std::size_t k = 1; k < key.size(); ++k) name += (k > 1 ? "+" : "") + modelById(key[k]).name;
    m_slotNames.push_back(name);
  }

  // ---- The sampling plan: tables for the non-delta materials and components the scene uses
  // (identical (model, params) share a set), built before the materials are packed ----
  struct TableUse {
    std::uint32_t material;
    int component;  // -1: the material itself; kInsideUse: a transmitting material seen from the inside
  };
  constexpr int kInsideUse = -2;
  // Component k of a combined material seen from the inside (a transmitting component's tables
  // for transmissionInsideParams, GpuComponent.info.w).
  auto insideComponentUse = [](std::size_t k) { return -3 - static_cast<int>(k); };
  std::vector<std::pair<std::uint32_t, shared::BrdfParams>> toBuild;
  std::vector<TableUse> uses;
  // Binned sampling: gltf_pbr materials whose textures vary their parameters share K sets of the
  // pure specular lobe (binParams at binRoughness), built first so that they are sets 0 .. K - 1
  // (buildSamplerTables numbers distinct parameter blocks in order of first use).
  auto binnedMaterial = [&](std::size_t i) {
    const Material& m = scene.materials[i];
    return used[i] && settings.sampler == SamplerKind::Quadtree && settings.roughnessBins >= 2 && !m.combined() &&
           m.model == MODEL_GLTF_PBR && textureUse(m, scene).paramsVary();
  };
  // ... and the gltf_pbr components of combined materials whose textures vary them (GpuComponent.info.z).
  auto binnedComponent = [&](std::size_t i, std::size_t k) {
    const Material& m = scene.materials[i];
    return used[i] && settings.sampler == SamplerKind::Quadtree && settings.roughnessBins >= 2 && m.combined() &&
           m.components[k].model == MODEL_GLTF_PBR && textureUse(m, scene).paramsVary();
  };
  bool anyBinned = false;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    anyBinned = anyBinned || binnedMaterial(i);
    for (std::size_t k = 0; k < scene.materials[i].components.size(); ++k) anyBinned = anyBinned || binnedComponent(i, k);
  }
  if (anyBinned) {
    if (!(settings.roughnessBinSpacing > 0.0f) || !std::isfinite(settings.roughnessBinSpacing))
      throw Error("the roughness bins' spacing must be a positive number");
    m_bins = shared::RoughnessBins{0u, settings.roughnessBins, settings.roughnessBinSpacing, 0u};
    toBuild = quadtree::roughnessBinMaterials(m_bins);
    for (std::uint32_t j = 0; j < settings.roughnessBins; ++j) uses.push_back({INVALID_INDEX, static_cast<int>(j)});
  }
  // A BRDF that does not depend on the sampled direction (lambert): its quadtree would be the
  // uniform disc, which cosine sampling draws exactly and faster, so the quadtree gives it no
  // table (INVALID_INDEX: effectiveSampler takes cosine; constantInSampledDirection).
  auto constantBrdf = [&](std::uint32_t model, const shared::BrdfParams& params) {
    if (settings.sampler != SamplerKind::Quadtree || !quadtree::constantInSampledDirection(model, params)) return false;
    ++m_plan.constantBrdfs;
    return true;
  };
  if (settings.sampler == SamplerKind::Quadtree || settings.sampler == SamplerKind::Tabulated)
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
      if (!used[i]) continue;
      const Material& m = scene.materials[i];
      // A texture that varies the BRDF's parameters over the surface: no one table fits
      // (INVALID_INDEX): gltf_pbr under the quadtree samples the roughness bins above
      // (MATERIAL_BINNED), the rest falls back to cosine (docs/scenes.md, "Sampling textured materials").
      if (!m.combined() && !modelById(m.model).delta && !textureUse(m, scene).paramsVary() &&
          !constantBrdf(m.model, m.params)) {
        toBuild.push_back({m.model, m.params});
        uses.push_back({static_cast<std::uint32_t>(i), -1});
        // A transmitting model's tables for the inside too (its parameters seen from there,
        // transmissionInsideParams: rough_dielectric's 1 / eta), GpuMaterial.components.z.
        if (shared::modelTransmits(m.model)) {
          toBuild.push_back({m.model, shared::transmissionInsideParams(m.model, m.params)});
          uses.push_back({static_cast<std::uint32_t>(i), kInsideUse});
        }
      }
      // A textured gltf_pbr component has no table either: the roughness bins above under the
      // quadtree, else cosine (MaterialTextureUse::paramsVary).
      const bool pbrVaries = textureUse(m, scene).paramsVary();
      for (std::size_t k = 0; k < m.components.size(); ++k)
        if (!modelById(m.components[k].model).delta && !(pbrVaries && m.components[k].model == MODEL_GLTF_PBR) &&
            !constantBrdf(m.components[k].model, m.components[k].params)) {
          toBuild.push_back({m.components[k].model, m.components[k].params});
          uses.push_back({static_cast<std::uint32_t>(i), static_cast<int>(k)});
          if (shared::modelTransmits(m.components[k].model)) {
            toBuild.push_back(
                {m.components[k].model, shared::transmissionInsideParams(m.components[k].model, m.components[k].params)});
            uses.push_back({static_cast<std::uint32_t>(i), insideComponentUse(k)});
          }
        }
    }
  std::vector<std::uint32_t> setOf(toBuild.size(), INVALID_INDEX);
  quadtree::SamplerTables qt;
  sampling::TabulatedTables tab;
  if (!toBuild.empty() && settings.sampler == SamplerKind::Tabulated) {
    // Memory budget: the default 64 KiB per table (90 x 180 cells; docs/strategies.md). Sizing each
    // material's tables like its quadtree (bytesPerTableLike) would need the quadtree built first
    // (seconds to minutes per material when the cache is cold), so renders use the default.
    tab = sampling::buildTabulatedTables(toBuild, sampling::TabulatedSettings{}, setOf);
    m_plan.seconds = tab.seconds;
    m_plan.tables = static_cast<std::uint32_t>(tab.tables.size());
    m_plan.bytes = tab.bytes();
  } else if (!toBuild.empty()) {
    quadtree::QuadtreeSettings qs;
    // The bins' trees are looked up at any texel's wo: full tables (the settings' counts).
    qs.thetaTables = std::max(1u, settings.samplerThetaTables);
    qs.phiTables = std::max(2u, settings.samplerPhiTables);
    if (settings.notice)
      qs.beforeBuild = [&settings](std::size_t materials, std::size_t tables) {
        const std::string dir = quadtree::cacheDirectory();
        settings.notice("sampler: building the quadtrees of " + std::to_string(materials) + " material" +
                        (materials == 1 ? "" : "s") + " (" + std::to_string(tables) + " tables; " +
                        (dir.empty() ? "no writable cache directory" : "cached in " + dir + " for later renders") +
                        "): a first build can take minutes for some models, see docs/sampler.md");
      };
    qt = quadtree::buildSamplerTables(toBuild, qs, setOf);
    m_plan.seconds = qt.seconds;
    m_plan.tables = static_cast<std::uint32_t>(qt.tables.size());
    m_plan.bytes = qt.bytes();
    m_plan.cacheHits = qt.cacheHits;
    m_plan.cacheMisses = qt.cacheMisses;
    m_plan.cacheRejected = qt.cacheRejected;
  }
  if (anyBinned) {
    for (std::uint32_t j = 0; j < m_bins.count; ++j)
      if (setOf[j] != j) throw Error("internal: the roughness bins are not the first quadtree sets");
    quadtree::setRoughnessBinMoments(qt, m_bins);
    m_plan.roughnessBins = m_bins.count;
    for (const quadtree::MaterialStats& st : qt.materials)
      if (st.set < m_bins.count) m_plan.binBytes += st.bytes;
  }
  // The set of each material and component: the quadtree's QuadSet or the tabulated TabSet (the
  // shade stage passes it to bsdfSample as the set of the strategy it is specialised for).
  auto setFor = [&](std::uint32_t material, int component) {
    for (std::size_t u = 0; u < uses.size(); ++u)
      if (uses[u].material == material && uses[u].component == component) return setOf[u];
    return INVALID_INDEX;
  };

  // ---- Measured tables (merl): each distinct table once, in the order first used; the GPU blocks
  // carry the table's index in this buffer instead of the CPU store's slot ----
  std::vector<std::uint32_t> measuredSlots;
  auto gpuMeasured = [&](std::uint32_t model, shared::BrdfParams& p) {
    if (model != MODEL_MERL) return;
    std::uint32_t cpuSlot = merlSlot(p);
    auto it = std::find(measuredSlots.begin(), measuredSlots.end(), cpuSlot);
    std::uint32_t index = static_cast<std::uint32_t>(it - measuredSlots.begin());
    if (it == measuredSlots.end()) measuredSlots.push_back(cpuSlot);
    p.v[0][MERL_SLOT] = static_cast<float>(index);
  };

  // ---- GPU materials and components, packed once ----
  const bool maxChannelChoice = settings.roulette == RouletteMode::Throughput;
  std::vector<GpuMaterial> materials(std::max<std::size_t>(scene.materials.size(), 1));
  std::vector<GpuComponent> components;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& src = scene.materials[i];
    GpuMaterial& dst = materials[i];
    std::uint32_t slot = 0;
    std::vector<std::uint32_t> key = slotKey(src);
    for (std::uint32_t s = 0; s < m_slotKeys.size(); ++s)
      if (m_slotKeys[s] == key) slot = s;
    std::uint32_t flags = 0;
    if (src.emits()) flags |= MATERIAL_EMISSIVE;
    bool allDelta = true;
    for (const MaterialComponent& c : src.components) allDelta = allDelta && modelById(c.model).delta;
    if (src.combined() ? allDelta : modelById(src.model).delta) flags |= MATERIAL_DELTA;
    if (src.combined()) flags |= MATERIAL_COMBINED;
    if (used[i] && textureUse(src, scene).any()) flags |= MATERIAL_TEXTURED;
    if (used[i] && textureUse(src, scene).alpha) flags |= MATERIAL_ALPHA;
    if (src.absorbs()) flags |= MATERIAL_ABSORBING;
    if (binnedMaterial(i)) flags |= MATERIAL_BINNED;
    const std::uint32_t material = static_cast<std::uint32_t>(i);
    dst.info = glm::uvec4(src.combined() ? src.components[0].model : src.model, flags,
                          src.combined() ? INVALID_INDEX : setFor(material, -1), slot);
    dst.emission = v4(src.emission);
    dst.absorption = v4(src.absorption);
    dst.params = src.params;
    if (used[i] && !src.combined()) gpuMeasured(src.model, dst.params);
    dst.components = glm::uvec4(0u);
    if (!src.combined() && shared::modelTransmits(src.model)) dst.components.z = setFor(material, kInsideUse);
    if (!src.combined() || !used[i]) continue;
    dst.components = glm::uvec4(static_cast<std::uint32_t>(components.size()),
                                static_cast<std::uint32_t>(src.components.size()), 0u, 0u);
    for (std::size_t k = 0; k < src.components.size(); ++k) {
      const MaterialComponent& c = src.components[k];
      GpuComponent gc{};
      gc.info = glm::uvec4(c.model, setFor(material, static_cast<int>(k)), binnedComponent(i, k) ? 1u : 0u,
                           shared::modelTransmits(c.model) && !modelById(c.model).delta
                               ? setFor(material, insideComponentUse(k))
                               : INVALID_INDEX);
      gc.data = glm::vec4(c.weight, 0.0f, 0.0f, 0.0f);
      gc.params = c.params;
      // Every non-delta component gets its albedo table under the throughput roulette; under the
      // albedo roulette quadtree components read their set's table (quadAlbedo) instead.
      const bool delta = modelById(c.model).delta;
      const bool readsQuadAlbedo = settings.sampler == SamplerKind::Quadtree && gc.info.y != INVALID_INDEX;
      if (!delta && (maxChannelChoice || !readsQuadAlbedo)) tabulateComponentAlbedo(gc, maxChannelChoice);
      gpuMeasured(c.model, gc.params);
      components.push_back(gc);
    }
  }

  // ---- Device buffers ----
  auto make = [&](vk::Buffer& b, std::size_t count, std::size_t stride, const char* what, const void* data) {
    const VkDeviceSize bytes = std::max<std::size_t>(count, 1) * stride;
    b = vk::createBuffer(m_ctx, bytes, 0, false, what);
    if (data && count) vk::uploadBuffer(m_ctx, b, data, count * stride);
  };
  make(m_materials, materials.size(), sizeof(GpuMaterial), "material", materials.data());
  make(m_components, components.size(), sizeof(GpuComponent), "material components", components.data());
  make(m_quadSets, qt.sets.size(), sizeof(shared::QuadSet), "quadtree sets", qt.sets.data());
  make(m_quadTables, qt.tables.size(), sizeof(shared::QuadTable), "quadtree tables", qt.tables.data());
  make(m_quadNodes, qt.nodes.size(), sizeof(shared::QuadNode), "quadtree nodes", qt.nodes.data());
  make(m_quadLeaves, qt.leaves.size(), sizeof(shared::QuadLeaf), "quadtree leaves", qt.leaves.data());
  make(m_tabSets, tab.sets.size(), sizeof(shared::TabSet), "tabulated sets", tab.sets.data());
  make(m_tabTables, tab.tables.size(), sizeof(shared::TabTable), "tabulated tables", tab.tables.data());
  make(m_tabData, tab.data.size(), sizeof(float), "tabulated cdfs", tab.data.data());
  // Textures: one-entry buffers when the scene has none.
  const TextureData textures = buildTextureData(scene);
  m_textured = !textures.materials.empty();
  m_alpha = sceneUsesAlpha(scene);
  make(m_textures, textures.textures.size(), sizeof(shared::GpuTexture), "textures", textures.textures.data());
  make(m_texels, textures.texels.size(), sizeof(std::uint32_t), "texels", textures.texels.data());
  make(m_materialTextures, textures.materials.size(), sizeof(shared::GpuMaterialTextures), "material textures",
       textures.materials.data());
  m_measured = vk::createBuffer(m_ctx, std::max<std::size_t>(measuredSlots.size() * MERL_TABLE_FLOATS, 1) * sizeof(float), 0,
                                false, "measured tables");
  for (std::size_t k = 0; k < measuredSlots.size(); ++k) {
    shared::BrdfParams p{};
    p.v[0][MERL_SLOT] = static_cast<float>(measuredSlots[k]);
    vk::uploadBuffer(m_ctx, m_measured, merlTable(p).rgb.data(), MERL_TABLE_FLOATS * sizeof(float),
                     k * MERL_TABLE_FLOATS * sizeof(float));
  }
}

MaterialTable::~MaterialTable() {
  for (vk::Buffer* b : {&m_materials, &m_components, &m_quadSets, &m_quadTables, &m_quadNodes, &m_quadLeaves,
                        &m_tabSets, &m_tabTables, &m_tabData, &m_measured, &m_textures, &m_texels, &m_materialTextures})
    vk::destroyBuffer(m_ctx, *b);
}

std::uint64_t MaterialTable::deviceBytes() const {
  std::uint64_t total = 0;
  for (const vk::Buffer* b : {&m_materials, &m_components, &m_quadSets, &m_quadTables, &m_quadNodes, &m_quadLeaves,
                              &m_tabSets, &m_tabTables, &m_tabData, &m_measured, &m_textures, &m_texels, &m_materialTextures})
    total += b->size;
  return total;
}

void MaterialTable::fillGlobals(shared::Globals& g) const {
  g.materials = m_materials.address;
  g.components = m_components.address;
  g.quadSets = m_quadSets.address;
  g.quadTables = m_quadTables.address;
  g.quadNodes = m_quadNodes.address;
  g.quadLeaves = m_quadLeaves.address;
  g.tabSets = m_tabSets.address;
  g.tabTables = m_tabTables.address;
  g.tabData = m_tabData.address;
  g.measured = m_measured.address;
  g.textures = m_textures.address;
  g.texels = m_texels.address;
  g.materialTextures = m_materialTextures.address;
  g.texturedScene = m_textured ? 1u : 0u;
  g.alphaScene = m_alpha ? 1u : 0u;
  g.materialCount = static_cast<std::uint32_t>(std::max<std::size_t>(m_materialCount, 1));
  g.roughnessBins = m_bins;
}

}  // namespace nusselt
