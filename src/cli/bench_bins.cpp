// bench_bins.cpp: `nusselt bench bins` (issue 18): binned sampling of gltf_pbr materials whose
// textures vary their parameters (shaders/shared/bsdf_sampling.h, "Binned sampling") against an
// exact per-texel tree and the cosine, as a function of the bin count K and spacing.
//
// For every texel (roughness r, metallic m, a fixed base colour) and incident angle theta it draws
// n samples of each strategy on the CPU (the shared code) and prints the relative variance
// Var[X] / E[X]^2 of the one-sample estimator X = lum(f) cos / pdf of the texel's albedo:
// cosine (cosine-weighted hemisphere), exact (a quadtree built at the texel's own parameters,
// the quadtree sampler of an untextured material) and binned with K bins. The trees are those of
// the production grid (--theta-tables, 90 by default), built at the measured angles only (the
// sampling at a table direction does not depend on the others). With --full it also builds every
// bin set with all its tables (cache off) and prints each K's memory and build time.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "../../shaders/shared/bsdf_sampling.h"
#include "brdf/albedo.h"
#include "cli/commands.h"
#include "quadtree/roughness_bins.h"
#include "quadtree/sampler_tables.h"

namespace nusselt {

namespace {

using namespace shared;

struct BinsArgs {
  std::vector<std::uint32_t> bins{2, 4, 8, 16, 32};
  std::vector<float> spacings{1.0f, 2.0f};
  std::vector<float> roughness{0.05f, 0.1f, 0.2f, 0.35f, 0.5f, 0.8f};
  std::vector<float> metallic{0.0f, 1.0f};
  std::vector<double> thetas{0.0, 45.0, 75.0};
  std::uint32_t n = 1u << 16;
  std::uint32_t thetaTables = 90;
  std::uint32_t seed = 1;
  bool full = false;
  unsigned threads = 0;
};

const vec3 kBase(0.9f, 0.6f, 0.4f);  // the texels' base colour (a copper-like tint)

BrdfParams texel(float r, float m) {
  BrdfParams p{};
  p.v[0] = vec4(kBase, m);
  p.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = r;
  return p;
}

vec3 incident(double thetaDeg) {
  double t = thetaDeg * M_PI / 180;
  return vec3(float(std::sin(t)), 0.0f, float(std::cos(t)));
}

// Relative variance of X = lum(f) cos / pdf over n samples of `draw` (false: X = 0).
template <class Draw>
double relativeVariance(std::uint32_t n, std::uint32_t seed, const BrdfParams& p, vec3 v, Draw draw) {
  double s = 0, s2 = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    vec2 u = rng2(i, 0u, RNG_DIM_BSDF, seed);
    vec3 wi;
    float pdf;
    double x = 0;
    if (draw(u, wi, pdf) && pdf > 0.0f && wi.z > 0.0f) x = double(luminance(gltfPbrEval(p, wi, v))) * wi.z / pdf;
    s += x;
    s2 += x * x;
  }
  double mean = s / n;
  return mean > 0 ? std::max(0.0, s2 / n - mean * mean) / (mean * mean) : 0.0;
}

quadtree::QuadtreeSettings partialSettings(const BinsArgs& a) {
  quadtree::QuadtreeSettings qs;
  qs.thetaTables = a.thetaTables;
  qs.useCache = false;
  qs.threads = a.threads;
  for (double th : a.thetas)
    qs.onlyThetaTables.push_back(
        std::min<std::uint32_t>(std::uint32_t(std::lround(th / (90.0 / a.thetaTables))), a.thetaTables - 1));
  return qs;
}

int benchBins(const BinsArgs& a) {
  for (double th : a.thetas)
    if (std::fabs(th / (90.0 / a.thetaTables) - std::round(th / (90.0 / a.thetaTables))) > 1e-9)
      std::fprintf(stderr, "note: theta %g is between tables of the %u-table grid\n", th, a.thetaTables);
  const quadtree::QuadtreeSettings qs = partialSettings(a);
  // The bins of every (spacing, K), each its own tables (sets 0 .. K - 1).
  struct Config {
    RoughnessBins B;
    quadtree::SamplerTables t;
  };
  std::vector<Config> configs;
  for (float s : a.spacings)
    for (std::uint32_t k : a.bins) {
      Config c;
      c.B = RoughnessBins{0u, k, s, 0u};
      c.t = quadtree::buildRoughnessBinTables(c.B, qs);
      configs.push_back(std::move(c));
    }

  std::printf("relative variance Var[X] / E[X]^2 of X = lum(f) cos / pdf (the one-sample estimate of the texel's "
              "albedo), %u samples each;\ngltf_pbr texels with baseColor (%.1f, %.1f, %.1f); exact: a quadtree at the "
              "texel's parameters; K: binned sampling with K bins at r_j = (j / (K - 1))^spacing\n\n",
              a.n, kBase.x, kBase.y, kBase.z);
  std::printf("| r | metallic | theta | albedo | cosine | exact |");
  for (const Config& c : configs) std::printf(" K=%u s=%g |", c.B.count, c.B.spacing);
  std::printf("\n|---|---|---|---|---|---|");
  for (std::size_t i = 0; i < configs.size(); ++i) std::printf("---|");
  std::printf("\n");
  std::vector<double> logSum(configs.size() + 2, 0.0);
  std::vector<double> worst(configs.size() + 2, 0.0);
  int rows = 0;
  for (float m : a.metallic)
    for (float r : a.roughness) {
      const BrdfParams p = texel(r, m);
      std::vector<std::uint32_t> idx;
      quadtree::SamplerTables exact = quadtree::buildSamplerTables({{MODEL_GLTF_PBR, p}}, qs, idx);
      for (double th : a.thetas) {
        const vec3 v = incident(th);
        std::vector<double> rv;
        rv.push_back(relativeVariance(a.n, a.seed, p, v, [&](vec2 u, vec3& wi, float& pdf) {
          wi = squareToCosineHemisphere(u);
          pdf = cosineHemispherePdf(wi);
          return true;
        }));
        {
          quadtree::QuadHostScope scope(exact);
          rv.push_back(relativeVariance(a.n, a.seed, p, v, [&](vec2 u, vec3& wi, float& pdf) {
            vec3 f;
            return quadSample(0u, MODEL_GLTF_PBR, p, v, u, wi, pdf, f);
          }));
        }
        for (const Config& c : configs) {
          quadtree::QuadHostScope scope(c.t);
          rv.push_back(relativeVariance(a.n, a.seed, p, v, [&](vec2 u, vec3& wi, float& pdf) {
            vec3 f;
            return binnedSample(c.B, p, v, u, wi, pdf, f);
          }));
        }
        std::printf("| %.2f | %.0f | %.0f | %.4f |", r, m, th, directionalAlbedo(MODEL_GLTF_PBR, p, th));
        for (std::size_t i = 0; i < rv.size(); ++i) {
          std::printf(" %.3g |", rv[i]);
          logSum[i] += std::log(std::max(rv[i], 1e-12));
          worst[i] = std::max(worst[i], rv[i]);
        }
        std::printf("\n");
        ++rows;
      }
    }
  std::printf("| geometric mean | | | |");
  for (double l : logSum) std::printf(" %.3g |", std::exp(l / rows));
  std::printf("\n| worst | | | |");
  for (double w : worst) std::printf(" %.3g |", w);
  std::printf("\n");

  if (a.full) {
    std::printf("\nmemory and build time of the bins with all %u theta tables (cache off; CPU seconds summed over the "
                "trees; moments: the Fresnel moments of every table, setRoughnessBinMoments, on every core)\n\n"
                "| K | spacing | bytes | MiB | build CPU s | build wall s | moments wall s |\n|---|---|---|---|---|---|---|\n",
                a.thetaTables);
    quadtree::QuadtreeSettings fs;
    fs.thetaTables = a.thetaTables;
    fs.useCache = false;
    fs.threads = a.threads;
    for (float s : a.spacings)
      for (std::uint32_t k : a.bins) {
        const auto t0 = std::chrono::steady_clock::now();
        quadtree::SamplerTables t = quadtree::buildRoughnessBinTables(RoughnessBins{0u, k, s, 0u}, fs);
        const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        double cpu = 0;
        for (const quadtree::MaterialStats& st : t.materials) cpu += st.buildSeconds;
        std::printf("| %u | %g | %llu | %.2f | %.1f | %.1f | %.2f |\n", k, s, static_cast<unsigned long long>(t.bytes()),
                    t.bytes() / 1048576.0, cpu, t.seconds, total - t.seconds);
        std::fflush(stdout);
      }
  }
  return 0;
}

}  // namespace

void registerBenchBins(CLI::App& bench, CommandRunner& run) {
  auto a = std::make_shared<BinsArgs>();
  CLI::App* c = bench.add_subcommand("bins", "Binned sampling of textured gltf_pbr: relative variance against the bin "
                                              "count, an exact per-texel tree and the cosine; memory and build time (--full)");
  c->add_option("--bins", a->bins, "Bin counts K (>= 2)")->capture_default_str()->check(CLI::Range(2u, 64u));
  c->add_option("--spacing", a->spacings, "Bin spacings: r_j = (j / (K - 1))^spacing")->capture_default_str()->check(CLI::Range(0.25f, 4.0f));
  c->add_option("--roughness", a->roughness, "Texel roughness values")->capture_default_str()->check(CLI::Range(0.0f, 1.0f));
  c->add_option("--metallic", a->metallic, "Texel metallic values")->capture_default_str()->check(CLI::Range(0.0f, 1.0f));
  c->add_option("--theta", a->thetas, "Incident angles, degrees")->capture_default_str()->check(CLI::Range(0.0, 89.0));
  c->add_option("-n", a->n, "Samples per estimate")->capture_default_str()->check(CLI::Range(1u, 1u << 26));
  c->add_option("--theta-tables", a->thetaTables, "Tables along theta")->capture_default_str()->check(CLI::Range(1u, 4096u));
  c->add_option("--seed", a->seed, "Seed")->capture_default_str();
  c->add_flag("--full", a->full, "Also build every bin set with all its tables (cache off): memory and build time");
  c->add_option("--threads", a->threads, "Build threads (0: all cores)")->capture_default_str();
  c->callback([a, &run]() { run = [a]() { return benchBins(*a); }; });
}

}  // namespace nusselt
