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

// Appends quad a b c d (counter-clockwise seen from the side its normal points to) as two
// triangles; geometric and shading normal = normalize(cross(b - a, c - a)).
void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material);

struct Rendered {
  Image image;  // with variance of the mean per channel
  RenderStats stats;
  SceneSummary summary;  // pipeline and quadtree build times, cache hits
};
// Renders settings.spp passes. A traversal left at auto is replaced by NUSSELT_TEST_TRAVERSAL
// (rayquery or bvh) when that is set.
Rendered render(const Scene& scene, const RenderSettings& settings);

// Runs an embedded standalone compute kernel (one that declares its own push-constant block of at
// most 128 bytes, typically buffer device addresses, and no descriptor sets) over `invocations`
// threads, with the given specialization constants, and waits for it.
void runKernel(const std::string& name, const std::vector<std::uint32_t>& specialization, const void* push,
               std::uint32_t pushBytes, std::uint32_t invocations);

// Two-sided p-value of a standard normal z.
double normalPValue(double z);
// Inverse of the upper tail of the standard normal: z with P(Z > z) = p.
double normalQuantileUpper(double p);
// Smallest k such that P(Binomial(n, p) > k) <= alpha.
int binomialUpperLimit(int n, double p, double alpha);

// Welch z-test of two independent estimates (means and variances of the mean), per block of
// block x block pixels (block = 1: per pixel). Averaging a block sums many samples, which makes
// the z statistic close to normal even for heavy-tailed estimators (BSDF sampling of a small
// light), where a per-pixel test with a 100-sample variance estimate is not.
// A block fails when its two-sided p-value is below cellAlpha; the test passes when the number
// of failing blocks is within binomialUpperLimit(blocks, cellAlpha, alpha). Returns a message
// describing the outcome (empty on success).
//
// referenceVarianceScale > 0: b is a reference of the same estimator with many more samples, and
// a's variance is taken as b's times this scale (= reference spp / a's spp) instead of a's own
// estimate. Under the null hypothesis both have the same per-sample variance, and the
// reference's estimate is the precise one: a low-spp estimate misses rare bright samples (a
// pixel that partly covers a light) exactly when its mean is low, which inflates |z|.
std::string compareImagesStatistically(const Image& a, const Image& b, double cellAlpha, double alpha, int block = 1,
                                       double referenceVarianceScale = 0);

}  // namespace nusselt::test
