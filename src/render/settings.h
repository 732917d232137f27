// settings.h: what a render is asked to do (RenderSettings and its modes) and what it counted
// (RenderStats). Shared by the renderer's parts, the render loop and the command line.
#pragma once
#include <cstdint>
#include <string>

namespace nusselt {

enum class LightingMode : std::uint32_t { Mis = 0, NeeOnly = 1, BsdfOnly = 2 };
const char* lightingModeName(LightingMode mode);
// BSDF sampling strategy for non-delta models (SAMPLER_* in shaders/shared/bsdf_sampling.h).
enum class SamplerKind : std::uint32_t { Quadtree = 0, Cosine = 1, Uniform = 2, Analytic = 3, Tabulated = 4 };
const char* samplerName(SamplerKind kind);
// nullptr-safe parse: returns false for an unknown name.
bool parseSampler(const std::string& name, SamplerKind& kind);

// Random numbers: independent PCG hashes, or padded Owen-scrambled Sobol (quasi-Monte Carlo).
enum class RngMode : std::uint32_t { Pcg = 0, Qmc = 1 };
const char* rngModeName(RngMode mode);

// How a combined material chooses its component at a bounce (COMPONENTS_* in layout.h): albedo =
// the random-walk source's estimator (probability = the component's albedo for wo, the rest ends
// the walk); uniform = probability 1/n and a separate albedo roulette (for comparison).
enum class ComponentSelection : std::uint32_t { Albedo = 0, Uniform = 1 };
const char* componentSelectionName(ComponentSelection mode);
bool parseComponentSelection(const std::string& name, ComponentSelection& mode);

// Russian roulette (ROULETTE_* in layout.h): throughput = continue with the path throughput's
// largest channel from the third bounce on (the default: never amplifies a channel); albedo = the
// random-walk source's roulette by the sample's luminance albedo (for comparison).
enum class RouletteMode : std::uint32_t { Throughput = 0, Albedo = 1 };
const char* rouletteModeName(RouletteMode mode);
bool parseRouletteMode(const std::string& name, RouletteMode& mode);

struct RenderSettings {
  std::uint32_t width = 512;
  std::uint32_t height = 512;
  std::uint32_t spp = 64;
  std::uint32_t maxDepth = 8;       // pbrt's convention: 0 = emitted light only, 1 = direct light
  std::uint32_t seed = 0;
  LightingMode lighting = LightingMode::Mis;
  RngMode rng = RngMode::Pcg;
  SamplerKind sampler = SamplerKind::Quadtree;  // the generic sampler of Montes et al.
  ComponentSelection components = ComponentSelection::Albedo;  // combined materials only
  RouletteMode roulette = RouletteMode::Throughput;
  // The quadtree sampler's table counts (quadtree::QuadtreeSettings; the paper's 90 and 16 by
  // default; phi only for anisotropic sets). Fewer tables build faster (the hard-case tests use
  // 90 x 4 for the anisotropic hard sets) at the cost of a coarser grid in the outgoing direction:
  // a looser fit between tables, more variance (never bias).
  std::uint32_t samplerThetaTables = 90;
  std::uint32_t samplerPhiTables = 16;
  // Sample indices of this render start here (`--spp-offset`): a frame can be split across
  // machines into disjoint sample ranges and merged (`nusselt merge`).
  std::uint32_t sampleOffset = 0;
  // Time every stage with GPU timestamps (stageSeconds()); for benchmarks.
  bool timeStages = false;
  // Paths traced together in one chunk of a pass (path state memory ~128 bytes each).
  std::uint32_t maxPathsPerChunk = 1u << 20;
};

struct RenderStats {
  std::uint64_t rays = 0;
  std::uint64_t shadowRays = 0;
  std::uint64_t nonFiniteSamples = 0;
  std::uint64_t bvhStackOverflows = 0;
  std::uint64_t samplerBoundViolations = 0;
  std::uint64_t samplerTrialFailures = 0;
};

}  // namespace nusselt
