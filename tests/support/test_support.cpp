#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <gtest/gtest.h>

#include "../../shaders/shared/brdf/dispatch.h"
#include "../../shaders/shared/warp.h"
#include "cli/cli_common.h"
#include "scene/gltf_loader.h"
#include "util/error.h"

namespace nusselt::test {

namespace {
vk::Context* g_context = nullptr;  // set once the shared context exists

struct ContextHolder {
  vk::Context ctx;
  ContextHolder() {
    vk::ContextOptions o;
    const char* v = std::getenv("NUSSELT_VALIDATION");
    o.validation = v && *v && std::string(v) != "0";
    vk::createContext(ctx, o);
    g_context = &ctx;
  }
  ~ContextHolder() {
    g_context = nullptr;
    vk::destroyContext(ctx);
  }
};

// Any validation-layer message during a test fails that test, whether or not the test checks
// validationMessages() itself (ctest runs the GPU and render tests with NUSSELT_VALIDATION=1).
class ValidationListener : public ::testing::EmptyTestEventListener {
  std::uint64_t m_before = 0;
  static std::uint64_t count() { return g_context ? g_context->validationMessages.load() : 0; }
  void OnTestStart(const ::testing::TestInfo&) override { m_before = count(); }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    std::uint64_t n = count() - m_before;
    if (n) ADD_FAILURE() << info.test_suite_name() << "." << info.name() << ": " << n << " Vulkan validation message(s)";
  }
};
const bool g_listener = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new ValidationListener);
  return true;
}();
}  // namespace

vk::Context& context() {
  static ContextHolder holder;
  return holder.ctx;
}

std::uint64_t validationMessages() { return context().validationMessages.load(); }

std::string sourcePath(const std::string& relative) { return std::string(NUSSELT_SOURCE_DIR) + "/" + relative; }

Scene loadTestScene(const std::string& relative) { return loadScene(sourcePath(relative)); }

void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material) {
  glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (glm::vec3 p : {a, b, c, a, c, d}) {
    s.positions.push_back(p);
    s.normals.push_back(n);
  }
  s.triangleMaterial.push_back(material);
  s.triangleMaterial.push_back(material);
}

Rendered render(const Scene& scene, const RenderSettings& settings) {
  // NUSSELT_TEST_TRAVERSAL=rayquery|bvh runs the renders that leave the traversal at auto with
  // that one (the render suite under both traversals: README, Tests).
  RenderSettings s = settings;
  const char* forced = std::getenv("NUSSELT_TEST_TRAVERSAL");
  if (forced && *forced && s.traversal == Traversal::Auto && !parseTraversal(forced, s.traversal))
    throw Error(std::string("NUSSELT_TEST_TRAVERSAL=") + forced + ": not auto, rayquery or bvh");
  Renderer r(context(), scene, s);
  r.render(s.spp);
  return {r.image(true), r.stats(), r.summary()};
}

void blockMeans(const Image& img, std::vector<double>& mean, std::vector<double>* var) {
  constexpr int kBlock = 4;  // blocks of 4 x 4 pixels: 16 blocks of a 16 x 16 image
  const int bw = img.width / kBlock, bh = img.height / kBlock, blocks = bw * bh;
  mean.assign(blocks + 1, 0.0);
  if (var) var->assign(blocks + 1, 0.0);
  const double w[3] = {0.2126, 0.7152, 0.0722};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::size_t p = std::size_t(y) * img.width + x;
      const int b = (y / kBlock) * bw + x / kBlock;
      for (int c = 0; c < 3; ++c) {
        mean[b] += w[c] * img.rgb[3 * p + c] / (kBlock * kBlock);
        mean[blocks] += w[c] * img.rgb[3 * p + c] / (img.width * img.height);
      }
      // Channels of one pixel are correlated: the luminance's variance is bounded by (sum w sd)^2.
      if (var) {
        double sd = 0;
        for (int c = 0; c < 3; ++c) sd += w[c] * std::sqrt(std::max(0.0f, img.variance[3 * p + c]));
        (*var)[b] += sd * sd / double(kBlock * kBlock * kBlock * kBlock);
        (*var)[blocks] += sd * sd / (double(img.width) * img.height * img.width * img.height);
      }
    }
}

// Simpson's rule on t = tan theta.
double studentTail(double t, double nu) {
  const double c = std::exp(std::lgamma(0.5 * (nu + 1)) - std::lgamma(0.5 * nu)) / std::sqrt(nu * M_PI);
  const double a = std::atan(t), b = 0.5 * M_PI;
  const int n = 20000;
  auto f = [&](double th) {
    if (th >= b) return 0.0;
    const double x = std::tan(th), s = 1.0 / std::cos(th);
    return c * std::pow(1 + x * x / nu, -0.5 * (nu + 1)) * s * s;
  };
  double sum = f(a) + f(b);
  for (int i = 1; i < n; ++i) sum += f(a + (b - a) * i / n) * (i % 2 ? 4 : 2);
  return sum * (b - a) / (3 * n);
}

Scene defaultScene() { return loadSceneOrDefault("", ""); }

RenderSettings integratorSettings(std::uint32_t seed) {
  RenderSettings s;
  s.width = 16;
  s.height = 16;
  s.maxDepth = 5;
  s.seed = seed;
  return s;
}

double expectReplicasMatchReference(const Image& reference, const std::vector<Image>& replicas, const std::string& what,
                                    const std::string& detail) {
  std::vector<double> refMean, refVar;
  blockMeans(reference, refMean, &refVar);
  const std::size_t tests = refMean.size();
  std::vector<double> sum(tests, 0.0), sumSq(tests, 0.0);
  for (const Image& img : replicas) {
    std::vector<double> m;
    blockMeans(img, m, nullptr);
    for (std::size_t b = 0; b < tests; ++b) sum[b] += m[b], sumSq[b] += m[b] * m[b];
  }
  const double alpha = 0.001 / double(tests), n = double(replicas.size());
  double imageT = 0;
  for (std::size_t b = 0; b < tests; ++b) {
    const double mean = sum[b] / n, s2 = std::max(0.0, (sumSq[b] - n * mean * mean) / (n - 1));
    const double t = (mean - refMean[b]) / std::sqrt(s2 / n + refVar[b]);
    const double p = 2 * studentTail(std::abs(t), n - 1);
    if (b + 1 == tests) {
      imageT = t;
      std::printf("%s, %zu seeds: image luminance %.5f +- %.5f, path %.5f +- %.5f (t %.2f)%s%s\n", what.c_str(),
                  replicas.size(), mean, std::sqrt(s2 / n), refMean[b], std::sqrt(refVar[b]), t,
                  detail.empty() ? "" : "; ", detail.c_str());
    }
    EXPECT_GT(p, alpha) << (b + 1 == tests ? std::string("image") : "block " + std::to_string(b)) << ": " << what
                        << " " << mean << " +- " << std::sqrt(s2 / n) << " vs path " << refMean[b] << " +- "
                        << std::sqrt(refVar[b]) << " (t " << t << ")";
  }
  return imageT;
}

BrdfParityKernel::BrdfParityKernel(std::vector<std::pair<glm::vec3, glm::vec3>> pairs, std::uint64_t measured)
    : m_pairs(std::move(pairs)), m_measured(measured) {
  vk::Context& ctx = context();
  const std::size_t n = m_pairs.size();
  m_pairBuf = vk::createBuffer(ctx, n * 32, 0, true, "pairs");
  m_paramBuf = vk::createBuffer(ctx, sizeof(shared::BrdfParams), 0, true, "params");
  m_resultBuf = vk::createBuffer(ctx, n * 16, 0, true, "results");
  for (std::size_t i = 0; i < n; ++i) {
    float* p = static_cast<float*>(m_pairBuf.mapped) + 8 * i;
    for (int c = 0; c < 3; ++c) {
      p[c] = m_pairs[i].first[c];
      p[4 + c] = m_pairs[i].second[c];
    }
  }
}

BrdfParityKernel::~BrdfParityKernel() {
  vk::Context& ctx = context();
  for (vk::Buffer* b : {&m_pairBuf, &m_paramBuf, &m_resultBuf}) vk::destroyBuffer(ctx, *b);
}

BrdfParityKernel::Result BrdfParityKernel::run(std::uint32_t model, const shared::BrdfParams& gpuParams,
                                                const shared::BrdfParams& params) {
  const int n = int(m_pairs.size());
  struct Push {
    std::uint64_t pairs, params, result;
    std::uint32_t count, pad;
    std::uint64_t measured;  // merl's tables
  } push{m_pairBuf.address, m_paramBuf.address, m_resultBuf.address, std::uint32_t(n), 0, m_measured};
  std::memcpy(m_paramBuf.mapped, &gpuParams, sizeof gpuParams);
  runKernel("eval_brdf", {model}, &push, sizeof push, std::uint32_t(n));
  const float* gpu = static_cast<const float*>(m_resultBuf.mapped);
  const float ulp = std::ldexp(1.0f, -23);
  auto perturb = [&](glm::vec3 w) {
    for (int c = 0; c < 3; ++c) w[c] *= 1.0f + m_step(m_prng) * ulp;
    return w;
  };
  Result r;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 cpu = shared::brdfEval(model, params, m_pairs[std::size_t(i)].first, m_pairs[std::size_t(i)].second);
    glm::vec3 sensitivity(0.0f);
    for (int k = 0; k < 6; ++k) {
      glm::vec3 moved = shared::brdfEval(model, params, perturb(m_pairs[std::size_t(i)].first), perturb(m_pairs[std::size_t(i)].second));
      for (int c = 0; c < 3; ++c) sensitivity[c] = std::max(sensitivity[c], std::fabs(moved[c] - cpu[c]));
    }
    bool bad = false;
    for (int c = 0; c < 3; ++c) {
      const double a = gpu[4 * i + c], b = cpu[c];
      if (!std::isfinite(a)) {
        ++r.nonFinite;
        bad = true;
        continue;
      }
      const double bound = 4.0 * sensitivity[c] + 16.0 * ulp * std::fabs(b) + 1e-30;
      const double diff = std::fabs(a - b), scale = std::max(std::fabs(a), std::fabs(b));
      if (scale > 1e-30) r.worstRel = std::max(r.worstRel, diff / scale);
      if (diff / bound > r.worstRatio) {
        r.worstRatio = diff / bound;
        r.worstIndex = i;
      }
      bad = bad || diff > bound;
    }
    r.outside += bad;
  }
  return r;
}

void runKernel(const std::string& name, const std::vector<std::uint32_t>& specialization, const void* push,
               std::uint32_t pushBytes, std::uint32_t invocations) {
  vk::Context& ctx = context();
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  VkPipelineLayout layout;
  VK_CHECK(vkCreatePipelineLayout(ctx.device, &pl, nullptr, &layout));
  vk::ComputePipeline p = vk::createComputePipeline(ctx, layout, name, specialization);
  VkCommandBuffer cmd = vk::beginOneShot(ctx);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
  vkCmdDispatch(cmd, (invocations + WORKGROUP_SIZE - 1) / WORKGROUP_SIZE, 1, 1);
  vk::endOneShot(ctx, cmd);
  vk::destroyComputePipeline(ctx, p);
  vkDestroyPipelineLayout(ctx.device, layout, nullptr);
}

double normalPValue(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

glm::dvec3 albedoAtNormalIncidence(std::uint32_t model, const shared::BrdfParams& p, int n) {
  glm::dvec3 a(0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      glm::vec3 wi = shared::squareToCosineHemisphere(glm::vec2((i + 0.5f) / n, (j + 0.5f) / n));
      glm::vec3 f = shared::brdfEval(model, p, wi, glm::vec3(0, 0, 1));
      for (int k = 0; k < 3; ++k) a[k] += f[k] * M_PI;  // f cos / pdf, pdf = cos / pi
    }
  return a / (double(n) * n);
}

double normalQuantileUpper(double p) {
  // Bisection on the upper tail: plenty accurate for test thresholds.
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > p) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

int binomialUpperLimit(int n, double p, double alpha) {
  // P(X > k) = 1 - sum_{i<=k} pmf(i); pmf by the recurrence in log space.
  double logPmf = n * std::log1p(-p);
  double cdf = std::exp(logPmf);
  int k = 0;
  while (1.0 - cdf > alpha && k < n) {
    logPmf += std::log(double(n - k) / double(k + 1)) + std::log(p) - std::log1p(-p);
    ++k;
    cdf += std::exp(logPmf);
  }
  return k;
}

std::string compareImagesStatistically(const Image& a, const Image& b, double cellAlpha, double alpha, int block,
                                       double referenceVarianceScale) {
  if (a.width != b.width || a.height != b.height) return "image sizes differ";
  if (a.variance.empty() || b.variance.empty()) return "both images need variance channels";
  const int bw = (a.width + block - 1) / block, bh = (a.height + block - 1) / block;
  const double w[3] = {0.2126, 0.7152, 0.0722};
  int failures = 0, cells = 0;
  double totalDiff = 0, totalVar = 0;
  double worstZ = 0, worstA = 0, worstB = 0, worstVa = 0, worstVb = 0;
  int worstX = -1, worstY = -1;
  for (int by = 0; by < bh; ++by)
    for (int bx = 0; bx < bw; ++bx) {
      // Luminance of each block mean; its variance from the channel variances, the channels of a
      // pixel treated as perfectly correlated (an upper bound: conservative), pixels independent.
      double ma = 0, mb = 0, va = 0, vb = 0;
      int k = 0;
      for (int y = by * block; y < std::min(a.height, (by + 1) * block); ++y)
        for (int x = bx * block; x < std::min(a.width, (bx + 1) * block); ++x) {
          int i = y * a.width + x;
          double sa = 0, sb = 0;
          for (int c = 0; c < 3; ++c) {
            ma += w[c] * a.rgb[3 * i + c];
            mb += w[c] * b.rgb[3 * i + c];
            double vaPixel = referenceVarianceScale > 0 ? referenceVarianceScale * b.variance[3 * i + c] : a.variance[3 * i + c];
            sa += w[c] * std::sqrt(std::max(0.0, vaPixel));
            sb += w[c] * std::sqrt(std::max(0.0f, b.variance[3 * i + c]));
          }
          va += sa * sa;
          vb += sb * sb;
          ++k;
        }
      ++cells;
      totalDiff += ma - mb;
      totalVar += va + vb;
      double var = (va + vb) / (double(k) * k);
      double diff = (ma - mb) / k;
      double z = var > 0 ? diff / std::sqrt(var) : (diff == 0 ? 0.0 : INFINITY);
      if (normalPValue(z) < cellAlpha) ++failures;
      if (std::fabs(z) > worstZ) {
        worstZ = std::fabs(z);
        worstX = bx * block;
        worstY = by * block;
        worstA = ma / k;
        worstB = mb / k;
        worstVa = va / (double(k) * k);
        worstVb = vb / (double(k) * k);
      }
    }
  int limit = binomialUpperLimit(cells, cellAlpha, alpha);
  std::ostringstream os;
  // The whole-image mean, tested too: it has by far the smallest variance, so it catches a small
  // bias spread over the image (a missing bounce) that no single cell can resolve.
  const double zImage = totalDiff / std::sqrt(totalVar);
  if (normalPValue(zImage) < alpha) {
    os << "the image means differ: z = " << zImage << " (p < " << alpha << "); mean luminance difference "
       << totalDiff / (double(a.width) * a.height);
    return os.str();
  }
  if (failures <= limit) return "";
  os << failures << " of " << cells << " cells of " << block << "x" << block << " pixels fail the z-test at p < "
     << cellAlpha << " (at most " << limit << " expected at significance " << alpha << "); worst |z| = " << worstZ
     << " at pixel (" << worstX << ", " << worstY << "): luminance " << worstA << " (variance " << worstVa << ") vs "
     << worstB << " (variance " << worstVb << ")";
  return os.str();
}

RoughSplit roughDielectricSplit(float alpha, float eta, glm::vec3 wo, int N, const std::function<bool(glm::vec3)>& accept) {
  RoughSplit r;
  const double no = wo.z > 0 ? 1.0 : eta;
  for (int side = 0; side < 2; ++side) {
    double acc = 0;
    for (int a = 0; a < N; ++a) {
      const double th = (a + 0.5) / N * 0.5 * M_PI, mu = std::cos(th), st = std::sin(th);
      for (int b = 0; b < 2 * N; ++b) {
        const double ph = (b + 0.5) / (2 * N) * 2 * M_PI;
        const glm::vec3 wi(float(st * std::cos(ph)), float(st * std::sin(ph)), float(side == 0 ? mu : -mu));
        if (accept && !accept(wi)) continue;
        acc += shared::roughDielectricF(alpha, eta, wi, wo) * mu * st;  // f |cos| dw = f cos sin dtheta dphi
      }
    }
    acc *= (0.5 * M_PI / N) * (M_PI / N);
    const double ni = side == 0 ? 1.0 : eta;
    if ((side == 0) == (wo.z > 0)) {
      r.R = acc;
    } else {
      r.Trad = acc;
      r.Tenergy = acc * (ni / no) * (ni / no);
    }
  }
  return r;
}

}  // namespace nusselt::test
