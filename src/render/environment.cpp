// environment.cpp: texels and sampling distribution of the environment light. See environment.h.
#include "render/environment.h"

#include <algorithm>
#include <cmath>

namespace nusselt {

Environment effectiveEnvironment(const Scene& scene) {
  if (scene.environment.present()) return scene.environment;
  Environment e;
  const glm::vec3 b = scene.background;
  if (b.x > 0.0f || b.y > 0.0f || b.z > 0.0f) {
    e.kind = EnvironmentKind::Uniform;
    e.color = b;
  }
  return e;
}

std::uint64_t environmentBytes(const Environment& env) {
  if (!env.present()) return 0;
  const std::uint64_t w = env.kind == EnvironmentKind::Map ? env.width : kUniformEnvironmentWidth;
  const std::uint64_t h = env.kind == EnvironmentKind::Map ? env.height : kUniformEnvironmentHeight;
  return w * h * 16 + (h * (w + 1) + h + 1) * 4 + sizeof(shared::GpuEnvironment);
}

EnvironmentData buildEnvironment(const Environment& env) {
  EnvironmentData d;
  if (!env.present()) return d;
  const bool map = env.kind == EnvironmentKind::Map;
  const int w = map ? env.width : kUniformEnvironmentWidth;
  const int h = map ? env.height : kUniformEnvironmentHeight;
  const double a = double(env.rotateDegrees) * M_PI / 180.0;
  d.gpu.info = glm::uvec4(std::uint32_t(w), std::uint32_t(h), 0u, 0u);
  d.gpu.rotation = glm::vec4(float(std::cos(a)), float(std::sin(a)), 0.0f, 0.0f);

  // ---- Texels: radiance x scale ----
  d.texels.resize(std::size_t(w) * h);
  for (std::size_t i = 0; i < d.texels.size(); ++i) {
    glm::vec3 c = map ? glm::vec3(env.rgb[3 * i], env.rgb[3 * i + 1], env.rgb[3 * i + 2]) : env.color;
    d.texels[i] = glm::vec4(c * env.scale, 0.0f);
  }

  // ---- Weights: the bilinear lookup's luminance integrated over each texel (the separable
  // kernel 1/8, 3/4, 1/8; u wraps, v clamps like the lookup) times sin(theta) at its centre ----
  std::vector<double> lum(d.texels.size());
  for (std::size_t i = 0; i < lum.size(); ++i) lum[i] = shared::luminance(glm::vec3(d.texels[i]));
  std::vector<double> rowBlur(lum.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double* row = &lum[std::size_t(y) * w];
      rowBlur[std::size_t(y) * w + x] = 0.125 * row[(x + w - 1) % w] + 0.75 * row[x] + 0.125 * row[(x + 1) % w];
    }
  std::vector<double> weight(lum.size());
  for (int y = 0; y < h; ++y) {
    const double sinTheta = std::sin(M_PI * (y + 0.5) / h);
    const int ym = std::max(y - 1, 0), yp = std::min(y + 1, h - 1);
    for (int x = 0; x < w; ++x)
      weight[std::size_t(y) * w + x] =
          sinTheta * (0.125 * rowBlur[std::size_t(ym) * w + x] + 0.75 * rowBlur[std::size_t(y) * w + x] +
                      0.125 * rowBlur[std::size_t(yp) * w + x]);
  }

  // ---- CDFs (double sums, rounded once; the last entry exactly 1) ----
  d.distribution.assign(shared::dist2dSize(std::uint32_t(w), std::uint32_t(h)), 0.0f);
  std::vector<double> rowSum(h, 0.0);
  for (int y = 0; y < h; ++y) {
    float* cdf = &d.distribution[std::size_t(y) * (w + 1)];
    double total = 0;
    for (int x = 0; x < w; ++x) total += weight[std::size_t(y) * w + x];
    rowSum[y] = total;
    double acc = 0;
    cdf[0] = 0.0f;
    for (int x = 0; x < w; ++x) {
      acc += total > 0 ? weight[std::size_t(y) * w + x] : 1.0;  // a row without mass: uniform
      cdf[x + 1] = float(acc / (total > 0 ? total : double(w)));
    }
    cdf[w] = 1.0f;
  }
  float* marginal = &d.distribution[std::size_t(h) * (w + 1)];
  double total = 0;
  for (int y = 0; y < h; ++y) total += rowSum[y];
  d.weightTotal = total;
  double acc = 0;
  marginal[0] = 0.0f;
  for (int y = 0; y < h; ++y) {
    acc += total > 0 ? rowSum[y] : 1.0;
    marginal[y + 1] = float(acc / (total > 0 ? total : double(h)));
  }
  marginal[h] = 1.0f;

  // ---- Integral of luminance over the sphere (texel values times their solid angles), for the
  // power estimate of light selection ----
  double integral = 0;
  for (int y = 0; y < h; ++y) {
    const double solid = (2.0 * M_PI / w) * (std::cos(M_PI * y / h) - std::cos(M_PI * (y + 1) / h));
    for (int x = 0; x < w; ++x) integral += lum[std::size_t(y) * w + x] * solid;
  }
  d.luminanceIntegral = integral;
  return d;
}

}  // namespace nusselt
