// test_support.h: shared helpers of the GPU and render tests: one Vulkan context per test
// binary (validation layer on when NUSSELT_VALIDATION=1, as ctest sets it), rendering a scene to
// an image with its per-pixel variance, and statistical comparisons.
#pragma once
#include <string>

#include "io/image.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "vk/vk.h"

namespace nusselt::test {

vk::Context& context();
// Validation messages so far (must be 0 after every test).
std::uint64_t validationMessages();

std::string sourcePath(const std::string& relative);
Scene loadTestScene(const std::string& relative);

struct Rendered {
  Image image;  // with variance of the mean per channel
  RenderStats stats;
};
Rendered render(const Scene& scene, const RenderSettings& settings);

// Two-sided p-value of a standard normal z.
double normalPValue(double z);
// Inverse of the upper tail of the standard normal: z with P(Z > z) = p.
double normalQuantileUpper(double p);
// Smallest k such that P(Binomial(n, p) > k) <= alpha.
int binomialUpperLimit(int n, double p, double alpha);

// Per-pixel Welch z-test of two independent estimates (means and variances of the mean).
// A pixel fails when its two-sided p-value is below pixelAlpha; the test passes when the number
// of failing pixels is within binomialUpperLimit(pixels, pixelAlpha, alpha). Returns a message
// describing the outcome (empty on success).
std::string compareImagesStatistically(const Image& a, const Image& b, double pixelAlpha, double alpha);

}  // namespace nusselt::test
