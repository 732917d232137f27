// vegas_integrator.cpp: the warp's buffers, the weighted passes and the learning (vegas_integrator.h).
#include "render/vegas_integrator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "../../shaders/shared/layout.h"
#include "../../shaders/shared/vegas.h"
#include "util/error.h"

namespace nusselt {

using shared::GpuVegas;
using shared::Globals;

void vegasUniformCdf(float* cdf, std::uint32_t bins) {
  for (std::uint32_t i = 0; i <= bins; ++i) cdf[i] = static_cast<float>(double(i) / double(bins));
}

void vegasRefine(std::vector<double>& G, float* cdf, std::uint32_t bins, const double* S, double n, double alpha) {
  if (n <= 0) return;
  for (std::uint32_t b = 0; b < bins; ++b) {
    const double p = (double(cdf[b + 1]) - double(cdf[b])) * double(bins);  // the pass's density in bin b
    G[b] += p * S[b] / n;
  }
  // Classic VEGAS's smoothing: each bin's estimate averaged with its neighbours' (one bin's
  // noise, a firefly's F^2, spreads over three), then the square root.
  std::vector<double> q(bins);
  double mean = 0;
  for (std::uint32_t b = 0; b < bins; ++b) {
    const std::uint32_t lo = b > 0 ? b - 1 : b, hi = b + 1 < bins ? b + 1 : b;
    double sum = 0;
    for (std::uint32_t c = lo; c <= hi; ++c) sum += G[c];
    q[b] = std::sqrt(sum / double(hi - lo + 1));
    mean += q[b];
  }
  mean /= double(bins);
  if (!(mean > 0) || !std::isfinite(mean)) {
    vegasUniformCdf(cdf, bins);
    return;
  }
  // Cumulative masses (1 / bins of the density each) in double, rounded to float once.
  double acc = 0;
  cdf[0] = 0.0f;
  for (std::uint32_t b = 0; b < bins; ++b) {
    const double p = (1.0 - alpha) * q[b] / mean + alpha;
    acc += p / double(bins);
    cdf[b + 1] = static_cast<float>(acc);
  }
  cdf[bins] = 1.0f;
  for (std::uint32_t b = 0; b < bins; ++b)
    if (!(cdf[b + 1] > cdf[b])) throw Error("vegas: a bin of the learned density lost its mass in float (bins or alpha)");
}

std::uint64_t VegasIntegrator::bytesFor(const RenderSettings& s) {
  const std::uint64_t axes = std::uint64_t(s.vegasBounces) * VEGAS_AXES_PER_BOUNCE;
  return axes * (s.vegasBins + 1) * 4 + axes * s.vegasBins * 8 + sizeof(GpuVegas);
}

VegasIntegrator::VegasIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                                 std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels)
    : PrimarySampleIntegrator(ctx, globals, settings, std::move(paths), pixels) {
  const std::uint32_t dims = globals.host().primaryDims;
  if (dims != shared::vegasPrimaryDims(settings.vegasBounces))
    throw Error("vegas: the path tracer's primary draws do not cover the warped bounces");
  m_axes = settings.vegasBounces * VEGAS_AXES_PER_BOUNCE;
  m_bins = settings.vegasBins;
  m_report.axes = m_axes;
  m_report.bins = m_bins;
  m_report.bounces = settings.vegasBounces;
  m_report.dims = dims;
  m_report.maxDensity.assign(m_axes, 1.0f);
  m_G.assign(m_axes, std::vector<double>(m_bins, 0.0));
  auto make = [&](VkDeviceSize bytes, const std::string& what) { return makeBuffer(bytes, what, true); };
  m_vegas = make(sizeof(GpuVegas), "vegas state");
  m_cdf = make(std::uint64_t(m_axes) * (m_bins + 1) * 4, "vegas tables");
  m_sums = make(std::uint64_t(m_axes) * m_bins * 8, "vegas bin sums");
  float* cdf = static_cast<float*>(m_cdf->mapped);
  for (std::uint32_t a = 0; a < m_axes; ++a) vegasUniformCdf(cdf + std::size_t(a) * (m_bins + 1), m_bins);
  std::memset(m_sums->mapped, 0, std::size_t(m_axes) * m_bins * 8);
  GpuVegas& v = *static_cast<GpuVegas*>(m_vegas->mapped);
  v = GpuVegas{};
  v.info = {m_axes, m_bins, dims, settings.vegasBounces};
  v.epoch = {0u, VEGAS_NUMBERS_RENDER, settings.vegasLearn > 0 ? 1u : 0u, 0u};
  v.cdf = m_cdf->address;
  v.sums = m_sums->address;
  globals.host().vegas = m_vegas->address;

  createKernels("vegas", VEGAS_KERNEL_WEIGH + 1);
}

VegasIntegrator::~VegasIntegrator() = default;

std::vector<float> VegasIntegrator::cdf(std::uint32_t axis) const {
  const float* c = static_cast<const float*>(m_cdf->mapped) + std::size_t(axis) * (m_bins + 1);
  return std::vector<float>(c, c + m_bins + 1);
}

void VegasIntegrator::renderPass(std::uint32_t sampleIndex, std::uint32_t samples) {
  samples = std::max(1u, samples);
  const std::uint64_t paths = m_pixels * samples;
  if (paths > 0xffffffffull) throw Error("a pass of " + std::to_string(samples) + " samples per pixel has too many paths");
  const std::uint32_t capacity = m_paths->capacity();
  for (std::uint64_t start = 0; start < paths; start += capacity) {
    const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::uint64_t>(capacity, paths - start));
    Globals& g = m_globals.host();
    g.chunkFirst = static_cast<std::uint32_t>(start);
    g.chunkPaths = count;
    g.sampleIndex = sampleIndex;
    g.passSamples = samples;
    m_globals.upload();

    VkCommandBuffer cmd = begin();
    dispatch(cmd, VEGAS_KERNEL_WARP, count);
    m_paths->recordTrace(cmd, count);
    vk::computeBarrier(cmd);
    dispatch(cmd, VEGAS_KERNEL_WEIGH, count);
    m_paths->recordAccumulate(cmd, count);
    submit();
  }
  if (m_report.refinements < m_settings.vegasLearn) learn(paths);
}

void VegasIntegrator::learn(std::uint64_t paths) {
  const auto t0 = std::chrono::steady_clock::now();
  std::uint32_t* sums = static_cast<std::uint32_t*>(m_sums->mapped);
  float* cdf = static_cast<float*>(m_cdf->mapped);
  std::vector<double> S(m_bins);
  for (std::uint32_t a = 0; a < m_axes; ++a) {
    for (std::uint32_t b = 0; b < m_bins; ++b) {
      const std::uint32_t* s = sums + (std::size_t(a) * m_bins + b) * 2;
      S[b] = (double(s[1]) * 4294967296.0 + double(s[0])) / double(VEGAS_FIXED_SCALE);
    }
    float* c = cdf + std::size_t(a) * (m_bins + 1);
    vegasRefine(m_G[a], c, m_bins, S.data(), double(paths), m_settings.vegasAlpha);
    float top = 0;
    for (std::uint32_t b = 0; b < m_bins; ++b) top = std::max(top, (c[b + 1] - c[b]) * float(m_bins));
    m_report.maxDensity[a] = top;
  }
  std::memset(sums, 0, std::size_t(m_axes) * m_bins * 8);
  ++m_report.refinements;
  // The next pass warps with a table learned from this pass's numbers: its warped numbers come from
  // a source none of them shares (vegasNumbers), hashes while the table is learned, the render's
  // sampler with a seed of its own once it is frozen; with alpha 1 no table leaves the uniform one
  // (the path tracer's numbers bit for bit).
  const bool learning = m_report.refinements < m_settings.vegasLearn;
  GpuVegas& v = *static_cast<GpuVegas*>(m_vegas->mapped);
  v.epoch = {m_report.refinements,
             m_settings.vegasAlpha >= 1.0f ? VEGAS_NUMBERS_RENDER : (learning ? VEGAS_NUMBERS_LEARN : VEGAS_NUMBERS_FROZEN),
             learning ? 1u : 0u, 0u};
  m_report.learnedPaths += paths;
  m_report.learnSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace nusselt
