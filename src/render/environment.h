// environment.h: the environment light's data, built on the CPU from a scene's Environment: the
// texels (radiance x scale) and the piecewise-constant 2-D sampling distribution of
// shaders/shared/envmap.h. The same arrays are uploaded to the device (DeviceScene) and read on the
// CPU through view() by the tests (chi-square of the sampler, GPU parity).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "../../shaders/shared/envmap.h"
#include "scene/scene.h"

namespace nusselt {

// A uniform environment is a constant map of this size: its sampling distribution then follows
// sin(theta), close to uniform over the sphere (a 1x1 map would sample the poles as often as the
// equator). 64 x 32 texels cost 32 KiB.
constexpr int kUniformEnvironmentWidth = 64;
constexpr int kUniformEnvironmentHeight = 32;

struct EnvironmentData {
  shared::GpuEnvironment gpu{};          // info and rotation; buffer addresses are the uploader's
  std::vector<glm::vec4> texels;         // width * height, radiance x scale
  std::vector<float> distribution;       // dist2dSize(width, height) floats
  double weightTotal = 0;                // sum of the texel weights (0: the map is black: no light)
  double luminanceIntegral = 0;          // integral of the texels' luminance over the sphere [W/m^2]

  bool emits() const { return weightTotal > 0; }
  // The CPU view for the shared functions (envRadiance, envPdf, envSample).
  shared::EnvHostView view() const {
    shared::EnvHostView v;
    v.e = gpu;
    v.texels = texels.data();
    v.distribution = distribution.data();
    return v;
  }
};

// Builds the texels and the distribution of `env` (Uniform or Map; None gives an empty result).
EnvironmentData buildEnvironment(const Environment& env);

// The environment a scene renders with: scene.environment, or a uniform one of scene.background
// when that is None and the background is not black; None otherwise.
Environment effectiveEnvironment(const Scene& scene);

// Device bytes the environment of `env` takes (texels, distribution, the struct).
std::uint64_t environmentBytes(const Environment& env);

}  // namespace nusselt
