// test_texture_gpu.cpp: CPU/GPU parity of the shared texture lookup (shaders/shared/texture.h):
// the same texels, texture records and coordinates through the C++ build and through the GLSL
// build on the device (shaders/tools/texture_tool.comp), for every pair of wrap modes, both
// filters, linear and sRGB data, and a texture transform.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "../support/test_support.h"
#include "render/texture_table.h"
#include "../../shaders/shared/texture.h"

using namespace nusselt;
using namespace nusselt::shared;

// A 5 x 4 image of random codes; 9 wrap pairs x 2 filters x 2 colour spaces, plus the same with a
// KHR_texture_transform (scale, rotation, offset); 400 coordinates per texture in [-3, 3]^2 and
// the corners, edges and centres of the texels. Tolerance 1e-5 absolute: the lookup is a few
// multiplications and one pow (sRGB), which Vulkan lets the device round differently. An item may
// differ only where a coordinate lies within rounding (1e-4 texel) of a texel edge (NEAREST) or
// centre (LINEAR), where the texel choice flips; at most 1 % of the items.
TEST(TextureParity, CpuAndGpuLookupsAgree) {
  TextureImage im;
  im.width = 5;
  im.height = 4;
  std::mt19937 rng(18);
  for (int i = 0; i < 4 * 5 * 4; ++i) im.rgba.push_back(std::uint8_t(rng() & 255u));
  std::vector<std::uint32_t> texels = packTexels(im);
  std::vector<GpuTexture> textures;
  for (int transformed = 0; transformed < 2; ++transformed)
    for (WrapMode s : {WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::MirroredRepeat})
      for (WrapMode t : {WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::MirroredRepeat})
        for (FilterMode f : {FilterMode::Nearest, FilterMode::Linear})
          for (ColorSpace c : {ColorSpace::Linear, ColorSpace::Srgb}) {
            TextureRef r;
            r.image = 0;
            r.wrapS = s;
            r.wrapT = t;
            r.magFilter = f;
            r.colorSpace = c;
            if (transformed) {
              const float a = 0.3f, sx = 1.7f, sy = 0.6f;
              r.transform = glm::mat3x2(glm::vec2(sx * std::cos(a), -sx * std::sin(a)),
                                        glm::vec2(sy * std::sin(a), sy * std::cos(a)), glm::vec2(0.2f, -0.4f));
            }
            textures.push_back(packTexture(r, im, 0));
          }
  std::uniform_real_distribution<float> U(-3.0f, 3.0f);
  std::vector<vec4> in;
  for (std::size_t k = 0; k < textures.size(); ++k) {
    for (int i = 0; i < 400; ++i) in.push_back(vec4(U(rng), U(rng), float(k), 0.0f));
    for (int i = -5; i <= 10; ++i)  // texel edges and centres along both axes, and the corners
      for (float v : {0.0f, 0.125f, 1.0f})
        in.push_back(vec4(float(i) / 10.0f, v, float(k), 0.0f));
  }
  const std::uint32_t n = std::uint32_t(in.size());

  vk::Context& ctx = test::context();
  vk::Buffer tb = vk::createBuffer(ctx, textures.size() * sizeof(GpuTexture), 0, true, "textures");
  vk::Buffer xb = vk::createBuffer(ctx, texels.size() * 4, 0, true, "texels");
  vk::Buffer ib = vk::createBuffer(ctx, n * 16, 0, true, "inputs");
  vk::Buffer rb = vk::createBuffer(ctx, n * 16, 0, true, "results");
  std::memcpy(tb.mapped, textures.data(), textures.size() * sizeof(GpuTexture));
  std::memcpy(xb.mapped, texels.data(), texels.size() * 4);
  std::memcpy(ib.mapped, in.data(), n * 16);
  struct Push {
    std::uint64_t textures, texels, inputs, result;
    std::uint32_t count, pad;
  } push{tb.address, xb.address, ib.address, rb.address, n, 0};
  test::runKernel("texture_tool", {}, &push, sizeof push, n);
  const vec4* gpu = static_cast<const vec4*>(rb.mapped);

  int differ = 0, unexplained = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const GpuTexture& t = textures[std::size_t(in[i].z)];
    vec4 cpu = textureLookup(texels.data(), t, vec2(in[i].x, in[i].y));
    bool bad = false;
    for (int c = 0; c < 4; ++c) bad = bad || !(std::fabs(gpu[i][c] - cpu[c]) <= 1e-5f);
    if (!bad) continue;
    ++differ;
    // Near a texel edge (NEAREST) or centre (LINEAR) in either axis, after the transform.
    vec2 uv = textureTransform(t, vec2(in[i].x, in[i].y));
    const float shift = (t.info.w & TEXTURE_FLAG_LINEAR) ? 0.5f : 0.0f;
    auto near = [&](float u, float size) {
      float x = u * size - shift;
      return std::fabs(x - std::round(x)) < 1e-4f;
    };
    if (!near(uv.x, 5.0f) && !near(uv.y, 4.0f) && ++unexplained <= 5)
      ADD_FAILURE() << "item " << i << " texture " << in[i].z << " uv " << in[i].x << " " << in[i].y << ": CPU "
                    << cpu.x << " " << cpu.y << " " << cpu.z << " " << cpu.w << ", GPU " << gpu[i].x << " "
                    << gpu[i].y << " " << gpu[i].z << " " << gpu[i].w;
  }
  std::printf("[ texture parity ] %d of %u lookups differ beyond 1e-5, %d not near a texel edge or centre\n", differ,
              n, unexplained);
  EXPECT_LE(differ, int(n / 100));
  EXPECT_EQ(unexplained, 0);
  EXPECT_EQ(test::validationMessages(), 0u);
  for (vk::Buffer* b : {&tb, &xb, &ib, &rb}) vk::destroyBuffer(ctx, *b);
}
