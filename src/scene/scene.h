// scene.h: the renderer's view of a scene, independent of glTF: world-space triangles with
// shading normals, texture coordinates, tangents and a material each, materials (model +
// parameters + emission + textures), decoded texture images, punctual lights and a camera.
// Built by the glTF loader (gltf_loader.h) or by tests directly.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "../brdf/registry.h"

namespace nusselt {

// One term w * f_k of a combined material.
struct MaterialComponent {
  std::uint32_t model = MODEL_LAMBERT;  // MODEL_* id (any catalogue model, delta ones included)
  float weight = 1.0f;                  // finite, >= 0
  BrdfParams params{};                  // packed by packParams()
};

// ---- textures (docs/scenes.md, "Textures") ----

// glTF sampler wrap modes (10497, 33071, 33648).
enum class WrapMode : std::uint32_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };
// Texel filters. glTF's four mipmapped minification filters are reduced to their level filter
// (NEAREST_MIPMAP_* -> Nearest, LINEAR_MIPMAP_* -> Linear): the images carry no mipmaps.
enum class FilterMode : std::uint32_t { Nearest = 0, Linear = 1 };

// How a texture's 8-bit code values become numbers: sRGB-encoded colour (baseColor, emissive:
// decode with the sRGB EOTF) or linear data (metallicRoughness, normal, transmission: v / 255).
// The same image may be used with either; the image itself has no colour space.
enum class ColorSpace : std::uint32_t { Linear = 0, Srgb = 1 };

// One decoded image, 8-bit RGBA (4 bytes per texel, row-major, top row first: texture
// coordinate (0, 0) is the top-left corner of texel (0, 0), (1, 1) the bottom-right corner of the
// last texel). Decoded once, shared by every texture that uses it.
struct TextureImage {
  std::string name;          // the glTF image's name, or its uri, or "images[i]"
  std::uint32_t source = 0;  // index into the glTF file's images
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // 4 * width * height bytes
};

// A material's use of a texture: glTF textureInfo + sampler + KHR_texture_transform.
struct TextureRef {
  std::int32_t image = -1;  // index into Scene::images; -1: no texture (the factor alone)
  WrapMode wrapS = WrapMode::Repeat, wrapT = WrapMode::Repeat;
  FilterMode magFilter = FilterMode::Linear, minFilter = FilterMode::Linear;
  ColorSpace colorSpace = ColorSpace::Linear;  // set by the slot (see ColorSpace)
  std::uint32_t texCoord = 0;  // which set: 0 = Scene::texcoords0, 1 = Scene::texcoords1
  // KHR_texture_transform as a 3x2 matrix (glm: 3 columns of 2 rows): the lookup coordinate is
  // transform * vec3(uv, 1). Identity without the extension.
  glm::mat3x2 transform{1.0f};

  bool present() const { return image >= 0; }
};

enum class AlphaMode : std::uint32_t { Opaque = 0, Mask = 1, Blend = 2 };

struct Material {
  std::string name;
  std::uint32_t model = MODEL_LAMBERT;  // MODEL_* id
  BrdfParams params{};                  // packed by packParams()
  glm::vec3 emission{0.0f};             // emitted radiance [W/(m^2 sr)], front faces only
  // Not empty: a combined material f = sum_k weight_k f_k (at most MAX_COMPONENTS terms; the
  // random-walk source's estimator picks one per bounce, shaders/shared/combined.h). model and
  // params then repeat the first component and are not used for shading.
  std::vector<MaterialComponent> components;

  // ---- glTF 2.0 material data beyond the BRDF parameters (for textures and alpha) ----
  // The factors as the file gives them (params above hold baseColor clamped to [0, 1]; the
  // textures multiply these factors). emissiveTexture multiplies `emission`.
  glm::vec4 baseColorFactor{1.0f};  // RGB linear, A = opacity
  float metallicFactor = 1.0f, roughnessFactor = 1.0f;
  TextureRef baseColorTexture;          // sRGB; RGB x baseColorFactor.rgb, A x baseColorFactor.a
  TextureRef metallicRoughnessTexture;  // linear; G x roughnessFactor, B x metallicFactor
  TextureRef normalTexture;             // linear; tangent space, needs Scene::tangents
  float normalScale = 1.0f;             // scales the sampled normal's x and y
  TextureRef emissiveTexture;           // sRGB; RGB x emission
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;  // MASK: opaque where alpha >= cutoff
  bool doubleSided = false;
  // KHR_materials_transmission: fraction of light transmitted (R channel of the texture).
  float transmissionFactor = 0.0f;
  TextureRef transmissionTexture;       // linear; R x transmissionFactor
  // Set by the loader when transmissionTexture applies: the material is KHR_materials_transmission's
  // combination {gltf_pbr, weight 1 - w; glass, weight w} (w = transmissionFactor x (1 - metallic);
  // in that order, even for w = 1), and the renderer takes w x R (the texture's R at the hit) for
  // the glass and 1 - w x R for gltf_pbr (docs/scenes.md, "Transmission").
  bool transmissionTextured = false;
  // KHR_materials_ior (1.5 without the extension).
  float ior = 1.5f;
  // KHR_materials_volume. hasVolume false, or thicknessFactor 0: a thin-walled surface.
  bool hasVolume = false;
  float thicknessFactor = 0.0f;
  float attenuationDistance = INFINITY;  // metres; infinity: no absorption
  glm::vec3 attenuationColor{1.0f};      // colour after attenuationDistance, in [0, 1]
  // The absorption coefficient sigma_a [1/m] per channel inside the material's volume, >= 0 and
  // finite (shaders/shared/volume.h); zero: none. The loader sets it for a refracting volume
  // (-ln attenuationColor / attenuationDistance). A ray that meets one of the material's
  // triangles from its back (against the geometric normal) has travelled inside and is attenuated
  // by exp(-sigma_a t) over its length t (docs/scenes.md, "Volumes").
  glm::vec3 absorption{0.0f};

  bool combined() const { return !components.empty(); }
  // Emits light (any channel of the emission above zero): the material's triangles are lights.
  bool emits() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
  // Absorbs inside its volume (any channel of absorption above zero).
  bool absorbs() const { return absorption.x > 0.0f || absorption.y > 0.0f || absorption.z > 0.0f; }
  // True when a normal map needs tangents at this material's triangles.
  bool normalMapped() const { return normalTexture.present(); }
  // The models a base-colour or metallic-roughness texture's RGB applies to (docs/scenes.md,
  // "Textures"), as the material's model or one of its components: gltf_pbr (base colour,
  // metallic, roughness) and, for the base colour, the transmitting models dielectric,
  // thin_dielectric and rough_dielectric (their tint: glTF's tinted transmission).
  bool hasGltfPbr() const;
  bool hasTintedTransmission() const;
};

enum class LightType { Point, Spot, Directional };

// KHR_lights_punctual, radiometric reading: colour * intensity is the radiant intensity [W/sr]
// of point and spot lights, and the irradiance [W/m^2] a directional light gives to a surface
// facing it. (The extension specifies candela and lux; we do not convert photometric units.)
struct PunctualLight {
  LightType type = LightType::Point;
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // where the light points (spot, directional)
  glm::vec3 intensity{1.0f};
  float innerConeAngle = 0.0f;             // radians (spot)
  float outerConeAngle = 0.7853981634f;    // radians (spot), glTF default pi/4
};

struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  bool orthographic = false;
  float yfov = 0.8f;                     // radians (perspective)
  float aspectRatio = 0.0f;              // 0: take the image's
  float xmag = 1.0f, ymag = 1.0f;        // half extents (orthographic)
};

// The light from around the scene, seen by rays that escape it (docs/environment.md): none, a
// uniform radiance, or an equirectangular (lat-long) radiance map (shaders/shared/envmap.h for
// its convention).
enum class EnvironmentKind { None, Uniform, Map };
struct Environment {
  EnvironmentKind kind = EnvironmentKind::None;
  std::string path;             // Map: the file it was read from (recorded in the EXR header)
  int width = 0, height = 0;    // Map
  std::vector<float> rgb;       // Map: 3 * width * height linear Rec. 709 radiances, top row first
  glm::vec3 color{0.0f};        // Uniform: the radiance
  float scale = 1.0f;           // radiance multiplier (--env-scale)
  float rotateDegrees = 0.0f;   // rotation about +Y, counter-clockwise seen from above (--env-rotate)
  // How light sampling chooses the environment when the scene has other lights (--env-select):
  // false = half of the light samples (the default), true = in proportion to estimated power.
  bool selectByPower = false;

  bool present() const { return kind != EnvironmentKind::None; }
};

struct Scene {
  std::string sourcePath;
  // Three entries per triangle, world space. Degenerate triangles never get here.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;       // unit shading normals; the geometric normal where absent
  // Per triangle corner like positions, or empty when no primitive of the scene has the
  // attribute. Corners of primitives without it get (0, 0). Finite (non-finite values are
  // replaced by 0 and counted in a warning).
  std::vector<glm::vec2> texcoords0;    // TEXCOORD_0, (0, 0) = top-left of the image
  std::vector<glm::vec2> texcoords1;    // TEXCOORD_1
  // Per triangle corner, or empty when no primitive has TANGENT and no material has a normal
  // map. xyz: unit world-space tangent orthogonal to the corner's shading normal (the direction
  // of increasing u of the normal map's texture coordinate set); w = +1 or -1: the bitangent is
  // w * cross(normal, tangent). From TANGENT when given, generated for normal-mapped primitives
  // without it (docs/scenes.md), and an arbitrary tangent perpendicular to the normal (w = +1)
  // elsewhere.
  std::vector<glm::vec4> tangents;
  std::vector<std::uint32_t> triangleMaterial;  // one per triangle
  std::vector<Material> materials;
  std::vector<TextureImage> images;     // decoded once; TextureRef::image indexes this
  std::vector<PunctualLight> lights;
  Camera camera;
  bool hasCamera = false;  // false: the renderer frames the scene with a default view
  glm::vec3 background{0.0f};  // radiance of escaping rays: a uniform environment when `environment` is None
  Environment environment;
  std::uint64_t droppedTriangles = 0;  // skipped: zero area, non-finite vertex, or a coordinate beyond 1e15
  std::vector<std::string> warnings;   // one line each, printed once by the caller

  std::size_t triangleCount() const { return triangleMaterial.size(); }
};

// The default view when a scene has no camera: looks at the bounding box from the +z side,
// framing it with a 45-degree vertical field of view.
Camera frameScene(const Scene& scene);

// ---- Materials of catalogue models, built in code (tests, benchmarks) ----
// A material of one model: its parameters packed by packParams (those not given take the model's
// defaults). Throws nusselt::Error naming `name` for an unknown model or a bad parameter.
Material catalogueMaterial(const std::string& model, const NamedParams& params, const std::string& name,
                           glm::vec3 emission = glm::vec3(0.0f));
// A term w * f of a combined material (errors name the model).
MaterialComponent catalogueComponent(const std::string& model, const NamedParams& params, float weight = 1.0f);
// Makes m the combination of `components` (model and params repeat the first, as Material says).
void setComponents(Material& m, const std::vector<MaterialComponent>& components);

}  // namespace nusselt
