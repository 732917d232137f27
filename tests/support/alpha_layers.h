// alpha_layers.h: a small scene with alpha (MASK, BLEND) for the tests of the traversal's alpha
// test, on the CPU twin (tests/unit/test_bvh.cpp) and against the GPU (tests/gpu/test_traversal.cpp).
#pragma once
#include <string>

#include "brdf/registry.h"
#include "scene/scene.h"

namespace nusselt::test {

// Three layers of 8 x 8 quads over [-1, 1]^2 (128 triangles each, so the BVH has depth): z = 0
// MASK (cutoff 0.5) with a 2 x 1 NEAREST base-colour texture whose alpha is 255 over x < 0 and 0
// over x > 0; z = -1 BLEND with baseColorFactor.a = 0.3; z = -2 opaque. Texture coordinates
// u = (x + 1) / 2, v = (1 - y) / 2.
inline Scene alphaLayers() {
  Scene s;
  TextureImage im;
  im.name = "mask";
  im.width = 2;
  im.height = 1;
  im.rgba = {255, 255, 255, 255, 255, 255, 255, 0};
  s.images.push_back(im);
  for (int layer = 0; layer < 3; ++layer) {
    Material m = catalogueMaterial("lambert", {}, "layer" + std::to_string(layer));
    if (layer == 0) {
      m.alphaMode = AlphaMode::Mask;
      m.baseColorTexture.image = 0;
      m.baseColorTexture.magFilter = m.baseColorTexture.minFilter = FilterMode::Nearest;
      m.baseColorTexture.colorSpace = ColorSpace::Srgb;
    } else if (layer == 1) {
      m.alphaMode = AlphaMode::Blend;
      m.baseColorFactor.w = 0.3f;
    }
    s.materials.push_back(m);
    const float z = -float(layer);
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const float x0 = -1 + 0.25f * i, y0 = -1 + 0.25f * j, x1 = x0 + 0.25f, y1 = y0 + 0.25f;
        const glm::vec3 a(x0, y0, z), b(x1, y0, z), c(x1, y1, z), d(x0, y1, z);
        for (glm::vec3 p : {a, b, c, a, c, d}) {
          s.positions.push_back(p);
          s.normals.push_back(glm::vec3(0, 0, 1));
          s.texcoords0.push_back(glm::vec2((p.x + 1) / 2, (1 - p.y) / 2));
        }
        s.triangleMaterial.push_back(std::uint32_t(layer));
        s.triangleMaterial.push_back(std::uint32_t(layer));
      }
  }
  return s;
}

}  // namespace nusselt::test
