// texture_table.cpp: the scene's textures packed for the GPU (texture_table.h).
#include "render/texture_table.h"

#include <map>
#include <set>

#include "../../shaders/shared/alpha.h"
#include "../../shaders/shared/texture.h"
#include "util/error.h"

namespace nusselt {

using shared::GpuMaterialTextures;
using shared::GpuTexture;

MaterialTextureUse textureUse(const Material& m, const Scene& scene) {
  MaterialTextureUse u;
  const bool pbr = m.hasGltfPbr();
  u.baseColor = (pbr || m.hasTintedTransmission()) && m.baseColorTexture.present();
  u.metallicRoughness = pbr && m.metallicRoughnessTexture.present();
  u.pbrVaries = pbr && (m.baseColorTexture.present() || m.metallicRoughnessTexture.present());
  u.emissive = m.emits() && m.emissiveTexture.present();
  u.alpha = m.alphaMode != AlphaMode::Opaque;
  u.transmission = m.transmissionTextured && m.transmissionTexture.present() && m.components.size() == 2;
  u.normal = m.normalTexture.present() && !scene.tangents.empty() && scene.tangents.size() == scene.positions.size();
  return u;
}

namespace {
// The materials some triangle uses.
std::vector<bool> usedMaterials(const Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (std::uint32_t m : scene.triangleMaterial)
    if (m < used.size()) used[m] = true;
  return used;
}

template <class F>
bool anyUsedMaterial(const Scene& scene, F f) {
  const std::vector<bool> used = usedMaterials(scene);
  for (std::size_t i = 0; i < scene.materials.size(); ++i)
    if (used[i] && f(textureUse(scene.materials[i], scene))) return true;
  return false;
}
}  // namespace

bool sceneUsesTextures(const Scene& scene) {
  return anyUsedMaterial(scene, [](const MaterialTextureUse& u) { return u.any(); });
}

bool sceneUsesAlpha(const Scene& scene) {
  return anyUsedMaterial(scene, [](const MaterialTextureUse& u) { return u.alpha; });
}

bool sceneUsesNormalMaps(const Scene& scene) {
  return anyUsedMaterial(scene, [](const MaterialTextureUse& u) { return u.normal; });
}

std::vector<std::uint32_t> packTexels(const TextureImage& image) {
  const std::size_t n = std::size_t(image.width) * image.height;
  if (image.rgba.size() != 4 * n) throw Error("internal: image " + image.name + " has the wrong number of bytes");
  std::vector<std::uint32_t> out(n);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = std::uint32_t(image.rgba[4 * i]) | std::uint32_t(image.rgba[4 * i + 1]) << 8 |
             std::uint32_t(image.rgba[4 * i + 2]) << 16 | std::uint32_t(image.rgba[4 * i + 3]) << 24;
  return out;
}

GpuTexture packTexture(const TextureRef& ref, const TextureImage& image, std::uint32_t firstTexel) {
  GpuTexture t{};
  std::uint32_t flags = static_cast<std::uint32_t>(ref.wrapS) | static_cast<std::uint32_t>(ref.wrapT) << 2;
  // No mipmaps: the magnification filter serves every footprint (docs/scenes.md).
  if (ref.magFilter == FilterMode::Linear) flags |= TEXTURE_FLAG_LINEAR;
  if (ref.colorSpace == ColorSpace::Srgb) flags |= TEXTURE_FLAG_SRGB;
  if (ref.texCoord == 1) flags |= TEXTURE_FLAG_SET1;
  t.info = glm::uvec4(firstTexel, image.width, image.height, flags);
  t.transform0 = glm::vec4(ref.transform[0][0], ref.transform[0][1], ref.transform[1][0], ref.transform[1][1]);
  t.transform1 = glm::vec4(ref.transform[2][0], ref.transform[2][1], 0.0f, 0.0f);
  return t;
}

namespace {
enum TextureSlot { SlotBaseColor, SlotMetallicRoughness, SlotEmissive, SlotNormal, SlotCoverage, SlotTransmission };

// Calls fn(material index, slot, reference, description) for every texture the renderer applies,
// in the order of the texture records: per material (those a triangle uses), baseColor,
// metallicRoughness, emissive, normal, then the coverage map (the base-colour texture read for
// its alpha by a material whose base colour is not textured), then transmission.
template <class F>
void forEachAppliedTexture(const Scene& scene, F fn) {
  const std::vector<bool> used = usedMaterials(scene);
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials[i];
    const MaterialTextureUse u = textureUse(m, scene);
    if (u.baseColor) fn(i, SlotBaseColor, m.baseColorTexture, m.name + " baseColorTexture");
    if (u.metallicRoughness) fn(i, SlotMetallicRoughness, m.metallicRoughnessTexture, m.name + " metallicRoughnessTexture");
    if (u.emissive) fn(i, SlotEmissive, m.emissiveTexture, m.name + " emissiveTexture");
    if (u.normal) fn(i, SlotNormal, m.normalTexture, m.name + " normalTexture");
    if (u.alpha && m.baseColorTexture.present() && !u.baseColor)
      fn(i, SlotCoverage, m.baseColorTexture, m.name + " baseColorTexture (alpha)");
    if (u.transmission) fn(i, SlotTransmission, m.transmissionTexture, m.name + " transmissionTexture");
  }
}

const TextureImage& appliedImage(const Scene& scene, const TextureRef& ref, const std::string& what) {
  if (ref.image < 0 || std::size_t(ref.image) >= scene.images.size())
    throw Error("internal: " + what + " names image " + std::to_string(ref.image) + " of " +
                std::to_string(scene.images.size()));
  const TextureImage& image = scene.images[std::size_t(ref.image)];
  if (image.width == 0 || image.height == 0) throw Error("internal: image " + image.name + " is empty");
  return image;
}
}  // namespace

std::uint64_t textureDeviceBytes(const Scene& scene) {
  if (!sceneUsesTextures(scene)) return 0;
  std::set<std::int32_t> images;
  std::uint64_t texels = 0, records = 0;
  forEachAppliedTexture(scene, [&](std::size_t, TextureSlot, const TextureRef& ref, const std::string& what) {
    const TextureImage& image = appliedImage(scene, ref, what);
    if (images.insert(ref.image).second) texels += std::uint64_t(image.width) * image.height;
    ++records;
  });
  return texels * 4 + records * sizeof(shared::GpuTexture) + scene.materials.size() * sizeof(shared::GpuMaterialTextures);
}

TextureData buildTextureData(const Scene& scene) {
  TextureData d;
  if (!sceneUsesTextures(scene)) return d;
  std::map<std::int32_t, std::uint32_t> firstTexel;  // scene image -> its texels in the buffer
  d.materials.resize(scene.materials.size());
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    GpuMaterialTextures& g = d.materials[i];
    g.maps = glm::uvec4(INVALID_INDEX);
    g.baseColorFactor = m.baseColorFactor;
    g.factors = glm::vec4(m.metallicFactor, m.roughnessFactor, m.normalScale, m.alphaCutoff);
    g.alpha = glm::uvec4(static_cast<std::uint32_t>(m.alphaMode), INVALID_INDEX, 0u, 0u);
    g.transmission = glm::uvec4(INVALID_INDEX, 0u, 0u, 0u);
  }
  forEachAppliedTexture(scene, [&](std::size_t i, TextureSlot slot, const TextureRef& ref, const std::string& what) {
    const TextureImage& image = appliedImage(scene, ref, what);
    auto it = firstTexel.find(ref.image);
    if (it == firstTexel.end()) {
      std::vector<std::uint32_t> t = packTexels(image);
      if (d.texels.size() + t.size() > UINT32_MAX) throw Error("the scene's textures exceed 2^32 texels");
      it = firstTexel.emplace(ref.image, std::uint32_t(d.texels.size())).first;
      d.texels.insert(d.texels.end(), t.begin(), t.end());
    }
    d.textures.push_back(packTexture(ref, image, it->second));
    const std::uint32_t index = std::uint32_t(d.textures.size() - 1);
    GpuMaterialTextures& g = d.materials[i];
    switch (slot) {
      case SlotBaseColor: g.maps.x = index; break;
      case SlotMetallicRoughness: g.maps.y = index; break;
      case SlotEmissive: g.maps.z = index; break;
      case SlotNormal: g.maps.w = index; break;
      case SlotCoverage: g.alpha.y = index; break;
      case SlotTransmission: g.transmission.x = index; break;
    }
    // Coverage: the base-colour texture's alpha, for any model (its RGB applies to gltf_pbr and
    // the transmitting models only).
    if (slot == SlotBaseColor && textureUse(scene.materials[i], scene).alpha) g.alpha.y = index;
  });
  return d;
}

shared::GpuTriTexcoords packTriTexcoords(const Scene& scene, std::uint32_t triangle) {
  const bool has0 = scene.texcoords0.size() == scene.positions.size();
  const bool has1 = scene.texcoords1.size() == scene.positions.size();
  glm::vec2 a[3]{}, b[3]{};
  for (std::uint32_t c = 0; c < 3; ++c) {
    if (has0) a[c] = scene.texcoords0[3 * triangle + c];
    if (has1) b[c] = scene.texcoords1[3 * triangle + c];
  }
  shared::GpuTriTexcoords t;
  t.a = glm::vec4(a[0], a[1]);
  t.b = glm::vec4(a[2], b[0]);
  t.c = glm::vec4(b[1], b[2]);
  return t;
}

AlphaTester::AlphaTester(const Scene& scene, const std::vector<std::uint32_t>& order)
    : m_scene(scene), m_order(order), m_data(buildTextureData(scene)) {}

bool AlphaTester::operator()(std::uint32_t tri, float b1, float b2, glm::vec3 origin, glm::vec3 dir) const {
  const std::uint32_t src = m_order.empty() ? tri : m_order[tri];
  const std::uint32_t material = m_scene.triangleMaterial[src];
  // MATERIAL_ALPHA (material_table.cpp): a used material with alphaMode MASK or BLEND.
  if (!textureUse(m_scene.materials[material], m_scene).alpha || m_data.materials.empty()) return true;
  const GpuMaterialTextures& T = m_data.materials[material];
  float alpha = T.baseColorFactor.w;
  if (T.alpha.y != INVALID_INDEX)
    alpha *= shared::textureAtHit(m_data.texels.data(), m_data.textures[T.alpha.y], packTriTexcoords(m_scene, src), b1,
                                  b2).w;
  return shared::alphaTest(T.alpha.x, alpha, T.factors.w, tri, origin, dir);
}

}  // namespace nusselt
