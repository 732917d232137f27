// settings.h: what a render is asked to do (RenderSettings and its modes) and what it counted
// (RenderStats). Shared by the renderer's parts, the render loop and the command line.
//
// Every mode is a C++ enum whose values are the shared ids the shaders test (LIGHTING_*,
// SAMPLER_*, RNG_*, COMPONENTS_*, ROULETTE_* in shaders/shared/), with one name table each: the
// command line, the EXR header and the messages all take their names from it.
#pragma once
#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "../../shaders/shared/bsdf_sampling.h"
#include "../../shaders/shared/layout.h"

namespace nusselt {

// A name table entry: an enum value and its name (command line, header).
template <class E>
struct EnumName {
  E value;
  const char* name;
};

// The name of `value` in `table` ("?" when absent).
template <class E, std::size_t N>
const char* enumName(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& e : table)
    if (e.value == value) return e.name;
  return "?";
}
// The value named `name`; false (value untouched) for an unknown name.
template <class E, std::size_t N>
bool parseEnum(const EnumName<E> (&table)[N], const std::string& name, E& value) {
  for (const EnumName<E>& e : table)
    if (name == e.name) {
      value = e.value;
      return true;
    }
  return false;
}
// Every name of `table`, in its order (for CLI11's IsMember and help texts).
template <class E, std::size_t N>
std::vector<std::string> enumNames(const EnumName<E> (&table)[N]) {
  std::vector<std::string> names;
  for (const EnumName<E>& e : table) names.push_back(e.name);
  return names;
}

// Light transport estimator: MIS (NEE + BSDF sampling), or one of them alone (tests, comparisons).
enum class LightingMode : std::uint32_t { Mis = LIGHTING_MIS, NeeOnly = LIGHTING_NEE_ONLY, BsdfOnly = LIGHTING_BSDF_ONLY };
inline constexpr EnumName<LightingMode> kLightingNames[] = {
    {LightingMode::Mis, "mis"}, {LightingMode::NeeOnly, "nee"}, {LightingMode::BsdfOnly, "bsdf"}};

// BSDF sampling strategy for non-delta models (shaders/shared/bsdf_sampling.h).
enum class SamplerKind : std::uint32_t {
  Quadtree = SAMPLER_QUADTREE,  // the generic sampler of Montes et al.
  Cosine = SAMPLER_COSINE,
  Uniform = SAMPLER_UNIFORM,
  Analytic = SAMPLER_ANALYTIC,
  Tabulated = SAMPLER_TABULATED,
};
inline constexpr EnumName<SamplerKind> kSamplerNames[] = {{SamplerKind::Quadtree, "quadtree"},
                                                          {SamplerKind::Cosine, "cosine"},
                                                          {SamplerKind::Uniform, "uniform"},
                                                          {SamplerKind::Analytic, "analytic"},
                                                          {SamplerKind::Tabulated, "tabulated"}};

// Random numbers: independent PCG hashes, or padded Owen-scrambled Sobol (quasi-Monte Carlo).
enum class RngMode : std::uint32_t { Pcg = RNG_PCG, Qmc = RNG_QMC };
inline constexpr EnumName<RngMode> kRngNames[] = {{RngMode::Pcg, "pcg"}, {RngMode::Qmc, "qmc"}};

// How a combined material chooses its component at a bounce (shaders/shared/combined.h): albedo
// = by the component's albedo (the random-walk source's estimator under the albedo roulette, the
// proportional choice by the largest channel under the throughput roulette); uniform = 1/n.
enum class ComponentSelection : std::uint32_t { Albedo = COMPONENTS_ALBEDO, Uniform = COMPONENTS_UNIFORM };
inline constexpr EnumName<ComponentSelection> kComponentNames[] = {{ComponentSelection::Albedo, "albedo"},
                                                                   {ComponentSelection::Uniform, "uniform"}};

// Russian roulette (ROULETTE_* in layout.h): throughput = continue with the path throughput's
// largest channel from the third bounce on (the default: never amplifies a channel); albedo = the
// random-walk source's roulette by the sample's luminance albedo (for comparison).
enum class RouletteMode : std::uint32_t { Throughput = ROULETTE_THROUGHPUT, Albedo = ROULETTE_ALBEDO };
inline constexpr EnumName<RouletteMode> kRouletteNames[] = {{RouletteMode::Throughput, "throughput"},
                                                            {RouletteMode::Albedo, "albedo"}};

// Scene traversal of the intersect stage (rays and shadow rays) (shaders/shared/trace.glsl): rayquery = the
// device's ray queries against acceleration structures, bvh = the GLSL BVH (every device), auto =
// rayquery on a GPU that offers it, else bvh (resolveTraversal, renderer.h). Not a shader value:
// it selects the stages' modules.
enum class Traversal : std::uint32_t { Auto, RayQuery, Bvh };
inline constexpr EnumName<Traversal> kTraversalNames[] = {
    {Traversal::Auto, "auto"}, {Traversal::RayQuery, "rayquery"}, {Traversal::Bvh, "bvh"}};

// The integrator of a render (`--integrator`): path = the wavefront path tracer; mlt = primary
// sample space Metropolis light transport over it (issue 19, docs/mlt.md); vegas = the path tracer
// with VEGAS's learned separable warp of its first draws (docs/vegas.md). Not a shader value.
enum class IntegratorKind : std::uint32_t { Path, Mlt, Vegas };
inline constexpr EnumName<IntegratorKind> kIntegratorNames[] = {
    {IntegratorKind::Path, "path"}, {IntegratorKind::Mlt, "mlt"}, {IntegratorKind::Vegas, "vegas"}};

inline const char* lightingModeName(LightingMode m) { return enumName(kLightingNames, m); }
inline const char* samplerName(SamplerKind k) { return enumName(kSamplerNames, k); }
inline const char* rngModeName(RngMode m) { return enumName(kRngNames, m); }
inline const char* componentSelectionName(ComponentSelection m) { return enumName(kComponentNames, m); }
inline const char* rouletteModeName(RouletteMode m) { return enumName(kRouletteNames, m); }
inline bool parseLighting(const std::string& name, LightingMode& m) { return parseEnum(kLightingNames, name, m); }
inline bool parseSampler(const std::string& name, SamplerKind& k) { return parseEnum(kSamplerNames, name, k); }
inline bool parseRngMode(const std::string& name, RngMode& m) { return parseEnum(kRngNames, name, m); }
inline bool parseComponentSelection(const std::string& name, ComponentSelection& m) {
  return parseEnum(kComponentNames, name, m);
}
inline bool parseRouletteMode(const std::string& name, RouletteMode& m) { return parseEnum(kRouletteNames, name, m); }
inline const char* traversalName(Traversal t) { return enumName(kTraversalNames, t); }
inline bool parseTraversal(const std::string& name, Traversal& t) { return parseEnum(kTraversalNames, name, t); }
inline const char* integratorName(IntegratorKind k) { return enumName(kIntegratorNames, k); }
inline bool parseIntegrator(const std::string& name, IntegratorKind& k) { return parseEnum(kIntegratorNames, name, k); }
// RenderSettings::mltChainLight's names (--mlt-chain-light, the header's nusselt/mltChainLight).
inline std::string mltChainLightName(std::uint32_t part) { return part == RADIANCE_INDIRECT ? "indirect" : "caustic"; }
inline bool parseMltChainLight(const std::string& name, std::uint32_t& part) {
  if (name != "caustic" && name != "indirect") return false;
  part = name == "indirect" ? RADIANCE_INDIRECT : RADIANCE_CAUSTIC;
  return true;
}

// RenderSettings::mltRestart: restart when a bootstrap pool's worth of pass paths is traced.
inline constexpr std::uint32_t kMltRestartAuto = 0xffffffffu;
// The largest restart pool (paths: samples x pixels; 256 MiB of f values).
inline constexpr std::uint64_t kMltMaxRestartPaths = 1ull << 26;

struct RenderSettings {
  IntegratorKind integrator = IntegratorKind::Path;
  std::uint32_t width = 512;
  std::uint32_t height = 512;
  std::uint32_t spp = 64;
  std::uint32_t maxDepth = 8;       // pbrt's convention: 0 = emitted light only, 1 = direct light
  std::uint32_t seed = 0;
  LightingMode lighting = LightingMode::Mis;
  // Scrambled Sobol points: on the Cornell boxes 0.6-0.9x the relMSE of independent numbers at equal
  // spp, for a few % more time (docs/performance.md, "Random numbers").
  RngMode rng = RngMode::Qmc;
  SamplerKind sampler = SamplerKind::Quadtree;  // the generic sampler of Montes et al.
  ComponentSelection components = ComponentSelection::Albedo;  // combined materials only
  RouletteMode roulette = RouletteMode::Throughput;
  // The Renderer resolves Auto to what it uses (Renderer::settings().traversal).
  Traversal traversal = Traversal::Auto;
  // The quadtree sampler's table counts (quadtree::QuadtreeSettings; the paper's 90 and 16 by
  // default; phi only for anisotropic sets). Fewer tables build faster (the hard-case tests use
  // 90 x 4 for the anisotropic hard sets) at the cost of a coarser grid in the outgoing direction:
  // a looser fit between tables, more variance (never bias).
  std::uint32_t samplerThetaTables = 90;
  std::uint32_t samplerPhiTables = 16;
  // Binned sampling of gltf_pbr materials whose textures vary their parameters (quadtree strategy;
  // shaders/shared/bsdf_sampling.h, "Binned sampling"; docs/scenes.md, "Sampling textured
  // materials"): the number of roughness bins K (0: no bins, such materials sample the cosine) and
  // their spacing, r_j = (j / (K - 1))^spacing. Defaults from `nusselt bench bins`.
  std::uint32_t roughnessBins = 16;
  float roughnessBinSpacing = 2.0f;
  // Sample indices of this render start here (`--spp-offset`): a frame can be split across
  // machines into disjoint sample ranges and merged (`nusselt merge`).
  std::uint32_t sampleOffset = 0;
  // Time every stage with GPU timestamps (stageSeconds()); for benchmarks.
  bool timeStages = false;
  // Samples per pixel traced together in one pass (`--samples-per-pass`); 0 = automatic
  // (samplesPerPassFor). A pass of K samples gives the image of K passes of one sample bit for
  // bit: it only puts more paths in flight per dispatch, which keeps a CPU device's cores busy
  // through the short tail of each bounce and a GPU's many more cores fed.
  std::uint32_t samplesPerPass = 0;
  // Paths traced together in one chunk of a pass (path state memory ~150 bytes each).
  std::uint32_t maxPathsPerChunk = 1u << 20;
  // Path guiding (issue 16, docs/guiding.md; `--guiding on`): directions from a learned
  // incident-radiance guide, one-sample MIS with the BSDF sampler. Off by default.
  bool guiding = false;
  // Samples per pixel of the guide's training, in iterations of 1, 2, 4, ... (`--guide-train`);
  // 0 = automatic (guideTrainingSpp). Training samples are rendered and kept in the image.
  std::uint32_t guideTrainSpp = 0;
  // Samples per pixel of a training pass at most (0: the render's samples per pass; the renderer
  // resolves it and the record states it). The guide depends on how its training samples were
  // grouped into passes (their splat order), so a resumed render trains in the saved one's passes.
  std::uint32_t guideTrainPass = 0;
  // The guide's trees at most this many bytes on the device (`--guide-memory`, MiB there).
  std::uint64_t guideMemory = 16ull << 20;
  // The guide's selection probability (`--guide-alpha`): < 0 (`auto`, the default) learns it per
  // region (guiding::kGuideAlphaAuto; docs/guiding.md); a value in [0, 1) serves every region
  // that learned something (0 keeps the guided pipelines but never samples the guide, to measure
  // their cost).
  float guideAlpha = -1.0f;
  // c of the guide's spatial split rule (`--guide-spatial`): a region splits after c sqrt(2^k)
  // splats in iteration k. Mueller et al.'s 12000 suits their 1280 x 720 images; small images
  // get few regions with it (docs/guiding.md, measurements).
  double guideSpatialThreshold = 12000;
  // The guide's splat filters (`--guide-filter`, `--guide-spatial-filter`: box or none) and the
  // uniform density mixed into it (`--guide-floor`): guiding::GuideSettings, docs/guiding.md.
  bool guideDirFilter = true;
  bool guideSpatialFilter = false;
  double guideFloor = 0.0;
  // What the guide learns (`--guide-learn`): the incident radiance L_i (false) or the product
  // L_i f cos of the vertices that trained it (true, the default: docs/guiding.md, "What the guide
  // learns"); guiding::GuideSettings::product.
  bool guideProduct = true;
  // Photons of the guide's pre-pass (`--guide-photons`; 0: none): traced from the lights before
  // the first training iteration, their arrivals after a bounce train the guide that iteration
  // samples (docs/guiding.md, "Photon pre-pass").
  std::uint32_t guidePhotons = 0;
  // The path tracer reads every random number of a path from a primary sample vector in a buffer
  // (PathOptions::primaryDims = PathIntegrator::primaryDimsFor(maxDepth); Renderer::paths()), which
  // the caller fills: for tests of the primary sample source. Not a command-line option.
  bool primarySamples = false;
  // Called with a line of news about long start-up work (a quadtree build that misses the cache,
  // which can take minutes: "sampler: building ..."); the command line prints it unless --quiet.
  // Not a command-line option; may be empty.
  std::function<void(const std::string&)> notice;
  // The part of each path's radiance the path tracer adds (RADIANCE_*, layout.h: 0 all, 1 direct
  // light only, 2 indirect light only; Globals.radiancePart). Not a command-line option: for tests
  // (Metropolis sets its own, mlt_integrator.h).
  std::uint32_t radiancePart = 0;
  // Metropolis (--integrator mlt, docs/mlt.md). Chains in flight (`--mlt-chains`; each a path slot
  // and a primary sample vector of PathIntegrator::primaryDimsFor(maxDepth) draws). 4096 with 8
  // steps per iteration: caustic chains start from the bootstrap's few caustic paths, and fewer,
  // longer chains were better at equal time on lavapipe (docs/mlt.md, "Caustic chains").
  std::uint32_t mltChains = 4096;
  // Independent paths of the bootstrap (`--mlt-bootstrap`): the normalisation b and the chains'
  // starts come from them; 0 = 16 x chains, at least 2^21 (docs/mlt.md, "The pool's size": caustic
  // chains that start at a rare, bright pool path stay near it, so the pool bounds their error; at
  // 2^21 the glass box's whole-image error at equal time was 14-15 % below 2^20's in two runs).
  std::uint32_t mltBootstrap = 0;
  // Probability of a large step (`--mlt-large-step`; Kelemen et al. and pbrt: 0.3; caustic chains
  // accept 0.1 % of them, docs/mlt.md).
  float mltLargeStep = 0.1f;
  // Standard deviation of a small step's move per coordinate (`--mlt-sigma`; pbrt: 0.01).
  float mltSigma = 0.01f;
  // Splat weights (`--mlt-weights`): Kelemen et al.'s combination of the chain with its large steps
  // (each large step's path also counts as an independent path-tracer sample, both weighted by
  // 1 / (f / b' + p_large)), or the plain expected-value splats (false). docs/mlt.md.
  bool mltKelemen = true;
  // The light the chains carry (`--mlt-chain-light`; RADIANCE_CAUSTIC or RADIANCE_INDIRECT,
  // layout.h) when mltPassSpp > 0: the rest is path-traced per pixel beside the splats. Caustic:
  // only light that reached a non-delta vertex through delta bounces from the light (paths the
  // path tracer's next-event estimation cannot sample; Metropolis only where path tracing fails);
  // indirect: light after two or more scatterings (Mitsuba's pssmlt). docs/mlt.md.
  std::uint32_t mltChainLight = RADIANCE_CAUSTIC;
  // Steps of every chain per iteration (`--mlt-steps`): an iteration (a sample per pixel of the
  // render's count) moves each chain this many times and path-traces mltPassSpp samples of every
  // pixel for the light outside the chains, so this sets the share of mutations in the time.
  std::uint32_t mltSteps = 8;
  // Path-traced samples per pixel per iteration of the light outside the chains (`--mlt-pass-spp`,
  // formerly `--mlt-direct-spp`); 0: the chains carry all light (docs/mlt.md).
  std::uint32_t mltPassSpp = 1;
  // Restarts (`--mlt-restart`, docs/mlt.md "Restarts"): the caustic chains start again, from the
  // pass's own paths (with mltPassSpp > 0), whenever the pass has traced this many samples of every
  // pixel since their last start: b and the starts from those paths, as the bootstrap's from its
  // pool. 0: never (the chains run from their bootstrap starts to the end); kMltRestartAuto (the
  // default): mltRestartSpp.
  std::uint32_t mltRestart = kMltRestartAuto;
  // VEGAS (--integrator vegas, docs/vegas.md). Bins per warped axis (`--vegas-bins`, 1 .. 4096).
  std::uint32_t vegasBins = 64;
  // Bounces whose light choice, light point and BSDF draws are warped (`--vegas-bounces`, 1 ..
  // max depth + 1; 5 axes each). 1: bounce 1's axes learned little and cost throughput (docs/vegas.md).
  std::uint32_t vegasBounces = 1;
  // Weight of the uniform density in every learned one (`--vegas-alpha`, 0.01 .. 1; 1: no warp):
  // every bin keeps a density >= alpha, so the estimate stays unbiased and 1 / p_a <= 1 / alpha.
  float vegasAlpha = 0.2f;
  // Tables learned (`--vegas-learn`, one after each pass; at least 1): then the table is frozen,
  // and the warped numbers of the later passes come from the render's sampler again (vegas.h,
  // vegasNumbers: while it learns, they are hashes). docs/vegas.md.
  std::uint32_t vegasLearn = 8;
};

// RenderSettings::mltRestart resolved for an image of `pixels`: auto restarts caustic chains
// (beside a pass) after as many pass samples per pixel as make a bootstrap pool (mltBootstrapPaths,
// rounded up to whole samples of every pixel; at most kMltMaxRestartPaths paths), and never restarts
// other chains, nor any in an image whose single sample of every pixel would be a larger pool.
inline std::uint32_t mltRestartSpp(const RenderSettings& s, std::uint64_t pixels);

// The bootstrap paths of a Metropolis render (RenderSettings::mltBootstrap resolved).
inline std::uint32_t mltBootstrapPaths(const RenderSettings& s) {
  return s.mltBootstrap ? s.mltBootstrap
                        : static_cast<std::uint32_t>(std::min<std::uint64_t>(std::max<std::uint64_t>(16ull * s.mltChains, 1u << 21), 1u << 30));
}

inline std::uint32_t mltRestartSpp(const RenderSettings& s, std::uint64_t pixels) {
  if (s.mltRestart != kMltRestartAuto) return s.mltRestart;
  if (!s.mltPassSpp || s.mltChainLight != RADIANCE_CAUSTIC || pixels == 0 || pixels > kMltMaxRestartPaths) return 0;
  const std::uint64_t spp = std::max<std::uint64_t>(1, (mltBootstrapPaths(s) + pixels - 1) / pixels);
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(spp, kMltMaxRestartPaths / pixels));
}

// The training samples per pixel of a guided render: settings.guideTrainSpp, or when 0 the
// largest 2^K - 1 <= min(spp / 2, 127) (complete doubling iterations, at most half of the
// samples, and at most 127 for renders limited by time, whose spp is open).
inline std::uint32_t guideTrainingSpp(const RenderSettings& s) {
  if (s.guideTrainSpp) return s.guideTrainSpp;
  std::uint32_t budget = std::min<std::uint32_t>(s.spp / 2, 127u), t = 0;
  while (2 * t + 1 <= budget) t = 2 * t + 1;
  return t;
}

// Whether `trained` samples per pixel end a training iteration: iteration k covers the samples
// [2^k - 1, 2^(k+1) - 1), so its end is 2^(k+1) - 1 (0 ends none).
inline bool guideIterationEnds(std::uint32_t trained) { return trained > 0 && ((trained + 1) & trained) == 0; }

// What the stages counted, summed over passes: one field per entry of NUSSELT_STATS (layout.h).
struct RenderStats {
#define NUSSELT_STAT_FIELD(ID, index, name, what) std::uint64_t name = 0;
  NUSSELT_STATS(NUSSELT_STAT_FIELD)
#undef NUSSELT_STAT_FIELD

  // Every counter of `other` added to this one's.
  void add(const RenderStats& other);
  // The device's 32-bit counters (the stats buffer, STAT_COUNT uints) added.
  void addDevice(const std::uint32_t* counters);
  // Calls f(name, description, value&) for every counter, in the list's order (header, merge).
  template <class F>
  void forEach(F&& f) {
#define NUSSELT_STAT_VISIT(ID, index, name, what) f(#name, what, name);
    NUSSELT_STATS(NUSSELT_STAT_VISIT)
#undef NUSSELT_STAT_VISIT
  }
  template <class F>
  void forEach(F&& f) const {
#define NUSSELT_STAT_VISIT(ID, index, name, what) f(#name, what, name);
    NUSSELT_STATS(NUSSELT_STAT_VISIT)
#undef NUSSELT_STAT_VISIT
  }
};

}  // namespace nusselt
