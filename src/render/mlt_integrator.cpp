// mlt_integrator.cpp: the chains' buffers, the bootstrap and the Metropolis steps (mlt_integrator.h).
#include "render/mlt_integrator.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "../../shaders/shared/layout.h"
#include "../../shaders/shared/mlt.h"
#include "util/error.h"

namespace nusselt {

using shared::GpuMlt;
using shared::Globals;


std::uint64_t MltIntegrator::bytesFor(std::uint32_t chains, std::uint32_t slots, std::uint32_t dims,
                                      std::uint32_t bootstrap, std::uint64_t pixels, std::uint32_t restartSpp) {
  // The second vector buffer, states, start indices, extents, stored draws; splat sums; the
  // bootstrap's f values (and the chunk of b' for Kelemen's weights), or the restart pool's if
  // larger; GpuMlt, counters.
  return std::uint64_t(shared::primarySampleSlots(chains)) * dims * 8ull + std::uint64_t(chains) * 32 + pixels * 24 +
         std::max<std::uint64_t>(std::uint64_t(bootstrap) + slots, std::uint64_t(restartSpp) * pixels) * 4 + 256;
}

std::uint32_t MltIntegrator::pathSlotsFor(const RenderSettings& s, std::uint64_t pixels) {
  const std::uint64_t wanted = std::max<std::uint64_t>(pixels * s.mltPassSpp, mltBootstrapPaths(s));
  return static_cast<std::uint32_t>(std::max<std::uint64_t>(s.mltChains, std::min<std::uint64_t>(wanted, 1u << 16)));
}

std::uint32_t MltIntegrator::iterationsPerPassFor(const RenderSettings& s) {
  if (s.samplesPerPass) return s.samplesPerPass;
  return std::max<std::uint32_t>(1, (1u << 18) / std::max<std::uint32_t>(s.mltChains * std::max(s.mltSteps, 1u), 1));
}

MltIntegrator::MltIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                             std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels, MltScene scene)
    : PrimarySampleIntegrator(ctx, globals, settings, std::move(paths), pixels), m_scene(scene) {
  m_chains = settings.mltChains;
  m_dims = globals.host().primaryDims;
  if (m_dims == 0 || m_chains == 0) throw Error("mlt: the path tracer has no primary samples");
  if (m_paths->capacity() < m_chains) throw Error("mlt: the path tracer has fewer path slots than chains");
  m_poolSize = mltBootstrapPaths(settings);
  const std::uint32_t restartSpp = mltRestartSpp(settings, pixels);
  if (restartSpp && (settings.mltPassSpp == 0 || settings.mltChainLight != RADIANCE_CAUSTIC))
    throw Error("mlt: --mlt-restart needs the caustic chains' path-traced pass (--mlt-pass-spp > 0, --mlt-chain-light "
                "caustic): the chains restart from its paths");
  // The restart pool: mltRestart samples of every pixel (whole sweeps, so that its paths cover the
  // image evenly: the pool's mean is then an unbiased b).
  const std::uint64_t restartPaths = std::uint64_t(restartSpp) * pixels;
  if (restartPaths > kMltMaxRestartPaths)
    throw Error("mlt: --mlt-restart " + std::to_string(restartSpp) + " x " + std::to_string(pixels) +
                " pixels is a pool of more than 2^26 paths; give fewer samples per pixel");
  m_report.chains = m_chains;
  m_report.dims = m_dims;
  m_report.bootstrapPaths = m_poolSize;
  auto make = [&](VkDeviceSize bytes, const std::string& what, bool host = false) { return makeBuffer(bytes, what, host); };
  m_mlt = make(sizeof(GpuMlt), "mlt state", true);
  // The chains' second vector buffer (the first is the path tracer's primarySamples).
  vk::Buffer* vectorsB = make(std::uint64_t(shared::primarySampleSlots(m_chains)) * m_dims * 8, "mlt vectors");
  m_state = make(std::uint64_t(m_chains) * 16, "mlt chain states");
  m_splats = make(m_pixels * 24, "mlt splats");
  m_poolF = make(std::max<std::uint64_t>(std::uint64_t(m_poolSize) + m_paths->capacity(), restartPaths) * 4,
                 "mlt bootstrap");
  m_start = make(std::uint64_t(m_chains) * 4, "mlt chain starts");
  vk::Buffer* extent = make(std::uint64_t(m_chains) * 4, "mlt chain extents");
  vk::Buffer* written = make(std::uint64_t(m_chains) * 4, "mlt stored draws");
  m_counters = make(MLT_COUNTERS * 4, "mlt counters", true);
  std::memset(m_counters->mapped, 0, MLT_COUNTERS * 4);
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  m = GpuMlt{};
  m.info = {m_chains, m_dims, 0u, static_cast<std::uint32_t>(m_pixels)};
  m.pool = {0u, 0u, m_poolSize, settings.seed};
  m.params = {settings.mltLargeStep, settings.mltSigma, 0.0f, 0.0f};
  m.vectorsB = vectorsB->address;
  m.state = m_state->address;
  m.splats = m_splats->address;
  m.poolF = m_poolF->address;
  m.start = m_start->address;
  m.counters = m_counters->address;
  m.extent = extent->address;
  m.written = written->address;
  m.outside = {0u, settings.mltPassSpp, 0u, 0u};
  m.restart = {0u, 0u, 0u, static_cast<std::uint32_t>(restartPaths)};
  globals.host().mlt = m_mlt->address;

  VkCommandBuffer cmd = vk::beginOneShot(m_ctx);
  vkCmdFillBuffer(cmd, m_splats->buffer, 0, VK_WHOLE_SIZE, 0);
  vk::endOneShot(m_ctx, cmd);

  createKernels("mlt", MLT_KERNELS);
}

MltIntegrator::~MltIntegrator() = default;

void MltIntegrator::bootstrap(std::uint32_t firstSample) {
  m_bootstrapped = true;
  // Without a delta lobe in the scene no path has caustic light: the chains' part is 0, known
  // without a pool (b = 0, the chains idle), and the path-traced pass carries all light.
  if (chainPart() == RADIANCE_CAUSTIC && !m_scene.deltaMaterials) {
    m_report.noCaustics = true;
    return;
  }
  auto t0 = std::chrono::steady_clock::now();
  Globals& g = m_globals.host();
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  const std::uint32_t seed =
      firstSample == 0 ? m_settings.seed
                       : shared::pcg4d(glm::uvec4(m_settings.seed, firstSample, MLT_STREAM_POOL, 0x85ebca6bu)).x;
  m.pool.w = seed;
  g.radiancePart = chainPart();  // b and the starts are of the chains' f
  g.primaryFresh = PRIMARY_FRESH_POOL;  // a pool path's draws are hashes of its index
  g.chunkFirst = 0;
  g.passSamples = 1;
  g.sampleIndex = 0;
  // The pool, a chunk of at most the path slots at a time.
  const std::uint32_t slots = m_paths->capacity();
  for (std::uint32_t first = 0; first < m_poolSize; first += slots) {
    const std::uint32_t count = std::min(slots, m_poolSize - first);
    m.pool.x = first;
    m.pool.y = count;
    g.chunkPaths = count;
    m_globals.upload();
    traceBetween(MLT_KERNEL_NONE, MLT_KERNEL_RECORD, count);
  }
  std::vector<float>& f = m_poolValues;
  f.resize(m_poolSize);
  vk::downloadBuffer(m_ctx, *m_poolF, f.data(), std::uint64_t(m_poolSize) * 4);
  m_report.b = startChains(f, seed, 0u, 0u);
  for (float fi : f) m_report.nonzeroBootstrap += fi > 0.0f ? 1 : 0;
  // Kelemen's weights need b', an estimate of b independent of the chains' starts (the weights are
  // then a fixed function on the chain's space and the estimate stays unbiased; b itself from the
  // same pool as the starts keeps E[b h(X_0)] = the integral of f h): one more chunk of independent
  // paths, as many as the path slots, pool indices poolSize .. poolSize + slots - 1.
  m.weights = {0.0f, 0.0f, 0.0f, 0.0f};
  if (m_settings.mltKelemen && m_settings.mltLargeStep > 0.0f && m_report.b > 0) {
    m.pool.x = m_poolSize;
    m.pool.y = slots;
    g.chunkPaths = slots;
    g.primaryFresh = PRIMARY_FRESH_POOL;
    m_globals.upload();
    traceBetween(MLT_KERNEL_NONE, MLT_KERNEL_RECORD, slots);
    std::vector<float> fb(slots);
    vk::downloadBuffer(m_ctx, *m_poolF, fb.data(), std::uint64_t(slots) * 4, std::uint64_t(m_poolSize) * 4);
    double sum = 0;
    for (float v : fb) sum += std::max(0.0, double(v));
    m_report.bPrime = sum / double(slots);
    // Without light in that chunk there is no b' to weigh by: the plain splats (a choice made from
    // the chunk alone, so the estimate stays unbiased).
    if (m_report.bPrime > 0)
      m.weights = {1.0f, static_cast<float>(1.0 / m_report.bPrime), 0.0f, m_settings.mltLargeStep};
  }
  setNormalisation(m_report.b);
  m_report.bootstrapSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double MltIntegrator::startChains(const std::vector<float>& f, std::uint32_t seed, std::uint32_t source,
                                  std::uint32_t firstNumber) {
  const std::uint32_t n = static_cast<std::uint32_t>(f.size());
  // b and the cumulative sums in double, in pool order (deterministic).
  std::vector<double> cdf(std::size_t(n) + 1, 0.0);
  for (std::uint32_t i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + std::max(0.0, double(f[i]));
  const double total = cdf[n];
  if (!(total > 0)) return 0.0;
  // Stratified resampling: chain c starts at the pool path whose cdf interval holds (c + u) /
  // chains of the total, u uniform (48 bits from a hash of (c, seed)). Chain c's start is drawn
  // from its own stratum of the cdf; over the chains, whose mean is the image, the starts are
  // in proportion to f_i, so E[b x mean over chains of h(X_0)] = E[(1/B) sum_i f_i h(x_i)] still,
  // and each pool path starts within one chain of its expected count (independent draws
  // scattered the counts multinomially).
  std::vector<std::uint32_t> start(m_chains);
  for (std::uint32_t c = 0; c < m_chains; ++c) {
    const glm::uvec4 h = shared::pcg4d(glm::uvec4(c, seed, MLT_STREAM_START, 0x9e3779b9u));
    const double u = (double(h.x >> 8) * 16777216.0 + double(h.y >> 8)) / 281474976710656.0;
    const double target = (double(c) + u) / double(m_chains) * total;
    auto it = std::upper_bound(cdf.begin() + 1, cdf.end(), target);
    std::uint32_t i = static_cast<std::uint32_t>(std::min<std::ptrdiff_t>(it - cdf.begin() - 1, n - 1));
    while (i > 0 && f[i] <= 0.0f) --i;  // a zero-width interval is never chosen (u < 1 guards the end)
    start[c] = i;
  }
  vk::uploadBuffer(m_ctx, *m_start, start.data(), std::uint64_t(m_chains) * 4);
  Globals& g = m_globals.host();
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  m.restart.x = source;
  m.restart.y = firstNumber;
  g.chunkFirst = 0;
  g.chunkPaths = m_chains;
  g.passSamples = 1;
  g.sampleIndex = 0;
  g.radiancePart = chainPart();
  g.primaryFresh = PRIMARY_FRESH_NONE;  // MLT_KERNEL_START stores the starts' draws
  m_globals.upload();
  traceBetween(MLT_KERNEL_START, MLT_KERNEL_ADOPT, m_chains);
  // A start's path, re-traced from its vector, must be the pool's: the same f (a path is a
  // function of its vector, whichever pass traced it). Counted for the tests.
  std::vector<glm::vec4> state(m_chains);
  vk::downloadBuffer(m_ctx, *m_state, state.data(), std::uint64_t(m_chains) * 16);
  for (std::uint32_t c = 0; c < m_chains; ++c)
    m_report.startMismatches += shared::luminance(glm::vec3(state[c])) != f[start[c]] ? 1 : 0;
  return total / double(n);
}

void MltIntegrator::setNormalisation(double b) {
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  m_b = b;
  // Film value of a splat sum: b x pixels / (chains x steps) per unit, per iteration (the film
  // divides by its count, the iterations); a large step's path as an independent sample: 1 / b.
  m.params.z = static_cast<float>(b * double(m_pixels) / (double(m_chains) * m_settings.mltSteps) /
                                  double(MLT_FIXED_SCALE));
  m.weights.z = b > 0 ? static_cast<float>(1.0 / b) : 0.0f;
}

void MltIntegrator::restart(std::uint32_t firstNumber) {
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  const std::uint32_t n = m.restart.w;
  std::vector<float> f(n);
  vk::downloadBuffer(m_ctx, *m_poolF, f.data(), std::uint64_t(n) * 4);
  const std::uint32_t seed = shared::pcg4d(glm::uvec4(m_settings.seed, m.restart.y, MLT_STREAM_POOL, 0x27d4eb2fu)).x;
  // The pool's paths are samples restart.y .. of every pixel: the starts' vectors are theirs.
  const double b = startChains(f, seed, 1u, m.restart.y);
  setNormalisation(b);
  ++m_report.restarts;
  m.restart.y = firstNumber;  // the next pool: the pass's samples from this iteration on
}

void MltIntegrator::traceBetween(std::uint32_t before, std::uint32_t after, std::uint32_t n) {
  VkCommandBuffer cmd = begin();
  if (before != MLT_KERNEL_NONE) dispatch(cmd, before, n);
  m_paths->recordTrace(cmd, n);
  vk::computeBarrier(cmd);
  dispatch(cmd, after, n);
  submit();
}

void MltIntegrator::readCounters() {
  std::uint32_t* c = static_cast<std::uint32_t*>(m_counters->mapped);
  m_report.proposals += c[0];
  m_report.accepted += c[1];
  m_report.largeProposals += c[2];
  m_report.largeAccepted += c[3];
  std::memset(c, 0, MLT_COUNTERS * 4);
}

void MltIntegrator::renderPass(std::uint32_t sampleIndex, std::uint32_t samples) {
  Globals& g = m_globals.host();
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  const std::uint32_t firstNumber = sampleIndex * m_settings.mltPassSpp;  // the pass's first sample in this call
  if (!m_bootstrapped) {
    bootstrap(sampleIndex);
    // Restarts: the pass pool fills from this call's pass on (none without caustic light).
    if (m_report.noCaustics) m.restart.w = 0;
    m.restart.y = firstNumber;
  } else if (m.restart.w != 0 && std::uint64_t(firstNumber - m.restart.y) * m_pixels >= m.restart.w) {
    restart(firstNumber);
  }
  g.radiancePart = chainPart();
  g.primaryFresh = PRIMARY_FRESH_MUTATE;  // a proposal stores only its moved draws
  g.chunkFirst = 0;
  g.chunkPaths = m_chains;
  g.passSamples = 1;
  if (m_b > 0) {
    // Every iteration moves each chain settings.mltSteps times, in one submission; step j of
    // iteration i is step i x mltSteps + j of the render (GpuMlt.info.z, which keys the step's
    // random numbers: MLT_KERNEL_ADVANCE counts it on the device between steps). The camera's
    // sample index is the iteration's first step: a chain's path reads only its vector.
    const std::uint32_t steps = m_settings.mltSteps;
    for (std::uint32_t k = 0; k < samples; ++k) {
      const std::uint32_t first = (sampleIndex + k) * steps;
      g.sampleIndex = first;
      m.info.z = first;
      m_globals.upload();
      VkCommandBuffer cmd = begin();
      for (std::uint32_t j = 0; j < steps; ++j) {
        if (j > 0) dispatch(cmd, MLT_KERNEL_ADVANCE, 1);
        dispatch(cmd, MLT_KERNEL_MUTATE, m_chains);
        m_paths->recordTrace(cmd, m_chains);
        vk::computeBarrier(cmd);
        dispatch(cmd, MLT_KERNEL_ACCEPT, m_chains);
      }
      submit();
      readCounters();
    }
  }
  // The pass's splats into the film; every pixel counts `samples` iterations.
  m.params.w = float(samples);
  VkCommandBuffer cmd = begin();
  dispatch(cmd, MLT_KERNEL_RESOLVE, static_cast<std::uint32_t>(m_pixels));
  submit();
  if (m_settings.mltPassSpp) outsidePass(sampleIndex, samples);
}

std::uint32_t MltIntegrator::chainPart() const {
  return m_settings.mltPassSpp ? m_settings.mltChainLight : RADIANCE_ALL;
}

void MltIntegrator::outsidePass(std::uint32_t sampleIndex, std::uint32_t samples) {
  Globals& g = m_globals.host();
  GpuMlt& m = *static_cast<GpuMlt*>(m_mlt->mapped);
  const std::uint32_t perIteration = m_settings.mltPassSpp;
  const std::uint32_t total = samples * perIteration;
  // Pixels per trace (at most the path slots), and as many samples of each as the slots hold.
  const std::uint32_t slots = m_paths->capacity();
  const std::uint32_t pixelsPerTrace = static_cast<std::uint32_t>(std::min<std::uint64_t>(slots, m_pixels));
  g.radiancePart = m_settings.mltChainLight == RADIANCE_INDIRECT ? RADIANCE_DIRECT : RADIANCE_NONCAUSTIC;
  g.primaryFresh = PRIMARY_FRESH_PIXEL;  // the path tracer's numbers of the pixel and sample
  g.chunkFirst = 0;
  g.passSamples = 1;
  for (std::uint32_t k = 0; k < total;) {
    // Samples are numbered by iteration, so a resumed render's continue the first segment's.
    const std::uint32_t number = sampleIndex * perIteration + k;
    const std::uint32_t per = std::max<std::uint32_t>(1, std::min<std::uint32_t>(total - k, slots / pixelsPerTrace));
    g.sampleIndex = number;
    m.outside.x = number;
    m.outside.z = per;
    for (std::uint64_t first = 0; first < m_pixels; first += pixelsPerTrace) {
      const std::uint32_t count = static_cast<std::uint32_t>(std::min<std::uint64_t>(pixelsPerTrace, m_pixels - first));
      m.pool.x = static_cast<std::uint32_t>(first);
      m.pool.y = count;
      g.chunkPaths = count * per;
      m_globals.upload();
      traceBetween(MLT_KERNEL_NONE, MLT_KERNEL_PIXEL_ADD, count * per);
    }
    k += per;
  }
  g.radiancePart = chainPart();
  m_globals.upload();
}

}  // namespace nusselt
