// mlt_integrator.h: primary-sample-space Metropolis light transport (PSSMLT; Kelemen,
// Szirmay-Kalos et al. 2002; issue 19, docs/mlt.md) on the GPU, a sibling of the path tracer that
// drives it: the path tracer (PathIntegrator with primary samples and image samples) turns each
// chain's proposed primary sample vector into a path, radiance L and pixel; the mlt stage
// (shaders/stages/mlt.comp) mutates, accepts and splats.
//
//   bootstrap (once): B independent paths (vectors hashed from their index), f_i = luminance(L_i)
//     (L: the chains' part of the radiance, below);
//     b = mean f_i (the normalisation: the integral of f over primary sample space); the chains
//     start at pool paths drawn in proportion to f_i by stratified resampling (chain c from the
//     stratum [c, c + 1) / chains of the cdf, on the host, from a hash of the chain index and the
//     seed), each re-traced from its vector (a path is a function of it).
//   step (per iteration, all chains at once): propose (large step with probability p, else small
//     step), trace, splat the proposal with weight a and the current state with 1 - a (a =
//     min(1, f(y) / f(x))), each as L / f, into 64-bit fixed-point sums; accept with probability a.
//     With Kelemen's weights (the default) both splats are over f / b' + p instead of f, and a
//     large step's path counts once more as an independent sample (docs/mlt.md).
//   resolve (per pass): film += (b x pixels / chains) x splats, count += iterations.
//
// The estimate is unbiased for any chain length: the starts are drawn from the pool in proportion
// to f (over the chains) with b from the same pool, so E[b mean_c h(X_0,c)] = E[(1/B) sum_i f_i
// h(x_i)] = integral of f h, and each step preserves it (f-invariance of the kernel).
//
// Part of the light outside the chains (RenderSettings::mltPassSpp > 0, the default): the chains'
// f is the luminance of one part of each path's radiance (Globals.radiancePart,
// RenderSettings::mltChainLight), and every iteration (mltSteps steps of every chain) also traces
// mltPassSpp paths per pixel for the rest, with the path tracer's own numbers, whose mean goes
// into the film beside the splats. The parts keep the full estimator's MIS weights, so their sum
// is the whole estimate; the chains spend their mutations where Metropolis pays.
// - caustic (the default): the chains carry light that reached a non-delta vertex through delta
//   bounces from the light (L S+ D ... E), which next-event estimation cannot sample; the pass the
//   rest. In a scene without delta lobes the chains stay idle and the pass is the path tracer.
// - indirect (Mitsuba's pssmlt "directSamples"): the chains carry light after two or more
//   scatterings; the pass direct light only (its paths end at their second vertex).
// 0: the whole path contribution is the chains' f.
//
// Restarts (RenderSettings::mltRestart, caustic chains only): every mltRestart pass samples per
// pixel, the chains start again from the pass's own paths of those samples, as from a bootstrap
// pool (b from their f, stratified starts, each re-traced from the pass path's numbers). The pass
// path's f is the caustic light it left to the chains, which the shade and escape stages keep in
// its radiance's w (PRIMARY_SAMPLES only). Each run of the chains between starts is an unbiased
// estimate on its own, as above; a chain held at a rare path holds it for one run, not the whole
// render, and the starts come from many more paths than one pool (docs/mlt.md, "Restarts").
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "render/primary_sample_integrator.h"

namespace nusselt {

struct MltReport {
  std::uint64_t proposals = 0, accepted = 0, largeProposals = 0, largeAccepted = 0;
  double b = 0;                 // the normalisation: mean luminance of the bootstrap paths
  double bPrime = 0;            // b' of Kelemen's weights (0: plain splats), from other paths
  std::uint32_t chains = 0, bootstrapPaths = 0, dims = 0;
  std::uint64_t nonzeroBootstrap = 0;  // bootstrap paths with f > 0
  bool noCaustics = false;      // caustic chains in a scene without delta lobes: no bootstrap, chains idle
  double bootstrapSeconds = 0;  // wall time of the bootstrap (its paths, b, the chains' starts)
  std::uint32_t restarts = 0;   // starts from the pass's paths (RenderSettings::mltRestart)
  std::uint64_t startMismatches = 0;  // chain starts whose re-traced f differs from their pool path's (0)
  double acceptance() const { return proposals ? double(accepted) / double(proposals) : 0.0; }
};

// What the integrator needs to know of the scene.
struct MltScene {
  bool deltaMaterials = true;  // some material (or component) has a delta lobe: caustic light is possible
};

class MltIntegrator : public PrimarySampleIntegrator {
 public:
  // paths: the path tracer, created with PathOptions{primaryDimsFor(maxDepth), imageSamples,
  // capacity = pathSlotsFor(settings, pixels)}.
  MltIntegrator(vk::Context& ctx, StageGlobals& globals, const RenderSettings& settings,
                std::unique_ptr<PathIntegrator> paths, std::uint64_t pixels, MltScene scene = {});
  ~MltIntegrator() override;

  // The path tracer's slots for a Metropolis render: one per chain, and at least as many as the
  // path-traced pass of the light outside the chains can fill (its samples of every pixel per
  // iteration) or the bootstrap pool, up to 2^16: a pass traced in chunks of a few thousand paths
  // cost a quarter more, and a small image's pool of 2^21 paths traced in chunks of its 4096
  // chains took 3.8 s where chunks of 2^16 take 2.2-2.5 s (32 x 32, cornell-glass).
  static std::uint32_t pathSlotsFor(const RenderSettings& settings, std::uint64_t pixels);
  // Device bytes of the chains' state beyond the path tracer's.
  static std::uint64_t bytesFor(std::uint32_t chains, std::uint32_t slots, std::uint32_t dims, std::uint32_t bootstrap,
                                std::uint64_t pixels, std::uint32_t restartSpp = 0);
  // Mutations per chain per pass when RenderSettings::samplesPerPass is 0: about 2^18 paths per
  // pass (the path tracer's count on a CPU device: a time budget ends within a few seconds on
  // lavapipe), at least 1.
  static std::uint32_t iterationsPerPassFor(const RenderSettings& settings);

  // `samples` iterations (one mutation of every chain each), iterations sampleIndex ..
  // sampleIndex + samples - 1; the bootstrap runs before the first.
  void renderPass(std::uint32_t sampleIndex, std::uint32_t samples) override;
  const MltReport& report() const { return m_report; }
  // f (luminance of L) of every bootstrap path, in pool order (after the first pass; tests).
  const std::vector<float>& bootstrapValues() const { return m_poolValues; }

 private:
  // The pool, b, b' and the chains' starts, keyed on the seed and the render's first sample index
  // (0: the seed itself), so that a resumed render's chains restart independently of the first
  // segment's.
  void bootstrap(std::uint32_t firstSample);
  // One submission: kernel `before` (or none: MLT_KERNEL_NONE) over n chains, the path tracer's
  // trace of their paths, then kernel `after` (the pool, the chains' starts, every step).
  void traceBetween(std::uint32_t before, std::uint32_t after, std::uint32_t n);
  void readCounters();
  // Chain starts drawn from a pool's f (in pool order) by stratified resampling (hashes of
  // `seed`), their paths traced (MLT_KERNEL_START from pool `source`: 0 the bootstrap's, 1 the
  // pass's, whose first sample is `firstNumber`; then MLT_KERNEL_ADOPT). Returns the pool's mean f
  // (b); 0 (no chain started) when every f is 0.
  double startChains(const std::vector<float>& f, std::uint32_t seed, std::uint32_t source, std::uint32_t firstNumber);
  // The splats' normalisation from b (GpuMlt.params.z, weights.z); b = 0: the chains idle.
  void setNormalisation(double b);
  // Restart (RenderSettings::mltRestart): the chains start again from the pass pool (the pass's
  // samples since the last start, GpuMlt.restart), with b from it; the next pool begins at pass
  // sample `firstNumber`.
  void restart(std::uint32_t firstNumber);
  // The part of a path's radiance that is the chains' f (RADIANCE_*: all, or indirect light when
  // direct light is outside the chain).
  std::uint32_t chainPart() const;
  // Direct light outside the chain: settings.mltPassSpp x samples direct-light-only paths per
  // pixel (each trace: as many samples of every pixel as the chains' path slots hold), each added
  // to the film / mltPassSpp.
  void outsidePass(std::uint32_t sampleIndex, std::uint32_t samples);

  std::uint32_t m_chains = 0, m_dims = 0, m_poolSize = 0;
  bool m_bootstrapped = false;
  double m_b = 0;  // the current starts' normalisation (the bootstrap's b, then each restart's)
  MltScene m_scene;
  MltReport m_report;
  std::vector<float> m_poolValues;
  vk::Buffer* m_mlt = nullptr;  // the GpuMlt (host visible)
  vk::Buffer* m_poolF = nullptr;
  vk::Buffer* m_start = nullptr;
  vk::Buffer* m_state = nullptr;
  vk::Buffer* m_counters = nullptr;
  vk::Buffer* m_splats = nullptr;
};

}  // namespace nusselt
