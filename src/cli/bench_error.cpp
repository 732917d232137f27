// bench_error.cpp: `nusselt bench error` (issue 5): speed against error for every BSDF sampling
// strategy, at one shading point (experiment 1: the GPU sample tool, two integrands, relative error
// against sample count and time) and in scenes (experiment 2: renders against a high-spp
// reference). It writes CSV files (run.csv: the settings; point.csv, point_summary.csv,
// scenes.csv: the measurements), PNG plots and EXRs, then the Markdown report, which
// bench_error_report.cpp makes from the CSV files alone (`--report-from DIR` does the same for an
// old run without a device). The method (estimators, references, error, timing, agreement tests)
// and the discussion of the results: docs/results-method.md.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "brdf/albedo.h"
#include "brdf/merl.h"
#include "brdf/registry.h"
#include "cli/bench_error_report.h"
#include "cli/cli_common.h"
#include "cli/commands.h"
#include "io/image.h"
#include "quadtree/sample_run.h"
#include "quadtree/sampler_tables.h"
#include "render/renderer.h"
#include "sampling/tabulated.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/progress.h"
#include "vk/vk.h"

namespace nusselt {
namespace {

using namespace shared;

struct ErrorArgs {
  bool quick = false;
  std::string out = "bench-error";
  std::string report;  // also write the report here (e.g. docs/results.md)
  std::string reportFrom;  // only write the report of the run in this directory (no device)
  int device = -1;
  int maxLog2 = -1;    // -1: 20 (quick: 12)
  int reps = -1;       // -1: 16 (quick: 8)
  std::vector<std::string> models;
  std::vector<std::string> presets;
  std::vector<double> angles;
  std::vector<std::string> files;  // measured materials (merl), experiment 1
  bool noPoint = false, noScenes = false;
  std::uint32_t width = 0, spp = 0, refSpp = 0;
  std::string commandLine;
};

const std::vector<std::uint32_t> kStrategies = {SAMPLER_QUADTREE, SAMPLER_TABULATED, SAMPLER_ANALYTIC, SAMPLER_COSINE,
                                                SAMPLER_UNIFORM};
SamplerKind samplerKind(std::uint32_t s) { return static_cast<SamplerKind>(s); }
const char* strategyName(std::uint32_t s) { return samplerName(samplerKind(s)); }
// Plot colours (sRGB 0-255) per strategy, in kStrategies order.
const int kColours[5][3] = {{214, 39, 40}, {31, 119, 180}, {44, 160, 44}, {255, 127, 14}, {148, 103, 189}};
const char* kColourNames[5] = {"red", "blue", "green", "orange", "purple"};

double envRadiance(vec3 w) {
  double x = std::max(0.0, -double(w.x));
  return 1.0 + 3.0 * x * x * x * x;
}

double zCritical(double alphaTwoSided) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > alphaTwoSided) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
// ---- Experiment 1 -------------------------------------------------------------------------------

struct Curve {
  std::string model, preset;
  double theta = 0;
  std::uint32_t strategy = 0;
  int integrand = 0;  // 0 albedo, 1 environment
  double ref = 0;
  std::vector<double> rmsRel;  // at N = 2^k, k = 0..maxLog2
  double secPerSample = 0;
  double mean = 0, se = 0, z = 0;
  std::uint64_t failed = 0, samples = 0, trialFailures = 0;
  bool analyticIsCosine = false;
  std::uint64_t tabBytes = 0, quadBytesPerTree = 0;
  double timeTo[2] = {0, 0};  // seconds to relative error 1e-2, 1e-3
  bool extrapolated[2] = {false, false};
};

// Seconds to reach relative error e on the curve (N = 2^k, error rms[k]).
double timeToError(const Curve& c, double e, bool& extrapolated) {
  extrapolated = false;
  const auto& r = c.rmsRel;
  for (std::size_t k = 0; k < r.size(); ++k) {
    if (!(r[k] <= e)) continue;
    double n;
    if (k == 0) n = 1;
    else if (r[k - 1] > 0 && r[k] > 0) {
      double t = std::log(r[k - 1] / e) / std::log(r[k - 1] / r[k]);  // in [0, 1]
      n = std::pow(2.0, double(k - 1) + t);
    } else n = std::pow(2.0, double(k));
    return n * c.secPerSample;
  }
  if (r.empty() || !(r.back() > 0) || !std::isfinite(r.back())) return INFINITY;
  extrapolated = true;
  double n = std::pow(2.0, double(r.size() - 1)) * (r.back() / e) * (r.back() / e);
  return n * c.secPerSample;
}

struct PointConfig {
  std::vector<std::string> models;
  std::vector<std::string> presets;
  std::vector<std::string> files;  // measured materials: model "merl-<file name>", preset "measured"
  std::vector<double> angles;
  int maxLog2 = 20;
  int reps = 16;
};

// Timed repetitions of 2^20 samples per strategy and case (median; sample_run.h).
constexpr std::uint32_t kTimingRepeats = 5;

std::vector<Curve> runPoint(vk::Context& ctx, const PointConfig& pc, Progress& progress, std::uint64_t& step) {
  std::vector<Curve> curves;
  const std::uint64_t n = std::uint64_t(1) << pc.maxLog2;
  // Repetitions per GPU call: at most 2^22 samples (128 MiB of read-back) per call.
  const std::uint64_t repsPerCall = std::max<std::uint64_t>(1, (std::uint64_t(1) << 22) / n);
  // The materials: every model x preset, then each measured file.
  struct Material {
    std::string name;
    const ModelSpec* m;
    std::string preset;
    BrdfParams p;
  };
  std::vector<Material> materials;
  for (const std::string& name : pc.models) {
    const ModelSpec* m = findModel(name);
    if (!m || m->delta || m->measured)
      throw Error("bench error --model " + name + ": unknown, delta or measured model (measured: --file)");
    for (const std::string& preset : pc.presets)
      materials.push_back({m->name, m, preset, packParams(*m, preset == "hard" ? hardParams(*m) : typicalParams(*m), m->name)});
  }
  for (const std::string& f : pc.files) {
    const ModelSpec* m = findModel("merl");
    materials.push_back({"merl-" + std::filesystem::path(f).filename().string(), m, "measured", measuredParams(*m, f, {})});
  }
  for (const Material& mat : materials) {
    const ModelSpec* m = mat.m;
    {
      const std::string& preset = mat.preset;
      const BrdfParams& p = mat.p;
      std::vector<std::uint32_t> qSet, tSet;
      quadtree::SamplerTables qt = quadtree::buildSamplerTables({{m->id, p}}, quadtree::QuadtreeSettings{}, qSet);
      sampling::TabulatedSettings ts;
      const quadtree::MaterialStats& qs = qt.materials[0];
      ts.bytesPerTable = sampling::bytesPerTableLike(qs.bytes, qs.trees);  // equal memory per table
      for (double th : pc.angles)
        ts.onlyThetaTables.push_back(
            std::min<std::uint32_t>(std::uint32_t(std::lround(th / (90.0 / ts.thetaTables))), ts.thetaTables - 1));
      sampling::TabulatedTables tab = sampling::buildTabulatedTables({{m->id, p}}, ts, tSet);
      for (double th : pc.angles) {
        const double t = th * M_PI / 180;
        vec3 v(float(std::sin(t)), 0.0f, float(std::cos(t)));
        double ref[2];
        ref[0] = hemisphereIntegral([&](vec3 w) { return double(luminance(brdfEval(m->id, p, w, v))); }, th, 0.0);
        ref[1] = hemisphereIntegral(
            [&](vec3 w) { return envRadiance(w) * double(luminance(brdfEval(m->id, p, w, v))); }, th, 0.0);
        for (std::uint32_t s : kStrategies) {
          Curve c[2];
          std::vector<double> sq(pc.maxLog2 + 1, 0.0);
          std::vector<double> sq1(pc.maxLog2 + 1, 0.0);
          double sum[2] = {0, 0}, sumSq[2] = {0, 0}, secPerSample = 0;
          std::uint64_t failed = 0, trialFailures = 0;
          std::uint32_t set = s == SAMPLER_QUADTREE ? qSet[0] : (s == SAMPLER_TABULATED ? tSet[0] : INVALID_INDEX);
          for (int r0 = 0; r0 < pc.reps; r0 += int(repsPerCall)) {
            int rn = std::min<int>(int(repsPerCall), pc.reps - r0);
            // Seed per call; within a call repetition r owns indices [r n, (r + 1) n).
            // The first call also times 2^20 samples (or all, if fewer) kTimingRepeats times: the
            // time per sample is their median, robust to a busy machine.
            quadtree::SampleBatch b = quadtree::sampleGpu(ctx, qt, set, m->id, p, v, std::uint32_t(rn * n),
                                                          0x5eed0000u + std::uint32_t(r0), s,
                                                          s == SAMPLER_TABULATED ? &tab : nullptr, true,
                                                          r0 == 0 ? kTimingRepeats : 0);
            if (r0 == 0) secPerSample = b.medianSecondsPerSample;
            trialFailures += b.trialFailures;
            for (int r = 0; r < rn; ++r) {
              double acc[2] = {0, 0};
              int k = 0;
              for (std::uint64_t i = 0; i < n; ++i) {
                const vec4& wp = b.wPdf[r * n + i];
                const vec4& fo = b.fOk[r * n + i];
                double y = 0, ye = 0;
                if (fo.w > 0 && wp.w > 0) {
                  // The integrand is the reflection hemisphere's, as the reference's and the other
                  // strategies'. A transmitting model's quadtree also samples the lower side; those
                  // samples add 0 (an unbiased estimate of the upper side's integral, not a failure).
                  y = wp.z > 0 ? double(luminance(vec3(fo))) * double(wp.z) / double(wp.w) : 0.0;
                  ye = y * envRadiance(vec3(wp));
                } else ++failed;
                if (!std::isfinite(y)) { y = 0; ye = 0; ++failed; }
                acc[0] += y;
                acc[1] += ye;
                sum[0] += y;
                sum[1] += ye;
                sumSq[0] += y * y;
                sumSq[1] += ye * ye;
                if (i + 1 == (std::uint64_t(1) << k)) {
                  double e0 = (acc[0] / double(i + 1) - ref[0]) / ref[0];
                  double e1 = (acc[1] / double(i + 1) - ref[1]) / ref[1];
                  sq[k] += e0 * e0;
                  sq1[k] += e1 * e1;
                  ++k;
                }
              }
            }
          }
          const double total = double(pc.reps) * double(n);
          for (int q = 0; q < 2; ++q) {
            Curve& cv = c[q];
            cv.model = mat.name;
            cv.preset = preset;
            cv.theta = th;
            cv.strategy = s;
            cv.integrand = q;
            cv.ref = ref[q];
            cv.secPerSample = secPerSample;
            cv.failed = failed;
            cv.samples = std::uint64_t(total);
            cv.trialFailures = trialFailures;
            cv.analyticIsCosine = s == SAMPLER_ANALYTIC && !analyticHasSampler(m->id);
            cv.tabBytes = ts.bytesPerTable;
            cv.quadBytesPerTree = qs.trees ? qs.bytes / qs.trees : 0;
            for (int k = 0; k <= pc.maxLog2; ++k) cv.rmsRel.push_back(std::sqrt((q == 0 ? sq[k] : sq1[k]) / pc.reps));
            cv.mean = sum[q] / total;
            double var = std::max(0.0, sumSq[q] / total - cv.mean * cv.mean);
            cv.se = std::sqrt(var / total + 1e-10 * ref[q] * ref[q]);
            cv.z = cv.se > 0 ? (cv.mean - ref[q]) / cv.se : 0;
            for (int e = 0; e < 2; ++e) cv.timeTo[e] = timeToError(cv, e == 0 ? 1e-2 : 1e-3, cv.extrapolated[e]);
            curves.push_back(cv);
          }
          progress.update(++step);
        }
      }
    }
  }
  return curves;
}

// ---- Drawing (no font: axes and legend are described in the report) -----------------------------

struct Canvas {
  Image img;
  Canvas(int w, int h, float grey = 1.0f) {
    img.width = w;
    img.height = h;
    img.rgb.assign(std::size_t(3) * w * h, grey);
  }
  static float lin(int c) {
    double x = c / 255.0;
    return float(x <= 0.04045 ? x / 12.92 : std::pow((x + 0.055) / 1.055, 2.4));
  }
  void put(int x, int y, const int c[3]) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
    for (int k = 0; k < 3; ++k) img.rgb[3 * (std::size_t(y) * img.width + x) + k] = lin(c[k]);
  }
  void line(double x0, double y0, double x1, double y1, const int c[3], int thick = 1) {
    int steps = int(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1;
    for (int i = 0; i <= steps; ++i) {
      double t = double(i) / steps;
      int x = int(std::lround(x0 + t * (x1 - x0))), y = int(std::lround(y0 + t * (y1 - y0)));
      for (int dx = 0; dx < thick; ++dx)
        for (int dy = 0; dy < thick; ++dy) put(x + dx, y + dy, c);
    }
  }
};

// Plot axes: x = log10 seconds in [-8, 2], y = log10 relative error in [-4, 1].
constexpr double kXMin = -8, kXMax = 2, kYMin = -4, kYMax = 1;

void drawPanel(Canvas& cv, int ox, int oy, int w, int h, const std::vector<const Curve*>& curves) {
  const int grid[3] = {225, 225, 225}, axis[3] = {0, 0, 0}, mark[3] = {150, 150, 150};
  auto px = [&](double lx) { return ox + (lx - kXMin) / (kXMax - kXMin) * (w - 1); };
  auto py = [&](double ly) { return oy + (kYMax - ly) / (kYMax - kYMin) * (h - 1); };
  for (double d = kXMin; d <= kXMax; d += 1) cv.line(px(d), oy, px(d), oy + h - 1, grid);
  for (double d = kYMin; d <= kYMax; d += 1) cv.line(ox, py(d), ox + w - 1, py(d), d == -2 || d == -3 ? mark : grid);
  cv.line(ox, oy, ox, oy + h - 1, axis);
  cv.line(ox, oy + h - 1, ox + w - 1, oy + h - 1, axis);
  cv.line(ox + w - 1, oy, ox + w - 1, oy + h - 1, axis);
  cv.line(ox, oy, ox + w - 1, oy, axis);
  for (const Curve* c : curves) {
    int si = int(std::find(kStrategies.begin(), kStrategies.end(), c->strategy) - kStrategies.begin());
    double lastX = NAN, lastY = NAN;
    for (std::size_t k = 0; k < c->rmsRel.size(); ++k) {
      double t = std::pow(2.0, double(k)) * c->secPerSample;
      double e = c->rmsRel[k];
      if (!(t > 0) || !(e > 0)) continue;
      double x = px(std::clamp(std::log10(t), kXMin, kXMax)), y = py(std::clamp(std::log10(e), kYMin, kYMax));
      if (std::isfinite(lastX)) cv.line(lastX, lastY, x, y, kColours[si], 2);
      lastX = x;
      lastY = y;
    }
  }
}

// ---- Experiment 2 -------------------------------------------------------------------------------

struct SceneCase {
  std::string name;
  Scene scene;
  std::string note;
};

MaterialComponent componentOf(const std::string& model, float weight) {
  return catalogueComponent(model, typicalParams(*findModel(model)), weight);
}

std::vector<SceneCase> makeScenes(bool quick) {
  std::vector<SceneCase> out;
  const std::string dir = NUSSELT_SCENES_DIR;
  out.push_back({"cornell", loadScene(dir + "/cornell-box.glb"), "Cornell box (all Lambert)"});
  {
    // The Cornell box with its white material (walls, boxes, light housing) a combination of Lambert
    // (weight 0.6) and Phong (typical, weight 0.4): glossy, and a combined material.
    SceneCase c{"cornell-combined", loadScene(dir + "/cornell-box.glb"),
                "Cornell box, white material = 0.6 lambert + 0.4 phong (typical)"};
    Material& white = c.scene.materials[0];
    NamedParams rho = typicalParams(*findModel("lambert"));
    MaterialComponent l = componentOf("lambert", 0.6f), ph = componentOf("phong", 0.4f);
    l.params = white.params;  // keep the white albedo
    setComponents(white, {l, ph});
    out.push_back(std::move(c));
  }
  if (!quick && std::filesystem::exists(dir + "/materials/materials.gltf"))
    out.push_back({"materials", loadScene(dir + "/materials/materials.gltf"), "materials scene (every model)"});
  // The dragon (100k triangles: its BVH and one Renderer per strategy) only in the full run: the
  // quick run is a CI check that the experiments run and agree, kept to a few minutes.
  if (!quick && std::filesystem::exists(dir + "/dragon/dragon.gltf")) {
    std::vector<std::string> models{"oren_nayar", "strauss", "lafortune"};
    for (const std::string& model : models) {
      SceneCase c{"dragon-" + model, loadScene(dir + "/dragon/dragon.gltf"), "dragon, " + model + " (typical)"};
      for (Material& mat : c.scene.materials)
        if (mat.name == "dragon") {
          MaterialComponent k = componentOf(model, 1.0f);
          mat.model = k.model;
          mat.params = k.params;
        }
      out.push_back(std::move(c));
    }
  }
  return out;
}

struct RenderResult {
  Image image;
  double seconds = 0, buildSeconds = 0;
  RenderStats stats;
};

RenderResult renderTimed(vk::Context& ctx, const Scene& scene, RenderSettings s) {
  RenderResult out;
  Renderer r(ctx, scene, s);
  out.buildSeconds = r.summary().samplerSeconds;
  r.renderPass(1);  // warm-up: lavapipe compiles each pipeline at its first dispatch
  r.reset();
  auto t0 = std::chrono::steady_clock::now();
  while (r.samplesDone() < s.spp) {
    if (g_stopSignal) throw Error("interrupted");
    r.renderPass(s.spp - r.samplesDone());
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.image = r.image(true);
  out.stats = r.stats();
  return out;
}

// z of the image means (per-pixel variances of the mean summed: pixels are independent).
double meanZ(const Image& a, const Image& b) {
  double ma = 0, mb = 0, va = 0, vb = 0;
  const double n = double(a.rgb.size());
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    ma += a.rgb[i];
    mb += b.rgb[i];
    if (!a.variance.empty()) va += a.variance[i];
    if (!b.variance.empty()) vb += b.variance[i];
  }
  double se = std::sqrt(va + vb) / n;
  return se > 0 ? (ma - mb) / n / se : 0;
}

// Heat map colour of e = per-pixel relative squared error, log10 e in [-5, 1]: blue -> red.
void heat(double e, int c[3]) {
  double t = std::clamp((std::log10(std::max(e, 1e-12)) + 5.0) / 6.0, 0.0, 1.0);
  static const int stops[5][3] = {{20, 20, 90}, {30, 110, 200}, {60, 190, 90}, {240, 220, 40}, {220, 30, 30}};
  double x = t * 4;
  int i = std::min(3, int(x));
  double f = x - i;
  for (int k = 0; k < 3; ++k) c[k] = int(stops[i][k] + f * (stops[i + 1][k] - stops[i][k]));
}

void writeSideBySide(const std::string& path, const Image& ref, const std::vector<Image>& images) {
  const int w = ref.width, h = ref.height, gap = 4;
  const int cols = int(images.size()) + 1;
  Canvas cv(cols * w + (cols - 1) * gap, 2 * h + gap, 1.0f);
  auto blit = [&](const Image& im, int ox) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k)
          cv.img.rgb[3 * (std::size_t(y) * cv.img.width + ox + x) + k] = im.rgb[3 * (std::size_t(y) * w + x) + k];
  };
  blit(ref, 0);
  for (std::size_t i = 0; i < images.size(); ++i) {
    int ox = int(i + 1) * (w + gap);
    blit(images[i], ox);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double e = 0;
        for (int k = 0; k < 3; ++k) {
          double a = images[i].rgb[3 * (std::size_t(y) * w + x) + k], r = ref.rgb[3 * (std::size_t(y) * w + x) + k];
          e += (a - r) * (a - r) / (r * r + 0.01) / 3;
        }
        int c[3];
        heat(e, c);
        cv.put(ox + x, h + gap + y, c);
      }
  }
  writePng(path, cv.img);
}

struct SceneRow {
  std::string scene, variant;  // variant: strategy name, or "pcg"/"qmc", "albedo"/"uniform"
  std::string experiment;      // strategies, rng, components
  std::uint32_t spp = 0;
  double relMse = 0, seconds = 0, buildSeconds = 0, z = 0;
  bool agree = true;
  std::uint64_t nonFinite = 0, trialFailures = 0;
  // A row whose z exceeds the threshold is rendered again with kReruns other seeds: if they all
  // agree, the first z was an outlier of a heavy-tailed estimator (the per-pixel sample variance
  // underestimates the variance of the mean when rare paths carry most of the energy: caustics
  // through mirrors and glass), not a bias; the verdict and the reruns' z are reported.
  std::vector<double> rerunZ;
};
constexpr int kReruns = 4;

// The report of the run in `dir` (bench_error_report.h) to every non-empty path of `paths`.
void writeReport(const std::string& dir, const std::vector<std::string>& paths) {
  std::string md = benchErrorReport(dir);
  for (const std::string& path : paths) {
    if (path.empty()) continue;
    std::ofstream f(path);
    f << md;
    if (!f) throw Error(path + ": cannot write the report");
  }
}

int benchError(const ErrorArgs& a) {
  if (!a.reportFrom.empty()) {
    // Only the report, from the CSV files of an earlier run: no device, no GPU work. Written to
    // --report, or back into the run's directory.
    const std::string path = a.report.empty() ? a.reportFrom + "/results.md" : a.report;
    writeReport(a.reportFrom, {path});
    std::printf("bench error: wrote %s from the CSV files in %s\n", path.c_str(), a.reportFrom.c_str());
    return kExitOk;
  }
  auto tStart = std::chrono::steady_clock::now();
  PointConfig pc;
  if (a.quick) {
    pc.models = {"phong", "ward", "strauss"};
    pc.presets = {"typical"};
    pc.angles = {0, 60};
    pc.maxLog2 = 12;
    pc.reps = 8;
  } else {
    for (const ModelSpec& m : allModels())
      if (!m.delta) pc.models.push_back(m.name);
    pc.presets = {"typical", "hard"};
    pc.angles = {0, 30, 60, 85};
  }
  if (!a.models.empty()) pc.models = a.models;
  if (!a.presets.empty()) pc.presets = a.presets;
  if (!a.angles.empty()) pc.angles = a.angles;
  pc.files = a.files;
  if (a.maxLog2 >= 0) pc.maxLog2 = a.maxLog2;
  if (a.reps > 0) pc.reps = a.reps;
  for (double th : pc.angles)
    if (!(th >= 0 && th < 90)) throw Error("--angle must lie in [0, 90)");
  const std::uint32_t width = a.width ? a.width : (a.quick ? 32 : 128);
  const std::uint32_t spp = a.spp ? a.spp : (a.quick ? 8 : 100);
  const std::uint32_t refSpp = a.refSpp ? a.refSpp : (a.quick ? 128 : 4096);

  std::filesystem::create_directories(a.out);
  if (!a.report.empty()) checkOutputPath(a.report, "--report");

  vk::Context ctx;
  vk::ContextOptions co;
  co.deviceIndex = a.device;
  co.validation = validationFromEnvironment();
  vk::createContext(ctx, co);
  struct Destroy {
    vk::Context& c;
    ~Destroy() { vk::destroyContext(c); }
  } destroy{ctx};

  std::vector<SceneCase> scenes;
  if (!a.noScenes) scenes = makeScenes(a.quick);
  const std::size_t pointMaterials = pc.models.size() * pc.presets.size() + pc.files.size();
  std::uint64_t steps = (a.noPoint ? 0 : pointMaterials * pc.angles.size() * kStrategies.size());
  for (const SceneCase& sc : scenes) {
    steps += 1 + kStrategies.size();
    if (sc.name == "cornell") steps += 1;           // qmc
    if (sc.name == "cornell-combined") steps += 1;  // uniform components
  }
  Progress progress("bench error", steps, 0);
  std::uint64_t step = 0;

  // ---- Experiment 1 ----
  std::vector<Curve> curves;
  const double zPointDen = 2.0 * double(pointMaterials * pc.angles.size() * kStrategies.size());
  const double zPoint = zCritical(1e-3 / zPointDen);
  if (!a.noPoint) {
    curves = runPoint(ctx, pc, progress, step);
    std::ofstream csv(a.out + "/point.csv");
    csv << "model,preset,theta,strategy,integrand,log2n,samples,rel_rms_error,seconds_per_estimate\n";
    std::ofstream sum(a.out + "/point_summary.csv");
    sum << "model,preset,theta,strategy,integrand,reference,mean,se,z,agree,ns_per_sample,t_1e-2,t_1e-3,"
           "extrapolated_1e-2,extrapolated_1e-3,failed_samples,trial_failures,tab_bytes_per_table,quad_bytes_per_tree,"
           "analytic_is_cosine\n";
    for (const Curve& c : curves) {
      const char* in = c.integrand ? "env" : "albedo";
      for (std::size_t k = 0; k < c.rmsRel.size(); ++k)
        csv << c.model << "," << c.preset << "," << c.theta << "," << strategyName(c.strategy) << "," << in << "," << k
            << "," << (1ull << k) << "," << fmt("%.6e", c.rmsRel[k]) << ","
            << fmt("%.6e", std::pow(2.0, double(k)) * c.secPerSample) << "\n";
      sum << c.model << "," << c.preset << "," << c.theta << "," << strategyName(c.strategy) << "," << in << ","
          << fmt("%.9g", c.ref) << "," << fmt("%.9g", c.mean) << "," << fmt("%.3e", c.se) << "," << fmt("%.3f", c.z)
          << "," << (std::abs(c.z) <= zPoint ? 1 : 0) << "," << fmt("%.3f", c.secPerSample * 1e9) << ","
          << fmt("%.6e", c.timeTo[0]) << "," << fmt("%.6e", c.timeTo[1]) << "," << c.extrapolated[0] << ","
          << c.extrapolated[1] << "," << c.failed << "," << c.trialFailures << "," << c.tabBytes << ","
          << c.quadBytesPerTree << "," << c.analyticIsCosine << "\n";
    }
    // One plot per model and preset (and per measured file): rows = integrands, columns = angles.
    const int pw = 260, ph = 180, gap = 10;
    std::vector<std::pair<std::string, std::string>> plots;
    for (const std::string& model : pc.models)
      for (const std::string& preset : pc.presets) plots.push_back({model, preset});
    for (const std::string& f : pc.files) plots.push_back({"merl-" + std::filesystem::path(f).filename().string(), "measured"});
    for (const auto& [model, preset] : plots) {
      {
        Canvas cv(int(pc.angles.size()) * (pw + gap) + gap, 2 * (ph + gap) + gap);
        for (int q = 0; q < 2; ++q)
          for (std::size_t ai = 0; ai < pc.angles.size(); ++ai) {
            std::vector<const Curve*> sel;
            for (const Curve& c : curves)
              if (c.model == model && c.preset == preset && c.integrand == q && c.theta == pc.angles[ai]) sel.push_back(&c);
            drawPanel(cv, gap + int(ai) * (pw + gap), gap + q * (ph + gap), pw, ph, sel);
          }
        writePng(a.out + "/point-" + model + "-" + preset + ".png", cv.img);
      }
    }
  }

  // ---- Experiment 2 ----
  std::vector<SceneRow> rows;
  std::size_t sceneTests = 0;
  sceneTests = scenes.size() * (kStrategies.size() + 1);
  const double zScene = zCritical(1e-3 / std::max<std::size_t>(1, sceneTests));
  for (const SceneCase& sc : scenes) {
    RenderSettings s;
    const Scene& scene = sc.scene;
    float aspect = scene.hasCamera && scene.camera.aspectRatio > 0 ? scene.camera.aspectRatio : 1.0f;
    s.width = width;
    s.height = std::max(1u, unsigned(width / aspect + 0.5f));
    s.spp = refSpp;
    s.seed = 1000;
    s.sampler = SamplerKind::Quadtree;
    RenderResult ref = renderTimed(ctx, scene, s);
    progress.update(++step);
    writeExr(a.out + "/scene-" + sc.name + "-reference.exr", ref.image);
    s.spp = spp;
    std::vector<Image> images;
    auto add = [&](const std::string& exp, const std::string& variant, const RenderResult& r) {
      SceneRow row;
      row.scene = sc.name;
      row.variant = variant;
      row.experiment = exp;
      row.spp = spp;
      row.relMse = compareImages(r.image, ref.image).relMse;
      row.seconds = r.seconds;
      row.buildSeconds = r.buildSeconds;
      row.z = meanZ(r.image, ref.image);
      row.agree = std::abs(row.z) <= zScene && std::isfinite(row.relMse);
      if (!row.agree && std::isfinite(row.relMse)) {
        RenderSettings again = s;
        bool all = true;
        for (int k = 0; k < kReruns; ++k) {
          again.seed = 5000 + 17 * std::uint32_t(rows.size()) + std::uint32_t(k);
          RenderResult rr = renderTimed(ctx, scene, again);
          row.rerunZ.push_back(meanZ(rr.image, ref.image));
          all = all && std::abs(row.rerunZ.back()) <= zScene;
        }
        row.agree = all;
      }
      row.nonFinite = r.stats.nonFiniteSamples;
      row.trialFailures = r.stats.samplerTrialFailures;
      rows.push_back(row);
      progress.update(++step);
    };
    std::uint32_t seed = 1;
    for (std::uint32_t st : kStrategies) {
      s.sampler = samplerKind(st);
      s.seed = seed++;
      RenderResult r = renderTimed(ctx, scene, s);
      add("strategies", strategyName(st), r);
      writeExr(a.out + "/scene-" + sc.name + "-" + strategyName(st) + ".exr", r.image);
      images.push_back(r.image);
    }
    writeSideBySide(a.out + "/scene-" + sc.name + ".png", ref.image, images);
    if (sc.name == "cornell") {
      // The strategies rendered with the default random numbers (RenderSettings::rng, QMC): the
      // quadtree's row again, and the other mode rendered here.
      const RngMode byDefault = s.rng;
      rows.push_back(rows[rows.size() - kStrategies.size()]);
      rows.back().experiment = "rng";
      rows.back().variant = rngModeName(byDefault);
      s.sampler = SamplerKind::Quadtree;
      s.rng = byDefault == RngMode::Qmc ? RngMode::Pcg : RngMode::Qmc;
      s.seed = seed++;
      RenderResult r = renderTimed(ctx, scene, s);
      add("rng", rngModeName(s.rng), r);  // (reruns, if any, with these settings)
      s.rng = byDefault;
    }
    if (sc.name == "cornell-combined") {
      rows.push_back(rows[rows.size() - kStrategies.size()]);
      rows.back().experiment = "components";
      rows.back().variant = "albedo";
      s.sampler = SamplerKind::Quadtree;
      s.components = ComponentSelection::Uniform;
      s.seed = seed++;
      RenderResult r = renderTimed(ctx, scene, s);
      add("components", "uniform", r);
      s.components = ComponentSelection::Albedo;
    }
  }
  if (!scenes.empty()) {
    std::ofstream csv(a.out + "/scenes.csv");
    csv << "experiment,scene,variant,width,spp,ref_spp,rel_mse,seconds,build_seconds,z_mean,agree,nonfinite,trial_failures,"
           "rerun_z\n";
    for (const SceneRow& r : rows) {
      csv << r.experiment << "," << r.scene << "," << r.variant << "," << width << "," << r.spp << "," << refSpp << ","
          << fmt("%.6e", r.relMse) << "," << fmt("%.4f", r.seconds) << "," << fmt("%.4f", r.buildSeconds) << ","
          << fmt("%.3f", r.z) << "," << (r.agree ? 1 : 0) << "," << r.nonFinite << "," << r.trialFailures << ",";
      for (std::size_t k = 0; k < r.rerunZ.size(); ++k) csv << (k ? " " : "") << fmt("%.3f", r.rerunZ[k]);
      csv << "\n";
    }
  }
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - tStart).count();
  progress.finish();
  {
    // The settings, for the report (bench_error_report.h): key,value; a list repeats its key.
    std::ofstream run(a.out + "/run.csv");
    auto kv = [&](const std::string& key, const std::string& value) { run << key << "," << csvField(value) << "\n"; };
    run << "key,value\n";
    kv("command", a.commandLine);
    kv("run", a.quick ? "the quick run" : "a custom/full run");
    kv("device", ctx.deviceName);
    kv("total_seconds", fmt("%.1f", total));
    kv("experiment_point", a.noPoint ? "0" : "1");
    kv("experiment_scenes", rows.empty() ? "0" : "1");
    for (std::size_t i = 0; i < kStrategies.size(); ++i) kv("strategy", strategyName(kStrategies[i]));
    for (const std::string& m : pc.models) kv("model", m);
    for (const std::string& p : pc.presets) kv("preset", p);
    for (const std::string& f : pc.files) kv("file", f);
    for (double th : pc.angles) kv("angle", fmt("%g", th));
    kv("max_log2", std::to_string(pc.maxLog2));
    kv("reps", std::to_string(pc.reps));
    kv("z_point", fmt("%.4f", zPoint));
    kv("width", std::to_string(width));
    kv("spp", std::to_string(spp));
    kv("ref_spp", std::to_string(refSpp));
    kv("z_scene", fmt("%.4f", zScene));
    kv("reruns", std::to_string(kReruns));
    for (const SceneCase& sc : scenes) kv("scene." + sc.name, sc.note);
    kv("plot_log10_seconds_min", fmt("%g", kXMin));
    kv("plot_log10_seconds_max", fmt("%g", kXMax));
    kv("plot_log10_error_min", fmt("%g", kYMin));
    kv("plot_log10_error_max", fmt("%g", kYMax));
    for (std::size_t i = 0; i < kStrategies.size(); ++i)
      kv(std::string("plot_colour.") + strategyName(kStrategies[i]), kColourNames[i]);
    if (!run) throw Error(a.out + "/run.csv: cannot write");
  }
  // One report path: the report is made from the files just written, as --report-from makes it.
  writeReport(a.out, {a.out + "/results.md", a.report});
  std::uint64_t messages = ctx.validationMessages.load();
  if (messages) throw Error(std::to_string(messages) + " Vulkan validation messages");
  int disagree = 0;
  for (const Curve& c : curves) disagree += std::abs(c.z) > zPoint;
  for (const SceneRow& r : rows) disagree += !r.agree;
  std::string written = "run.csv";
  if (!a.noPoint) written += ",point.csv,point_summary.csv,point-*.png";
  if (!rows.empty()) written += ",scenes.csv,scene-*";
  std::printf("bench error: %zu point curves, %zu scene renders in %.1f s; %d estimates disagree with their reference; "
              "wrote %s/{%s,results.md}%s%s\n",
              curves.size(), rows.size(), total, disagree, a.out.c_str(), written.c_str(),
              a.report.empty() ? "" : " and ", a.report.c_str());
  return kExitOk;
}

}  // namespace

void registerBenchError(CLI::App& bench, CommandRunner& run) {
  auto ea = std::make_shared<ErrorArgs>();
  CLI::App* e = bench.add_subcommand("error", "Speed against error of the BSDF sampling strategies: one shading point "
                                              "and scenes; CSV, PNG plots and a Markdown report");
  e->add_flag("--quick", ea->quick, "A few models, angles, counts and a tiny resolution (a few minutes on 2 cores)");
  e->add_option("--out", ea->out, "Output directory")->capture_default_str();
  e->add_option("--report", ea->report, "Also write the Markdown report here (e.g. docs/results.md)");
  CLI::Option* reportFrom = e->add_option("--report-from", ea->reportFrom,
                "Only write the report again from the CSV files of the run in this directory (no device, no "
                "measurement): to --report, else to DIR/results.md");
  e->add_option("--device", ea->device, "Vulkan device index");
  e->add_option("--max-log2", ea->maxLog2, "Experiment 1: largest sample count 2^N (default 20, quick 12)")
      ->check(CLI::Range(0, 24));
  e->add_option("--reps", ea->reps, "Experiment 1: independent repetitions (default 16, quick 8)")->check(CLI::Range(2, 1024));
  e->add_option("--model", ea->models, "Experiment 1: only these models (repeatable)");
  e->add_option("--file", ea->files, "Experiment 1: also a measured material (merl) from this MERL binary file (repeatable)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  e->add_option("--preset", ea->presets, "Experiment 1: typical and/or hard (repeatable)")
      ->check(CLI::IsMember({"typical", "hard"}));
  e->add_option("--angle", ea->angles, "Experiment 1: incident angles in degrees (repeatable)");
  e->add_flag("--no-point", ea->noPoint, "Skip experiment 1");
  e->add_flag("--no-scenes", ea->noScenes, "Skip experiment 2");
  e->add_option("--width", ea->width, "Experiment 2: image width (default 128, quick 32)")->check(CLI::Range(1u, 4096u));
  e->add_option("--spp", ea->spp, "Experiment 2: spp per strategy (default 100, quick 8)")->check(CLI::Range(1u, 1u << 20));
  e->add_option("--ref-spp", ea->refSpp, "Experiment 2: spp of the quadtree reference (default 4096, quick 128)")
      ->check(CLI::Range(1u, 1u << 24));
  for (CLI::Option* o : e->get_options())
    if (o != reportFrom && o->get_name() != "--report" && o->get_name() != "--help") reportFrom->excludes(o);
  e->callback([ea, &run, e]() {
    std::string cl = "nusselt bench error";
    if (ea->quick) cl += " --quick";
    for (CLI::Option* o : e->get_options())
      if (o->count() && o->get_name() != "--quick" && o->get_name() != "--help") {
        if (o->get_expected_max() == 0) cl += " " + o->get_name();  // a flag (--no-point): no value
        else
          for (const std::string& r : o->results()) cl += " " + o->get_name() + " " + r;
      }
    ea->commandLine = cl;
    run = [ea]() { return benchError(*ea); };
  });
}

}  // namespace nusselt
