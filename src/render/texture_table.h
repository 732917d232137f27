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
  // baseColor: RGB x baseColor of a gltf_pbr material or component, and x tint of a transmitting
  // one (dielectric, thin_dielectric, rough_dielectric: glTF's tinted transmission).
  bool baseColor = false;
  bool metallicRoughness = false;  // gltf_pbr material or component: G x roughness, B x metallic
  bool emissive = false;           // any material with a non-zero emission: RGB x emission
  bool normal = false;             // any material: the shading normal (needs Scene::tangents)
  bool alpha = false;              // any material: alphaMode MASK or BLEND (coverage in traversal)
  bool transmission = false;       // the transmission combination (Material::transmissionTextured)
  bool any() const { return baseColor || metallicRoughness || emissive || normal || alpha || transmission; }
  // A gltf_pbr material or component whose BRDF's shape varies over the surface (a textured
  // base colour or metallic-roughness): no one sampling table fits it (a single gltf_pbr samples
  // the roughness bins under the quadtree, a component and the rest fall back to cosine). A
  // texture that tints a transmitting model does not count: its tables (for the factors) still
  // cover every direction the textured BSDF scatters to, so they stay an unbiased proposal.
  bool pbrVaries = false;
  bool paramsVary() const { return pbrVaries; }
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

// Both coordinate sets of scene triangle `triangle`'s corners as the GPU holds them ((0, 0) for a
// set the scene lacks).
shared::GpuTriTexcoords packTriTexcoords(const Scene& scene, std::uint32_t triangle);

// The C++ twin of the GPU's alpha test in traversal (alphaPasses, stage_common.glsl), as a hit
// filter for bvhClosestHit (scene/bvh.h): alpha = baseColorFactor.a x the base-colour texture's
// alpha (texture.h's lookup on the packed textures), then shared/alpha.h's rule. `order` is the
// GPU triangle order (Bvh::triangleOrder; BLEND's hash takes the triangle's index in it); empty:
// the scene's order. Holds the scene and the order by reference.
class AlphaTester {
 public:
  AlphaTester(const Scene& scene, const std::vector<std::uint32_t>& order);
  bool operator()(std::uint32_t tri, float b1, float b2, glm::vec3 origin, glm::vec3 dir) const;

 private:
  const Scene& m_scene;
  const std::vector<std::uint32_t>& m_order;
  TextureData m_data;
};

}  // namespace nusselt
