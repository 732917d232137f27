// test_support.h: shared helpers of the GPU and render tests: one Vulkan context per test
// binary (validation layer on when NUSSELT_VALIDATION=1, as ctest sets it), rendering a scene to
// an image with its per-pixel variance, and statistical comparisons.
#pragma once
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "brdf/registry.h"
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

// Mean luminance of every 4 x 4 block of img (width and height multiples of 4) and, when var is
// given, its variance of the mean from the per-pixel variances (the path tracer's independent
// pixels); the whole image's last. (Integrators against the path tracer: test_mlt, test_vegas.)
void blockMeans(const Image& img, std::vector<double>& mean, std::vector<double>* var);
// Upper tail P(T > t) of Student's t with nu degrees of freedom.
double studentTail(double t, double nu);
// The default scene (the Cornell box), and the 16 x 16, max depth 5 settings of the integrator
// tests (test_mlt, test_vegas) with `seed`.
Scene defaultScene();
RenderSettings integratorSettings(std::uint32_t seed);
// Independent replicas (renders with different seeds) of an estimator whose per-pixel variance the
// film cannot give (Metropolis, VEGAS: a render's samples are correlated) against a path-traced
// reference: per 4 x 4 block and for the image (blockMeans), Student t with the replicas' sample
// variance plus the reference's variance, two-sided at 0.001 / tests (Bonferroni); a failure
// names the block, `what` and `detail`. Prints the image's line; returns the image's t.
double expectReplicasMatchReference(const Image& reference, const std::vector<Image>& replicas,
                                    const std::string& what, const std::string& detail = "");

// Runs an embedded standalone compute kernel (one that declares its own push-constant block of at
// most 128 bytes, typically buffer device addresses, and no descriptor sets) over `invocations`
// threads, with the given specialization constants, and waits for it.
void runKernel(const std::string& name, const std::vector<std::uint32_t>& specialization, const void* push,
               std::uint32_t pushBytes, std::uint32_t invocations);

// The GLSL build of brdfEval (kernel eval_brdf) against the C++ build at fixed direction pairs,
// one model and parameter block per run; `measured` is the device address of the merl tables (0:
// none). The two builds round differently (fused multiply-adds, LLVM's vs glibc's exp, pow,
// sin...), by a few ulps per operation; what that does to f depends on how sensitive f is at the
// pair (pow(x, 10000) multiplies the relative error of x by 10^4; tan near 90 degrees, a
// shadowing boundary...). So the bound at each pair is measured on the CPU build itself: the
// largest change of f when the directions' components move by up to 4 ulps (6 perturbations, from
// one generator seeded 99 for the object's life), and the GPU value must lie within 4x that
// change plus 16 ulps of f:
//   |gpu - cpu| <= 4 * sensitivity + 16 ulp * |cpu| + 1e-30.
class BrdfParityKernel {
 public:
  explicit BrdfParityKernel(std::vector<std::pair<glm::vec3, glm::vec3>> pairs, std::uint64_t measured = 0);
  ~BrdfParityKernel();
  BrdfParityKernel(const BrdfParityKernel&) = delete;
  BrdfParityKernel& operator=(const BrdfParityKernel&) = delete;
  struct Result {
    int outside = 0;     // pairs with a channel outside the bound
    int nonFinite = 0;   // GPU values that are NaN or infinite
    int worstIndex = -1; // the pair of the largest |diff| / bound
    double worstRel = 0, worstRatio = 0;  // largest relative difference, largest |diff| / bound
  };
  Result run(std::uint32_t model, const shared::BrdfParams& params) { return run(model, params, params); }
  // The GPU evaluates with `gpuParams`, the C++ build with `cpuParams` (merl: the table's slot in
  // the device buffer and in the process's store differ).
  Result run(std::uint32_t model, const shared::BrdfParams& gpuParams, const shared::BrdfParams& cpuParams);
  const std::vector<std::pair<glm::vec3, glm::vec3>>& pairs() const { return m_pairs; }

 private:
  std::vector<std::pair<glm::vec3, glm::vec3>> m_pairs;
  vk::Buffer m_pairBuf, m_paramBuf, m_resultBuf;
  std::uint64_t m_measured;
  std::mt19937 m_prng{99};
  std::uniform_int_distribution<int> m_step{-4, 4};
};

// The rough dielectric's split for the known direction wo (either side of its frame; eta = n_inside /
// n_outside; shaders/shared/brdf/rough_dielectric.h) by the midpoint rule over each hemisphere in
// (theta_i, phi), N x 2N cells: R = the integral of f |cos| over
// wo's hemisphere, Trad = over the other one (f as the renderer uses it, with its (n_o / n_i)^2),
// Tenergy = Trad (n_i / n_o)^2 (the transmitted energy); loss = 1 - R - Tenergy, the Smith term's
// single-scattering loss. accept (optional): only the directions wi it accepts count (a light's extent).
struct RoughSplit {
  double R = 0, Trad = 0, Tenergy = 0;
  double loss() const { return 1.0 - R - Tenergy; }
};
RoughSplit roughDielectricSplit(float alpha, float eta, glm::vec3 wo, int N,
                                const std::function<bool(glm::vec3)>& accept = {});

// The directional albedo at normal incidence of `model` with params p, the integral of f cos over
// the hemisphere, by a stratified n x n cosine-weighted quadrature of the shared C++ BRDF.
glm::dvec3 albedoAtNormalIncidence(std::uint32_t model, const shared::BrdfParams& p, int n = 1024);

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
