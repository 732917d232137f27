// vegas_integrator.h: VEGAS on the primary sample space (Lepage 1978; issue 19, docs/vegas.md), a
// sibling of the path tracer that drives it. Per chunk of a pass, one submission:
//   warp (shaders/stages/vegas.comp): each path slot's primary draws are the path tracer's own
//     uniform numbers (hash or QMC of pixel, sample index, dimension, seed), warped through the
//     separable piecewise-constant density on the warped axes (shaders/shared/vegas.h);
//   the path tracer traces the slots (PathIntegrator::recordTrace, PRIMARY_SAMPLES);
//   weigh: radiance x 1 / p(x) (p = the product of the axes' densities), and F^2 (F = luminance of
//     the weighted radiance) into per-axis, per-bin 64-bit fixed-point sums;
//   the path tracer's accumulate stage adds the weighted radiance to the film (sum and sum of
//     squares: --variance works).
// After each pass the host learns (vegasRefine): per axis, G_b += p_b S_b / n (an unbiased
// estimate of the integral over bin b of the marginal of f^2 / p_rest, whatever density the pass
// used), and the next pass samples p'_b proportional to sqrt(G_b) (the separable density that
// minimises the variance of the axis given the others), mixed with the uniform density
// (--vegas-alpha), so every bin keeps mass and 1 / p_a <= 1 / alpha. Every pass is unbiased and
// the film weighs every sample alike (the training passes are kept).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "render/primary_sample_integrator.h"

namespace nusselt {

// One axis' learning step. G: the axis' accumulated estimates (bins entries, updated); cdf: its
// CDF (bins + 1 floats: read as the pass's density, rewritten with the new one); S: the pass's sums
// of F^2 per bin; n: the pass's paths. The new density is (1 - alpha) sqrt(G_b) / mean_b sqrt(G_b)
// + alpha (uniform while G is 0).
void vegasRefine(std::vector<double>& G, float* cdf, std::uint32_t bins, const double* S, double n, double alpha);
// The uniform CDF of `bins` bins (cdf[i] = i / bins).
void vegasUniformCdf(float* cdf, std::uint32_t bins);

struct VegasReport {
  std::uint32_t axes = 0, bins = 0, bounces = 0, dims = 0;
  std::uint32_t refinements = 0;  // passes the tables were learned from
  std::uint64_t learnedPaths = 0; // paths those passes traced
  double learnSeconds = 0;        // host time reading the sums and rebuilding the tables
  // Per axis: the largest density of the current table (1: uniform; at most (1 - alpha) bins + alpha).
  std::vector<float> maxDensity;
};

class VegasIntegrator : public PrimarySampleIntegrator {
 public:
  // paths: the path tracer, created with PathOptions{vegasPrimaryDims(settings.vegasBounces)}.
  VegasIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                  std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels);
  ~VegasIntegrator() override;

  // Device bytes of the warp's state beyond the path tracer's.
  static std::uint64_t bytesFor(const RenderSettings& settings);

  void renderPass(std::uint32_t sampleIndex, std::uint32_t samples) override;
  const VegasReport& report() const { return m_report; }
  // The current CDF of axis a (bins + 1 floats; tests).
  std::vector<float> cdf(std::uint32_t axis) const;

 private:
  void learn(std::uint64_t paths);

  std::uint32_t m_axes = 0, m_bins = 0;
  VegasReport m_report;
  std::vector<std::vector<double>> m_G;  // per axis, per bin
  vk::Buffer* m_vegas = nullptr;  // the GpuVegas (host visible)
  vk::Buffer* m_cdf = nullptr;    // host visible
  vk::Buffer* m_sums = nullptr;   // host visible
};

}  // namespace nusselt
