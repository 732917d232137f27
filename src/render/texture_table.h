// texture_table.h: the scene's textures packed for the GPU (shaders/shared/texture_layout.h):
// which textures the renderer applies to each material, the texel buffer (each used image once),
// one GpuTexture per applied texture and the per-material texture blocks. docs/scenes.md,
// "Textures", says what renders and what does not.
#pragma once
#include <cstdint>
#include <vector>

#include "../../shaders/shared/layout.h"
#include "scene/scene.h"

namespace nusselt {

// The textures of a material that the shade stage applies.
struct MaterialTextureUse {
  bool baseColor = false;          // gltf_pbr materials (single-model): baseColor x baseColorFactor
  bool metallicRoughness = false;  // gltf_pbr: G x roughnessFactor, B x metallicFactor
  bool emissive = false;           // any material with a non-zero emission: RGB x emission
  bool normal = false;             // any material: the shading normal (needs Scene::tangents)
  bool alpha = false;              // any material: alphaMode MASK or BLEND (coverage in traversal)
  bool transmission = false;       // the transmission combination (Material::transmissionTextured)
  bool any() const { return baseColor || metallicRoughness || emissive || normal || alpha || transmission; }
  // The BRDF's parameters (not only its emission) vary over the surface: no per-material
  // sampling tables fit it (the quadtree and tabulated samplers fall back to cosine).
  bool paramsVary() const { return baseColor || metallicRoughness; }
};
// scene: for the normal map, which needs the scene's tangents (Scene::tangents per corner).
MaterialTextureUse textureUse(const Material& m, const Scene& scene);

// Some material that a triangle uses has a texture the renderer applies (normal: a normal map).
bool sceneUsesTextures(const Scene& scene);
bool sceneUsesNormalMaps(const Scene& scene);
bool sceneUsesAlpha(const Scene& scene);

// The packed textures. Empty vectors when the scene uses none.
struct TextureData {
  std::vector<shared::GpuTexture> textures;
  std::vector<std::uint32_t> texels;                   // RGBA8, R in the low byte
  std::vector<shared::GpuMaterialTextures> materials;  // one per scene material
};
TextureData buildTextureData(const Scene& scene);
// Device memory of buildTextureData's buffers for this scene, without packing any texel.
std::uint64_t textureDeviceBytes(const Scene& scene);

// One texture record; its texels start at firstTexel of the texel buffer.
shared::GpuTexture packTexture(const TextureRef& ref, const TextureImage& image, std::uint32_t firstTexel);
// An image's texels as the texel buffer holds them.
std::vector<std::uint32_t> packTexels(const TextureImage& image);

}  // namespace nusselt
