// texture_layout.h: the glTF textures as the GPU sees them (docs/scenes.md, "Textures"): one
// buffer of texels for every decoded image, one record per texture use of a material, the
// per-material texture block and the per-triangle texture coordinates. Included by layout.h; the
// lookup is shaders/shared/texture.h. Scenes without textures get one-entry buffers and a shade
// stage compiled without any of this (the HAS_TEXTURES specialization constant).
#ifndef NUSSELT_TEXTURE_LAYOUT_H
#define NUSSELT_TEXTURE_LAYOUT_H

#include "prelude.h"

SHARED_BEGIN

// Wrap modes (the values of scene.h's WrapMode) and filters (FilterMode).
#define TEXTURE_WRAP_REPEAT 0u
#define TEXTURE_WRAP_CLAMP 1u
#define TEXTURE_WRAP_MIRROR 2u
// GpuTexture.info.w: bits 0-1 wrap S, bits 2-3 wrap T, then the flags below.
#define TEXTURE_FLAG_LINEAR 16u  // bilinear (else nearest)
#define TEXTURE_FLAG_SRGB 32u    // RGB are sRGB-encoded colour: decode to linear (alpha is always linear)
#define TEXTURE_FLAG_SET1 64u    // TEXCOORD_1 (else TEXCOORD_0)

// One use of an image by a material: glTF textureInfo + sampler + KHR_texture_transform.
// info = (first texel in the texel buffer, width, height, wrap and flags);
// transform = the 3x2 matrix of KHR_texture_transform, column-major: the lookup coordinate is
// (t0.x u + t0.z v + t1.x, t0.y u + t0.w v + t1.y). Texels: RGBA8 packed in one uint each
// (R in the low byte), row-major, top row first: coordinate (0, 0) is the top-left corner of the
// image, (1, 1) its bottom-right corner. No mipmaps: the magnification filter applies at every
// footprint (docs/scenes.md).
struct GpuTexture {
  uvec4 info;
  vec4 transform0;  // (m[0][0], m[0][1], m[1][0], m[1][1])
  vec4 transform1;  // (m[2][0], m[2][1], 0, 0)
};
STATIC_ASSERT_SIZE(GpuTexture, 48);

// The texture data of material i (parallel to the materials buffer, read only when the material
// has MATERIAL_TEXTURED). maps = GpuTexture indices of (baseColor, metallicRoughness, emissive,
// normal), INVALID_INDEX where the material has none or the renderer does not apply it (a normal
// map needs Globals.tangents);
// baseColorFactor = rgba; factors = (metallicFactor, roughnessFactor, normalScale, alphaCutoff);
// alpha = (ALPHA_* mode, the GpuTexture whose alpha multiplies baseColorFactor.a (the base-colour
// texture, for any model) or INVALID_INDEX, 0, 0);
// transmission = (the GpuTexture of KHR_materials_transmission's texture or INVALID_INDEX, 0, 0, 0):
// its R scales the weight of component 1 (the glass) of the transmission combination, and
// component 0 (gltf_pbr) takes the rest (Material::transmissionTextured).
struct GpuMaterialTextures {
  uvec4 maps;
  vec4 baseColorFactor;
  vec4 factors;
  uvec4 alpha;
  uvec4 transmission;
};
STATIC_ASSERT_SIZE(GpuMaterialTextures, 80);

// glTF alphaMode (the values of scene.h's AlphaMode).
#define ALPHA_OPAQUE 0u
#define ALPHA_MASK 1u
#define ALPHA_BLEND 2u

// Texture coordinates of a triangle's corners, both sets (parallel to the triangles buffer):
// a = (set 0 corner 0, set 0 corner 1), b = (set 0 corner 2, set 1 corner 0),
// c = (set 1 corner 1, set 1 corner 2). Kept out of GpuTriangle / GpuTriShading: traversal
// and untextured shading never read them.
struct GpuTriTexcoords {
  vec4 a;
  vec4 b;
  vec4 c;
};
STATIC_ASSERT_SIZE(GpuTriTexcoords, 48);

SHARED_END

#endif
