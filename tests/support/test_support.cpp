#include "test_support.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "scene/gltf_loader.h"

namespace nusselt::test {

namespace {
struct ContextHolder {
  vk::Context ctx;
  ContextHolder() {
    vk::ContextOptions o;
    const char* v = std::getenv("NUSSELT_VALIDATION");
    o.validation = v && *v && std::string(v) != "0";
    vk::createContext(ctx, o);
  }
  ~ContextHolder() { vk::destroyContext(ctx); }
};
}  // namespace

vk::Context& context() {
  static ContextHolder holder;
  return holder.ctx;
}

std::uint64_t validationMessages() { return context().validationMessages.load(); }

std::string sourcePath(const std::string& relative) { return std::string(NUSSELT_SOURCE_DIR) + "/" + relative; }

Scene loadTestScene(const std::string& relative) { return loadScene(sourcePath(relative)); }

Rendered render(const Scene& scene, const RenderSettings& settings) {
  Renderer r(context(), scene, settings);
  for (std::uint32_t i = 0; i < settings.spp; ++i) r.renderPass();
  return {r.image(true), r.stats()};
}

double normalPValue(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

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

std::string compareImagesStatistically(const Image& a, const Image& b, double pixelAlpha, double alpha) {
  if (a.width != b.width || a.height != b.height) return "image sizes differ";
  const int n = a.width * a.height;
  int failures = 0;
  double worstZ = 0;
  int worstPixel = -1;
  for (int i = 0; i < n; ++i) {
    // Luminance of each estimate; its variance from the channel variances (channels treated as
    // perfectly correlated: an upper bound, conservative for the test).
    const double w[3] = {0.2126, 0.7152, 0.0722};
    double ma = 0, mb = 0, sa = 0, sb = 0;
    for (int c = 0; c < 3; ++c) {
      ma += w[c] * a.rgb[3 * i + c];
      mb += w[c] * b.rgb[3 * i + c];
      sa += w[c] * std::sqrt(std::max(0.0f, a.variance.empty() ? 0.0f : a.variance[3 * i + c]));
      sb += w[c] * std::sqrt(std::max(0.0f, b.variance.empty() ? 0.0f : b.variance[3 * i + c]));
    }
    double var = sa * sa + sb * sb;
    double z = var > 0 ? (ma - mb) / std::sqrt(var) : (ma == mb ? 0.0 : INFINITY);
    if (normalPValue(z) < pixelAlpha) ++failures;
    if (std::fabs(z) > worstZ) {
      worstZ = std::fabs(z);
      worstPixel = i;
    }
  }
  int limit = binomialUpperLimit(n, pixelAlpha, alpha);
  if (failures <= limit) return "";
  std::ostringstream os;
  os << failures << " of " << n << " pixels fail the per-pixel z-test at p < " << pixelAlpha << " (at most " << limit
     << " expected at significance " << alpha << "); worst |z| = " << worstZ << " at pixel (" << worstPixel % a.width
     << ", " << worstPixel / a.width << ")";
  return os.str();
}

}  // namespace nusselt::test
