// sampler_commands.cpp: `nusselt sample` (directions from the generic quadtree sampler, GPU or
// CPU, as CSV; optionally an SVG of the tree with the samples) and `nusselt bench precompute`
// (tree build time per model beside the paper's start-up times).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <thread>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "brdf/merl.h"
#include "brdf/registry.h"
#include "cli/cli_common.h"
#include "cli/commands.h"
#include "render/settings.h"
#include "quadtree/sample_run.h"
#include "quadtree/quadtree_build.h"
#include "quadtree/roughness_bins.h"
#include "quadtree/sampler_tables.h"
#include "sampling/tabulated.h"
#include "util/error.h"
#include "vk/vk.h"

namespace nusselt {
namespace {

// Runs gpu(ctx) on a Vulkan context of device `device` (destroyed afterwards, also on an error)
// and returns the device's name: the GPU side of `sample`'s strategies and of its binned mode.
template <class F>
std::string onDevice(int device, F&& gpu) {
  vk::Context ctx;
  vk::ContextOptions opts;
  opts.deviceIndex = device;
  vk::createContext(ctx, opts);
  try {
    gpu(ctx);
  } catch (...) {
    vk::destroyContext(ctx);
    throw;
  }
  std::string name = ctx.deviceName;
  vk::destroyContext(ctx);
  return name;
}

using namespace shared;

struct SampleArgs {
  std::string model;
  std::string file;  // measured models (merl)
  std::vector<std::string> params;
  std::string preset;  // typical (default) or hard
  double thetaDeg = 30;
  double phiDeg = 0;
  std::uint32_t n = 10000;
  std::string output = "samples.csv";
  std::string svg;
  bool cpu = false;
  std::uint32_t seed = 0;
  int device = -1;
  std::uint32_t thetaTables = 90;
  std::uint32_t phiTables = 16;
  std::string sampler = "quadtree";
  std::uint64_t tabBytes = 64 * 1024;
  std::uint32_t roughnessBins = 0;  // > 0: binned sampling of gltf_pbr (bsdf_sampling.h, "Binned sampling")
  float roughnessBinSpacing = 2.0f;
};

std::uint32_t strategyId(const std::string& name) {
  SamplerKind kind = SamplerKind::Quadtree;
  parseSampler(name, kind);
  return static_cast<std::uint32_t>(kind);
}

BrdfParams paramsFor(const ModelSpec& m, const std::string& preset, const std::vector<std::string>& extra) {
  NamedParams values = preset == "hard" ? hardParams(m) : typicalParams(m);
  for (const std::string& a : extra) {
    auto kv = parseParamArgument(a);
    bool replaced = false;
    for (auto& e : values)
      if (e.first == kv.first) { e.second = kv.second; replaced = true; }
    if (!replaced) values.push_back(kv);
  }
  return packParams(m, values, "--param");
}

const ModelSpec& modelOrThrow(const std::string& name) {
  const ModelSpec* m = findModel(name);
  if (!m) throw Error("--model " + name + ": unknown model (one of " + knownModelNames() + ")");
  if (m->delta) throw Error("--model " + name + ": a delta model is always sampled analytically (no strategy applies)");
  return *m;
}

// The tree of table `table` drawn over the disc, plus samples: square leaves as squares, polar
// leaves (the rim annulus) as annular sectors, shaded by their mean density; isotropic sets store
// the half disc y >= 0, drawn mirrored below it (dashed).
void writeSvg(const std::string& path, const quadtree::SamplerTables& t, std::uint32_t set, std::uint32_t table,
              const std::vector<vec4>& samples, const std::string& title) {
  std::ofstream out(path);
  if (!out) throw Error("--svg " + path + ": cannot write");
  const double S = 400;  // pixels per unit
  auto px = [&](double x) { return (x + 1.05) * S; };
  auto py = [&](double y) { return (1.05 - y) * S; };
  const bool aniso = (t.sets[set].info.w & QT_SET_ANISOTROPIC) != 0u;
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << 2.1 * S << "' height='" << 2.1 * S + 30 << "'>\n";
  out << "<rect width='100%' height='100%' fill='white'/>\n";
  out << "<circle cx='" << px(0) << "' cy='" << py(0) << "' r='" << S << "' fill='#f4f4f4' stroke='black' stroke-width='1'/>\n";
  // Square cells cover the inner disc only: clip them to it.
  out << "<clipPath id='inner'><circle cx='" << px(0) << "' cy='" << py(0) << "' r='" << S * std::sqrt(double(QT_INNER_R2))
      << "'/></clipPath>\n";
  const double rootMass = std::max(double(t.tables[table].data.x), 1e-30);
  auto fill = [&](double mass, double area) {
    double density = mass / std::max(area, 1e-30) / rootMass;  // mean pdf on the disc
    double shade = std::min(1.0, std::log1p(density) / std::log1p(50.0));
    int r = int(255 * (1 - 0.7 * shade)), gg = int(255 * (1 - 0.5 * shade));
    return "rgb(" + std::to_string(r) + "," + std::to_string(gg) + ",255)";
  };
  auto sector = [&](const QuadLeaf& l, double ySign, bool dashed) {
    double c0 = l.box.x, c1 = l.box.y, t0 = l.box.z, t1 = l.box.w;
    double r0 = std::sqrt(std::max(0.0, 1 - c1 * c1)), r1 = std::sqrt(std::max(0.0, 1 - c0 * c0));
    double area = 0.5 * (c1 * c1 - c0 * c0) * (t1 - t0) * M_PI;
    std::string d;
    const int K = 8;
    auto pt = [&](double r, double tt) {
      char b[64];
      std::snprintf(b, sizeof b, "%.2f,%.2f ", px(r * std::cos(M_PI * tt)), py(ySign * r * std::sin(M_PI * tt)));
      return std::string(b);
    };
    for (int k = 0; k <= K; ++k) d += pt(r1, t0 + (t1 - t0) * k / K);
    for (int k = K; k >= 0; --k) d += pt(r0, t0 + (t1 - t0) * k / K);
    out << "<polygon points='" << d << "' fill='" << fill(l.data.y, area) << "' fill-opacity='0.6' stroke='#c00000' stroke-width='0.4'"
        << (dashed ? " stroke-dasharray='2,2'" : "") << "/>\n";
  };
  quadtree::forEachLeaf(t.nodes.data(), t.leaves.data(), t.tables[table].info.x, aniso,
                        [&](std::uint32_t, const QuadLeaf& l, double x0, double y0, double size) {
    for (int mirror = 0; mirror < (aniso ? 1 : 2); ++mirror) {
      const std::uint32_t kind = std::uint32_t(l.data.z + 0.5f);
      if (kind == QT_PROPOSAL_POLAR) {
        sector(l, mirror ? -1 : 1, mirror != 0);
        continue;
      }
      // Squares (the inner-circle cuts outlined red), clipped to the inner disc.
      double y = mirror ? -(y0 + size) : y0;
      out << "<rect x='" << px(x0) << "' y='" << py(y + size) << "' width='" << size * S << "' height='" << size * S
          << "' fill='" << fill(l.data.y, size * size) << "' fill-opacity='0.6' stroke='"
          << (kind == QT_PROPOSAL_POLAR_CUT ? "#c00000" : "#303030") << "' stroke-width='0.4'"
          << (mirror ? " stroke-dasharray='2,2'" : "") << " clip-path='url(#inner)'/>\n";
    }
  });
  out << "<circle cx='" << px(0) << "' cy='" << py(0) << "' r='" << S * std::sqrt(double(QT_INNER_R2))
      << "' fill='none' stroke='#808080' stroke-width='0.6' stroke-dasharray='4,3'/>\n";
  for (const vec4& s : samples)
    if (s.w > 0) out << "<circle cx='" << px(s.x) << "' cy='" << py(s.y) << "' r='0.9' fill='black'/>\n";
  out << "<text x='10' y='" << 2.1 * S + 20 << "' font-family='monospace' font-size='13'>" << title << "</text>\n</svg>\n";
}

// The samples that succeeded as CSV (x,y,z,pdf,f: direction, density per unit solid angle,
// luminance of f); returns the number of failed ones (not written).
std::uint64_t writeSamplesCsv(const std::string& path, const quadtree::SampleBatch& b, std::uint32_t n) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw Error("-o " + path + ": cannot write");
  std::fprintf(f, "x,y,z,pdf,f\n");
  std::uint64_t failed = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const vec4& w = b.wPdf[i];
    if (b.fOk[i].w <= 0) { ++failed; continue; }
    std::fprintf(f, "%.9g,%.9g,%.9g,%.9g,%.9g\n", w.x, w.y, w.z, w.w, luminance(vec3(b.fOk[i])));
  }
  if (std::fclose(f) != 0) throw Error("-o " + path + ": cannot write");
  return failed;
}

// `nusselt sample --roughness-bins K`: binned sampling of one gltf_pbr texel (the parameters of
// --param / --preset) with K roughness bins, as a render samples a gltf_pbr material whose textures
// vary its parameters. The bins' trees are built at the theta tables the known direction reads
// only (thetaTablesAround: the sampling there is that of the full grid); pdf in the CSV is the
// mixture's exact density (binnedPdf), f the texel's.
int sampleBinned(const SampleArgs& a, const ModelSpec& m, const BrdfParams& p, vec3 v) {
  if (m.id != MODEL_GLTF_PBR)
    throw Error("--roughness-bins: binned sampling is for gltf_pbr (--model gltf_pbr), not " + m.name);
  if (strategyId(a.sampler) != SAMPLER_QUADTREE)
    throw Error("--roughness-bins: binned sampling mixes quadtrees (--sampler quadtree), not --sampler " + a.sampler);
  if (a.roughnessBins < 2) throw Error("--roughness-bins: at least 2 bins (0: the texel's own tree)");
  if (!a.svg.empty()) throw Error("--svg draws one tree: not with --roughness-bins");
  const RoughnessBins B{0u, a.roughnessBins, a.roughnessBinSpacing, 0u};
  quadtree::QuadtreeSettings qs;
  qs.thetaTables = a.thetaTables;
  qs.phiTables = a.phiTables;
  qs.onlyThetaTables = quadtree::thetaTablesAround(a.thetaDeg, a.thetaTables);
  const quadtree::SamplerTables tables = quadtree::buildRoughnessBinTables(B, qs);
  std::uint32_t j;
  float t;
  binLocate(B, brdfParam(p, GLTF_PBR_ROUGHNESS), j, t);
  float cd;
  {
    quadtree::QuadHostScope scope(tables);
    cd = binnedDiffuseChoice(B, p, v, j, t);
  }
  quadtree::SampleBatch b;
  std::string where;
  if (a.cpu) {
    b = quadtree::sampleCpu(tables, INVALID_INDEX, m.id, p, v, a.n, a.seed, 0, &B);
    where = "cpu";
  } else {
    where = onDevice(a.device, [&](vk::Context& ctx) {
      b = quadtree::sampleGpu(ctx, tables, INVALID_INDEX, m.id, p, v, a.n, a.seed, SAMPLER_QUADTREE, nullptr, false, 0,
                              1u << 20, &B);
    });
  }
  const std::uint64_t failed = writeSamplesCsv(a.output, b, a.n);
  std::printf("%s: %u samples (binned: %u bins spaced %g; roughness %g between bin %u (r = %g) and bin %u (r = %g), "
              "t = %.4g; cosine share c_d = %.4g) on %s in %.3f s; trees: %zu theta tables per bin (%.3f s), %.1f KiB\n",
              m.name.c_str(), a.n, B.count, B.spacing, brdfParam(p, GLTF_PBR_ROUGHNESS), j, binRoughness(B, j), j + 1,
              binRoughness(B, j + 1), t, cd, where.c_str(), b.seconds, qs.onlyThetaTables.size(), tables.seconds,
              tables.bytes() / 1024.0);
  std::printf("bound violations %llu, trial failures %llu, failed samples %llu\n",
              static_cast<unsigned long long>(b.boundViolations), static_cast<unsigned long long>(b.trialFailures),
              static_cast<unsigned long long>(failed));
  return kExitOk;
}

int sampleCommand(const SampleArgs& a) {
  const ModelSpec& m = modelOrThrow(a.model);
  if (a.thetaDeg < 0 || a.thetaDeg >= 90) throw Error("--theta must lie in [0, 90)");
  if (!m.measured && !a.file.empty()) throw Error("--file: only measured models (merl) read a file");
  BrdfParams p = m.measured ? measuredParams(m, a.file, a.params) : paramsFor(m, a.preset, a.params);
  const std::uint32_t strategy = strategyId(a.sampler);
  if (a.roughnessBins > 0) {
    double th = a.thetaDeg * M_PI / 180, ph = a.phiDeg * M_PI / 180;
    return sampleBinned(a, m, p,
                        vec3(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th))));
  }
  if (strategy != SAMPLER_QUADTREE && !a.svg.empty()) throw Error("--svg draws the quadtree: only with --sampler quadtree");
  double th = a.thetaDeg * M_PI / 180, ph = a.phiDeg * M_PI / 180;
  vec3 v(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
  std::vector<std::uint32_t> setIndex{INVALID_INDEX};
  quadtree::SamplerTables tables;
  sampling::TabulatedTables tab;
  if (strategy == SAMPLER_QUADTREE) {
    quadtree::QuadtreeSettings qs;
    qs.thetaTables = a.thetaTables;
    qs.phiTables = a.phiTables;
    tables = quadtree::buildSamplerTables({{m.id, p}}, qs, setIndex);
  } else if (strategy == SAMPLER_TABULATED) {
    sampling::TabulatedSettings ts;
    ts.thetaTables = a.thetaTables;
    ts.bytesPerTable = a.tabBytes;
    // Only the theta tables the known direction uses (the nearest one).
    ts.onlyThetaTables = {std::min<std::uint32_t>(std::uint32_t(std::lround(th / (0.5 * M_PI / a.thetaTables))),
                                                  a.thetaTables - 1)};
    tab = sampling::buildTabulatedTables({{m.id, p}}, ts, setIndex);
  }
  quadtree::SampleBatch b;
  std::string where;
  if (a.cpu && strategy == SAMPLER_QUADTREE) {
    b = quadtree::sampleCpu(tables, setIndex[0], m.id, p, v, a.n, a.seed);
    where = "cpu";
  } else if (a.cpu) {
    b = quadtree::sampleCpuStrategy(strategy, strategy == SAMPLER_TABULATED ? &tab : nullptr, setIndex[0], m.id, p, v,
                                    a.n, a.seed);
    where = "cpu";
  } else {
    where = onDevice(a.device, [&](vk::Context& ctx) {
      b = quadtree::sampleGpu(ctx, tables, setIndex[0], m.id, p, v, a.n, a.seed, strategy,
                             strategy == SAMPLER_TABULATED ? &tab : nullptr);
    });
  }
  const std::uint64_t failed = writeSamplesCsv(a.output, b, a.n);
  if (strategy == SAMPLER_QUADTREE) {
    const quadtree::MaterialStats& st = tables.materials[0];
    std::printf("%s: %u samples on %s in %.3f s; trees: %u (%s, %.3f s), %u nodes, %u leaves, %.1f KiB\n", m.name.c_str(),
                a.n, where.c_str(), b.seconds, st.trees, st.cacheHit ? "cache" : "built", tables.seconds, st.nodes,
                st.leaves, st.bytes / 1024.0);
  } else if (strategy == SAMPLER_TABULATED) {
    const TabSet& s = tab.sets[0];
    std::printf("%s: %u samples (tabulated) on %s in %.3f s; tables: %u x %u (1 theta row built, %.3f s), grid %u x %u, "
                "%.1f KiB per table\n",
                m.name.c_str(), a.n, where.c_str(), b.seconds, s.info.y, s.info.z, tab.seconds, s.grid.x, s.grid.y,
                (sizeof(TabTable) + 4.0 * (s.grid.x + double(s.grid.x) * s.grid.y)) / 1024.0);
  } else {
    std::printf("%s: %u samples (%s%s) on %s in %.3f s\n", m.name.c_str(), a.n, a.sampler.c_str(),
                strategy == SAMPLER_ANALYTIC && !analyticHasSampler(m.id) ? ": no own sampler, cosine" : "", where.c_str(),
                b.seconds);
  }
  std::printf("bound violations %llu, trial failures %llu, failed samples %llu\n",
              static_cast<unsigned long long>(b.boundViolations), static_cast<unsigned long long>(b.trialFailures),
              static_cast<unsigned long long>(failed));
  if (strategy == SAMPLER_QUADTREE && a.cpu && a.n > 0)
    std::printf("per sample: %.3f rejection trials, %.3f evaluations of f in the trials, %.2f inner nodes read\n",
                double(b.trials) / a.n, double(b.evaluations) / a.n, double(b.nodeReads) / a.n);
  if (!a.svg.empty()) {
    const QuadSet& s = tables.sets[setIndex[0]];
    std::uint32_t k = std::min<std::uint32_t>(std::uint32_t(std::lround(th / s.data.y)), s.info.y - 1);
    std::uint32_t j = s.info.z > 1 ? std::min<std::uint32_t>(std::uint32_t(std::lround(ph / s.data.z)), s.info.z - 1) : 0;
    char title[256];
    std::snprintf(title, sizeof title, "%s (%s), table theta=%.1f deg: %u samples; red: polar leaves (rim, inner-circle cuts)",
                  m.name.c_str(), a.preset.empty() ? "typical" : a.preset.c_str(), k * 90.0 / s.info.y, a.n);
    writeSvg(a.svg, tables, setIndex[0], s.info.x + k * s.info.z + j, b.wPdf, title);
  }
  return kExitOk;
}

struct BenchArgs {
  std::vector<std::string> models;
  std::vector<std::string> files;  // measured materials (merl), one row each
  std::string preset = "typical";
  std::uint32_t thetaTables = 90;
  std::uint32_t phiTables = 16;
  unsigned threads = 0;
  int audit = 0;  // lattice points per axis of the envelope audit (0: none)
};

// The time to build every model's trees (cache off), their size and shape, beside the paper's
// start-up times; with --audit N, every leaf's envelope checked against f on an N x N lattice.
int benchPrecompute(const BenchArgs& a) {
  if (std::find(a.models.begin(), a.models.end(), "merl") != a.models.end() && a.files.empty())
    throw Error("--model merl needs --file, a MERL binary file (docs/measured.md)");
  static const std::map<std::string, double> paper = {
      {"ashikhmin_shirley", 51.4}, {"beard_maxwell", 15.5}, {"blinn", 8.7}, {"coupled", 22.6},
      {"htsg", 102.7}, {"lafortune", 6.6}, {"lewis", 6.9}, {"minnaert", 7.3}, {"oren_nayar", 10.5},
      {"phong", 6.9}, {"poulin_fournier", 35.5}, {"schlick", 13.2}, {"strauss", 10.9},
      {"torrance_sparrow", 8.3}, {"ward", 20.7}};
  const unsigned threads = a.threads ? a.threads : std::max(1u, std::thread::hardware_concurrency());
  std::printf("# nusselt bench precompute: %s parameters, %u theta tables (x%u phi tables when anisotropic), cache off, %u threads\n",
              a.preset.c_str(), a.thetaTables, a.phiTables, threads);
  std::printf("%-17s %5s %8s %7s %7s %8s %6s %6s %6s %5s %5s %5s %6s %7s", "model", "trees", "wall_s", "leaves", "B/tree", "KiB",
              "polar", "exp", "sing", "tail", "cap", "depth", "minAcc", "paper_s");
  if (a.audit) std::printf(" %9s", "max f/e");
  std::printf("\n");
  double sum = 0, worstAudit = 0;
  int count = 0, under = 0;
  // The analytic models (unless --model leaves them out), then one measured material per --file.
  std::vector<std::tuple<std::string, const ModelSpec*, BrdfParams>> rows;
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    if (!a.models.empty() && std::find(a.models.begin(), a.models.end(), m.name) == a.models.end()) continue;
    rows.emplace_back(m.name, &m, paramsFor(m, a.preset, {}));
  }
  for (const std::string& f : a.files) {
    const ModelSpec& m = *findModel("merl");
    rows.emplace_back("merl-" + std::filesystem::path(f).filename().string(), &m, measuredParams(m, f, {}));
  }
  for (const auto& [name, model, p] : rows) {
    const ModelSpec& m = *model;
    quadtree::QuadtreeSettings qs;
    qs.useCache = false;
    qs.thetaTables = a.thetaTables;
    qs.phiTables = a.phiTables;
    qs.threads = a.threads;
    std::vector<std::uint32_t> idx;
    quadtree::SamplerTables t = quadtree::buildSamplerTables({{m.id, p}}, qs, idx);
    const quadtree::MaterialStats& s = t.materials[0];
    auto it = paper.find(m.name);
    char ps[16] = "-";
    if (it != paper.end()) std::snprintf(ps, sizeof ps, "%.1f", it->second);
    std::uint32_t singular = 0;
    for (const QuadLeaf& l : t.leaves) singular += l.env.z > 0.0f ? 1u : 0u;
    std::printf("%-17s %5u %8.3f %7u %7.0f %8.1f %6u %6u %6u %5u %5u %5u %6.3f %7s", name.c_str(), s.trees, t.seconds, s.leaves,
                double(s.bytes) / s.trees, s.bytes / 1024.0, s.rimLeaves, s.expLeaves, singular, s.tailLeaves, s.cappedLeaves,
                s.maxDepth, s.minAcceptance, ps);
    if (a.audit) {
      double worst = 0;
      const QuadSet& S = t.sets[0];
      for (std::uint32_t k = 0; k < S.info.y * S.info.z; ++k) {
        const QuadTable& T = t.tables[S.info.x + k];
        quadtree::EnvelopeAudit au = quadtree::auditEnvelopes(m.id, p, quadTableDirection(T), t.nodes.data(), t.leaves.data(),
                                                              T.info.x, T.data.x, a.audit);
        worst = std::max(worst, au.worst);
      }
      std::printf(" %9.4f", worst);
      worstAudit = std::max(worstAudit, worst);
    }
    std::printf("\n");
    if (m.measured) {
      // The table itself: rgb floats on the GPU; the CPU keeps them, the node luminances and their
      // maxima (pyramid, over phi_d: the builder's bounds).
      const MerlTable& mt = merlTable(p);
      std::uint64_t cpu = (mt.rgb.size() + mt.luminance.size() + mt.maxOverPhi.size()) * sizeof(float);
      for (const auto& level : mt.pyramid) cpu += level.size() * sizeof(float);
      std::printf("  %s: table %.1f KiB on the GPU (%u floats), %.1f KiB on the CPU; trees %.1f KiB; %u nodes not measured; "
                  "%.2f M evaluations of f, %.2f M boxes bounded, %.2f s of CPU\n",
                  name.c_str(), MERL_TABLE_FLOATS * 4 / 1024.0, unsigned(MERL_TABLE_FLOATS), cpu / 1024.0, s.bytes / 1024.0,
                  mt.unmeasured, s.evaluations / 1e6, s.certifyBoxes / 1e6, s.buildSeconds);
    }
    std::fflush(stdout);
    sum += t.seconds;
    under += t.seconds < 0.2 ? 1 : 0;
    ++count;
  }
  if (count) {
    std::printf("mean wall time %.3f s over %d models (paper: 20.71 s stated, 21.85 s from its 15 values); %d of %d under 0.2 s\n",
                sum / count, count, under, count);
    if (a.audit) std::printf("largest f / envelope on the %d x %d lattices: %.4f (above 1 would be a bound violation)\n", a.audit,
                             a.audit, worstAudit);
  }
  std::printf("columns: B/tree bytes per tree; polar leaves (rim annulus and inner-circle cuts); exp: leaves with an exponential\n"
              "envelope; sing: with a cos^-s part; tail: negligible-mass leaves below 1/n_max; cap: leaves at the depth cap below\n"
              "1/n_max; minAcc: the lowest acceptance I/V of the other leaves (n_max = 2: at least 0.5)\n");
  return kExitOk;
}

}  // namespace

void registerSamplerCommands(CLI::App& app, CLI::App& bench, CommandRunner& run) {
  auto sa = std::make_shared<SampleArgs>();
  CLI::App* sample = app.add_subcommand("sample", "Draw directions with a BSDF sampling strategy (default: the generic quadtree sampler; CSV: x,y,z,pdf,f)");
  sample->add_option("--model", sa->model, "Reflectance model")->required();
  sample->add_option("--param", sa->params, "name=value, name=r,g,b or name=[JSON] as in NUSSELT_brdf (repeatable); overrides the preset");
  sample->add_option("--file", sa->file, "Measured models (merl): the MERL binary file (docs/measured.md)");
  sample->add_option("--preset", sa->preset, "Parameter set: typical (default) or hard")->check(CLI::IsMember({"typical", "hard"}));
  sample->add_option("--theta", sa->thetaDeg, "Polar angle of the known direction (sin t cos p, sin t sin p, cos t), degrees")->required();
  sample->add_option("--phi", sa->phiDeg, "Azimuth of the known direction, degrees")->capture_default_str();
  sample->add_option("-n", sa->n, "Number of samples")->capture_default_str()->check(CLI::Range(1u, 1u << 28));
  sample->add_option("-o,--output", sa->output, "CSV file")->capture_default_str();
  sample->add_option("--svg", sa->svg, "Also draw the tree of the nearest table with the samples (SVG)");
  sample->add_flag("--cpu", sa->cpu, "Sample on the CPU (the same shared code) instead of the GPU");
  sample->add_option("--seed", sa->seed, "Seed")->capture_default_str();
  sample->add_option("--device", sa->device, "Vulkan device index");
  sample->add_option("--theta-tables", sa->thetaTables, "Tables along theta")->capture_default_str()->check(CLI::Range(1u, 4096u));
  sample->add_option("--phi-tables", sa->phiTables, "Quadtree tables along phi (anisotropic models)")->capture_default_str()->check(CLI::Range(2u, 1024u));
  sample->add_option("--sampler", sa->sampler, "Strategy: quadtree, cosine, uniform, analytic (the model's own importance "
                                               "sampling), tabulated")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kSamplerNames)));
  sample->add_option("--tab-bytes", sa->tabBytes, "tabulated: memory budget of one table in bytes (sets the grid)")
      ->capture_default_str()->check(CLI::Range(std::uint64_t(1024), std::uint64_t(1) << 30));
  sample->add_option("--roughness-bins", sa->roughnessBins, "gltf_pbr: binned sampling with K roughness bins, as renders "
                                                          "sample gltf_pbr whose textures vary its parameters (0: the "
                                                          "texel's own tree; docs/scenes.md)")
      ->capture_default_str()->check(CLI::Range(0u, 64u));
  sample->add_option("--roughness-bin-spacing", sa->roughnessBinSpacing, "with --roughness-bins: bin j of K at roughness "
                                                                      "(j / (K - 1))^spacing")
      ->capture_default_str()->check(CLI::Range(0.25f, 4.0f));
  sample->callback([sa, &run]() { run = [sa]() { return sampleCommand(*sa); }; });

  auto ba = std::make_shared<BenchArgs>();
  CLI::App* pre = bench.add_subcommand("precompute", "Time to build the trees of every model (cache disabled), beside the paper's start-up times");
  pre->add_option("--model", ba->models, "Only these models (repeatable)");
  pre->add_option("--file", ba->files, "Also a measured material (merl) from this MERL binary file (repeatable)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  pre->add_option("--preset", ba->preset, "typical (default) or hard")->check(CLI::IsMember({"typical", "hard"}));
  pre->add_option("--theta-tables", ba->thetaTables, "Tables along theta")->capture_default_str()->check(CLI::Range(1u, 4096u));
  pre->add_option("--phi-tables", ba->phiTables, "Tables along phi (anisotropic models)")->capture_default_str()->check(CLI::Range(2u, 1024u));
  pre->add_option("--threads", ba->threads, "Build threads (0: all cores)")->capture_default_str();
  pre->add_option("--audit", ba->audit, "Also check every leaf's envelope against f on an N x N lattice (0: no)")
      ->capture_default_str()->check(CLI::Range(0, 512));
  pre->callback([ba, &run]() { run = [ba]() { return benchPrecompute(*ba); }; });

  registerBenchError(bench, run);
  registerBenchBins(bench, run);
}

}  // namespace nusselt
