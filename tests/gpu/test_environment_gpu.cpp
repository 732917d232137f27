// test_environment_gpu.cpp: CPU/GPU parity of the environment's shared functions (envmap.h,
// distribution2d.h): the same map, uniform pairs and directions through the C++ build and through
// the GLSL build on the device (shaders/tools/env_tool.comp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "../support/test_support.h"
#include "render/environment.h"

using namespace nusselt;
using namespace nusselt::shared;

// A 64 x 32 map with a sun (two texels at 10^4 x the sky), rotated by 33 degrees; 20,000 uniform
// pairs and directions. Tolerances: the GPU's sin, cos and sqrt may differ from glibc's by a few
// ulps (Vulkan allows more), and the atan/acos are the shared portable ones. Sampled directions
// must agree within 1e-5 rad and radiances within 1e-4 relative, except where the sample or the
// direction lies within rounding of a cell edge (the density and the bilinear weights jump or
// turn there): at most 0.1 % of the items may differ, each accounted for by being within 1e-4 of
// an edge in u or v.
TEST(EnvironmentParity, CpuAndGpuSampleAndEvaluateTheSameMap) {
  Environment env;
  env.kind = EnvironmentKind::Map;
  env.width = 64;
  env.height = 32;
  env.rgb.resize(3 * 64 * 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c)
        env.rgb[3 * (y * 64 + x) + c] = 0.2f + 0.1f * c + 0.5f * float(y) / 32 + 0.2f * std::sin(0.3f * x);
  for (int x : {40, 41})
    for (int c = 0; c < 3; ++c) env.rgb[3 * (9 * 64 + x) + c] = 5000.0f;
  env.rotateDegrees = 33.0f;
  EnvironmentData data = buildEnvironment(env);
  EnvHostView host = data.view();

  vk::Context& ctx = test::context();
  const int n = 20000;
  vk::Buffer texels = vk::createBuffer(ctx, data.texels.size() * 16, 0, true, "env texels");
  vk::Buffer dist = vk::createBuffer(ctx, data.distribution.size() * 4, 0, true, "env distribution");
  vk::Buffer envBuf = vk::createBuffer(ctx, sizeof(GpuEnvironment), 0, true, "env");
  vk::Buffer inputs = vk::createBuffer(ctx, n * 32, 0, true, "inputs");
  vk::Buffer result = vk::createBuffer(ctx, n * 48, 0, true, "results");
  std::memcpy(texels.mapped, data.texels.data(), data.texels.size() * 16);
  std::memcpy(dist.mapped, data.distribution.data(), data.distribution.size() * 4);
  GpuEnvironment e = data.gpu;
  e.texels = texels.address;
  e.distribution = dist.address;
  std::memcpy(envBuf.mapped, &e, sizeof e);
  std::mt19937 rng(2026);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  std::vector<vec4> in(2 * n);
  for (int i = 0; i < n; ++i) {
    in[2 * i] = vec4(std::min(U(rng), NUSSELT_ONE_MINUS_EPS), std::min(U(rng), NUSSELT_ONE_MINUS_EPS), 0, 0);
    float s;
    vec3 d = envUvToDirection(vec2(U(rng), U(rng)), s);
    in[2 * i + 1] = vec4(d, 0);
  }
  std::memcpy(inputs.mapped, in.data(), in.size() * 16);
  struct Push {
    std::uint64_t env, inputs, result;
    std::uint32_t count, pad;
  } push{envBuf.address, inputs.address, result.address, std::uint32_t(n), 0};
  test::runKernel("env_tool", {}, &push, sizeof push, n);
  const vec4* gpu = static_cast<const vec4*>(result.mapped);

  auto nearEdge = [&](vec3 worldDir) {
    vec2 uv = envDirectionToUv(envWorldToMap(host.e.rotation, worldDir));
    float fu = uv.x * 64, fv = uv.y * 32;
    // Edges of the density's cells (integers) and of the bilinear weights (half-integers).
    auto dist = [](float f) { return std::min(std::fabs(f - std::round(f)), std::fabs(f - 0.5f - std::round(f - 0.5f))); };
    return dist(fu) < 1e-4f * 64 || dist(fv) < 1e-4f * 32;
  };
  int differ = 0, unexplained = 0;
  for (int i = 0; i < n; ++i) {
    float pdf;
    vec3 s = envSample(host, vec2(in[2 * i]), pdf);
    vec3 d = vec3(in[2 * i + 1]);
    float p = envPdf(host, d);
    vec3 L = envRadiance(host, d);
    vec3 gs = vec3(gpu[3 * i]);
    bool bad = glm::length(gs - s) > 1e-5f || std::fabs(gpu[3 * i].w - pdf) > 1e-4f * pdf ||
               std::fabs(gpu[3 * i + 1].x - p) > 1e-4f * p;
    for (int c = 0; c < 3; ++c) bad = bad || std::fabs(gpu[3 * i + 2][c] - L[c]) > 1e-4f * L[c] + 1e-7f;
    if (bad) {
      ++differ;
      if (!nearEdge(s) && !nearEdge(d)) {
        ++unexplained;
        if (unexplained < 5)
          ADD_FAILURE() << "item " << i << ": sample " << s.x << " " << s.y << " " << s.z << " pdf " << pdf << " vs GPU "
                        << gs.x << " " << gs.y << " " << gs.z << " " << gpu[3 * i].w << "; envPdf " << p << " vs "
                        << gpu[3 * i + 1].x << "; L " << L.x << " vs " << gpu[3 * i + 2].x;
      }
    }
  }
  std::printf("[ env parity ] %d of %d items differ beyond the tolerance, %d not near a cell edge\n", differ, n,
              unexplained);
  EXPECT_LE(differ, n / 1000);
  EXPECT_EQ(unexplained, 0);
  for (vk::Buffer* b : {&texels, &dist, &envBuf, &inputs, &result}) vk::destroyBuffer(ctx, *b);
}
