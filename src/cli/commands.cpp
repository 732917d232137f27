// commands.cpp: the command line: render, devices, bench render.
#include "cli/commands.h"

#include <CLI/CLI.hpp>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <thread>

#include "brdf/albedo.h"
#include "cli/cli_common.h"
#include "io/image.h"
#include "quadtree/sampler_tables.h"
#include "render/guide.h"
#include "render/mlt_integrator.h"
#include "render/vegas_integrator.h"
#include "../../shaders/shared/vegas.h"
#include "render/render_loop.h"
#include "render/renderer.h"
#include "scene/gltf_loader.h"
#include "util/error.h"
#include "util/format.h"
#include "util/progress.h"
#include "util/stop_signal.h"
#include "vk/vk.h"

namespace nusselt {
namespace {


struct RenderArgs {
  std::string scene;
  std::string output;
  std::string png;
  std::string camera;
  std::string resume;
  std::uint32_t spp = 64;
  std::uint32_t width = 0, height = 0;
  std::uint32_t seed = 0;
  std::uint32_t sppOffset = 0;
  std::uint32_t maxDepth = 8;
  std::uint32_t samplesPerPass = 0;
  int device = -1;
  std::string lighting = "mis";
  std::string rng = rngModeName(RenderSettings{}.rng);
  std::string sampler = "quadtree";
  std::uint32_t roughnessBins = RenderSettings{}.roughnessBins;
  float roughnessBinSpacing = RenderSettings{}.roughnessBinSpacing;
  std::string components = "albedo";
  std::string roulette = "throughput";
  std::string traversal = "auto";
  std::string integrator = "path";
  std::uint32_t mltChains = RenderSettings{}.mltChains;
  std::uint32_t mltBootstrap = 0;
  float mltLargeStep = RenderSettings{}.mltLargeStep;
  float mltSigma = RenderSettings{}.mltSigma;
  std::string mltWeights = "kelemen";
  std::uint32_t mltPassSpp = RenderSettings{}.mltPassSpp;
  std::string mltChainLight = mltChainLightName(RenderSettings{}.mltChainLight);
  std::uint32_t mltSteps = RenderSettings{}.mltSteps;
  std::string mltRestart = "auto";
  std::uint32_t vegasBins = 64;
  std::uint32_t vegasBounces = 1;
  float vegasAlpha = 0.2f;
  std::uint32_t vegasLearn = RenderSettings{}.vegasLearn;
  std::string guiding = "off";
  std::uint32_t guideTrain = 0;
  double guideMemoryMiB = 16;
  double guideSpatial = 12000;
  std::string guideAlpha = "auto";
  std::string guideFilter = "box";
  std::string guideSpatialFilter = "none";
  double guideFloor = 0.0;
  std::string guideLearn = "product";
  std::uint32_t guidePhotons = 0;
  bool variance = false;
  bool validation = false;
  bool quiet = false;
  float exposure = 0.0f;
  double checkpointSeconds = 120;
  double timeBudget = 0;
  bool sppGiven = false;
  EnvironmentArgs env;
};

// --guide-alpha: "auto" (learned per region: a negative alpha in the settings) or a number in
// [0, maxAlpha].
float parseGuideAlpha(const std::string& text, float maxAlpha) {
  if (text == "auto") return -1.0f;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !(v >= 0.0 && v <= maxAlpha))
    throw Error("--guide-alpha " + text + ": auto or a number in [0, " + std::to_string(maxAlpha).substr(0, 4) + "]");
  return static_cast<float>(v);
}

// --mlt-restart: "auto" (kMltRestartAuto), "off" or 0 (never), or samples per pixel.
std::uint32_t parseMltRestart(const std::string& text) {
  if (text == "auto") return kMltRestartAuto;
  if (text == "off") return 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || text[0] == '-' || *end != '\0' || v >= kMltRestartAuto)
    throw Error("--mlt-restart " + text + ": auto, off or a number of samples per pixel");
  return static_cast<std::uint32_t>(v);
}

int renderCommand(const RenderArgs& a) {
  if (a.spp == 0) throw Error("--spp 0: at least one sample per pixel is needed");
  const std::string output = !a.output.empty() ? a.output : !a.resume.empty() ? a.resume : "render.exr";
  checkOutputPath(output, "-o");
  if (!a.png.empty()) checkOutputPath(a.png, "--png");
  auto t0 = std::chrono::steady_clock::now();

  // A signal from here on is handled: before the first pass it just ends without output.
  ScopedStopSignals signals;

  Scene scene = loadCommandScene(a.scene, a.camera, a.env, a.quiet);

  RenderSettings s;
  s.seed = a.seed;
  s.maxDepth = a.maxDepth;
  s.sampleOffset = a.sppOffset;
  s.samplesPerPass = a.samplesPerPass;
  parseLighting(a.lighting, s.lighting);
  parseRngMode(a.rng, s.rng);
  parseSampler(a.sampler, s.sampler);
  s.roughnessBins = a.roughnessBins;
  s.roughnessBinSpacing = a.roughnessBinSpacing;
  parseComponentSelection(a.components, s.components);
  parseRouletteMode(a.roulette, s.roulette);
  parseTraversal(a.traversal, s.traversal);
  if (!parseIntegrator(a.integrator, s.integrator))
    throw Error("--integrator " + a.integrator + ": unknown integrator (path, mlt or vegas)");
  s.mltChains = a.mltChains;
  s.mltBootstrap = a.mltBootstrap;
  s.mltLargeStep = a.mltLargeStep;
  s.mltSigma = a.mltSigma;
  s.mltKelemen = a.mltWeights == "kelemen";
  s.mltPassSpp = a.mltPassSpp;
  s.mltSteps = a.mltSteps;
  s.mltRestart = parseMltRestart(a.mltRestart);
  if (!parseMltChainLight(a.mltChainLight, s.mltChainLight))
    throw Error("--mlt-chain-light " + a.mltChainLight + ": caustic or indirect");
  s.vegasBins = a.vegasBins;
  s.vegasBounces = a.vegasBounces;
  s.vegasAlpha = a.vegasAlpha;
  s.vegasLearn = a.vegasLearn;
  s.guiding = a.guiding == "on";
  s.guideTrainSpp = a.guideTrain;
  s.guideSpatialThreshold = a.guideSpatial;
  s.guideAlpha = parseGuideAlpha(a.guideAlpha, 0.99f);
  s.guideMemory = static_cast<std::uint64_t>(a.guideMemoryMiB * 1048576.0);
  s.guideDirFilter = a.guideFilter == "box";
  s.guideSpatialFilter = a.guideSpatialFilter == "box";
  s.guideFloor = a.guideFloor;
  s.guideProduct = a.guideLearn == "product";
  s.guidePhotons = a.guidePhotons;
  // What Metropolis renders do not support (docs/mlt.md): guiding and the variance of a correlated
  // estimate. A resumed one restarts its chains from a new bootstrap (docs/mlt.md, "Resume").
  if (s.integrator == IntegratorKind::Mlt) {
    if (s.guiding) throw Error("--integrator mlt with --guiding on: not supported (docs/mlt.md)");
    if (a.variance)
      throw Error("--variance with --integrator mlt: the Metropolis estimate has no per-sample variance (its samples "
                  "are correlated; docs/mlt.md)");
  }
  // VEGAS renders (docs/vegas.md): a resumed one learns its tables anew from uniform (docs/vegas.md).
  if (s.integrator == IntegratorKind::Vegas) {
    if (s.guiding) throw Error("--integrator vegas with --guiding on: not supported (docs/vegas.md)");
  }
  imageSize(scene, a.width, a.height, 512u, s.width, s.height);
  // The samples to take: --spp, or without it and with --time as many as the budget allows.
  const std::uint32_t targetSpp = a.timeBudget > 0 && !a.sppGiven ? (1u << 30) : a.spp;
  s.spp = targetSpp;
  if (s.guiding) s.guideTrainSpp = guideTrainingSpp(s);  // resolved once: the record states it

  RenderRecord base;
  base.scene = scene.sourcePath;
  base.settings = s;
  base.camera = scene.hasCamera ? scene.camera : frameScene(scene);
  base.droppedTriangles = scene.droppedTriangles;
  recordEnvironment(base, scene);

  // --resume: the saved render must be of this very render (scene and settings), fewer spp.
  Image saved;
  RenderRecord previous;
  if (!a.resume.empty()) {
    ImageMetadata meta;
    saved = readExr(a.resume, &meta);
    previous = readRecord(a.resume, meta);
    previous.settings.width = static_cast<std::uint32_t>(saved.width);
    previous.settings.height = static_cast<std::uint32_t>(saved.height);
    // A render resumes at the view it was rendered from (a preview's save may have moved it).
    if (previous.cameraRecorded) base.camera = previous.camera;
    else previous.camera = base.camera;
    const std::string d = firstDifference(previous, base);
    if (!d.empty())
      throw Error("--resume " + a.resume + ": " + d + " (saved vs this render; a render can only be resumed with the "
                  "same scene and settings)");
    // A guided render resumes with the guide it had learned: the same guide settings (the training
    // spp as recorded: the default depends on --spp) and the guide trained again below.
    if (s.guiding) {
      const RenderSettings& p = previous.settings;
      auto refuse = [&](const std::string& what, const std::string& was, const std::string& is) {
        throw Error("--resume " + a.resume + ": " + what + " was " + was + ", this render has " + is +
                    " (a guided render resumes with the guide settings it was rendered with)");
      };
      if (a.guideTrain != 0 && a.guideTrain != p.guideTrainSpp)
        refuse("--guide-train", std::to_string(p.guideTrainSpp), std::to_string(a.guideTrain));
      if (p.guideAlpha != s.guideAlpha)
        refuse("--guide-alpha", p.guideAlpha < 0 ? "auto" : formatNumber(p.guideAlpha),
               s.guideAlpha < 0 ? "auto" : formatNumber(s.guideAlpha));
      if (p.guideSpatialThreshold != s.guideSpatialThreshold)
        refuse("--guide-spatial", formatNumber(p.guideSpatialThreshold), formatNumber(s.guideSpatialThreshold));
      if (p.guideMemory != s.guideMemory)
        refuse("--guide-memory", formatNumber(p.guideMemory / 1048576.0) + " MiB",
               formatNumber(s.guideMemory / 1048576.0) + " MiB");
      auto box = [](bool on) { return std::string(on ? "box" : "none"); };
      if (p.guideDirFilter != s.guideDirFilter) refuse("--guide-filter", box(p.guideDirFilter), box(s.guideDirFilter));
      if (p.guideSpatialFilter != s.guideSpatialFilter)
        refuse("--guide-spatial-filter", box(p.guideSpatialFilter), box(s.guideSpatialFilter));
      if (p.guideFloor != s.guideFloor) refuse("--guide-floor", formatNumber(p.guideFloor), formatNumber(s.guideFloor));
      auto learn = [](bool product) { return std::string(product ? "product" : "radiance"); };
      if (p.guideProduct != s.guideProduct)
        refuse("--guide-learn", learn(p.guideProduct), learn(s.guideProduct));
      if (p.guidePhotons != s.guidePhotons)
        refuse("--guide-photons", std::to_string(p.guidePhotons), std::to_string(s.guidePhotons));
      s.guideTrainSpp = base.settings.guideTrainSpp = p.guideTrainSpp;
      s.guideTrainPass = base.settings.guideTrainPass = p.guideTrainPass;  // the passes it trained in
    }
    if (previous.settings.sampleOffset != s.sampleOffset)
      throw Error("--resume " + a.resume + ": --spp-offset was " + std::to_string(previous.settings.sampleOffset) +
                  ", this render has " + std::to_string(s.sampleOffset));
    if (saved.sum.empty() || saved.sumSq.empty())
      throw Error("--resume " + a.resume + ": no accumulation channels (sum.R/G/B, sumSq.R/G/B)");
    if (previous.spp >= targetSpp)
      throw Error("--resume " + a.resume + ": it already has " + std::to_string(previous.spp) +
                  " spp; ask for more with --spp (the total)");
  }

  vk::Context ctx;
  vk::ContextOptions co;
  co.deviceIndex = a.device;
  co.validation = a.validation || validationFromEnvironment();
  co.rayQuery = s.traversal != Traversal::Bvh;
  vk::createContext(ctx, co);
  int status = kExitOk;
  {
    if (!a.quiet) s.notice = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    Renderer renderer(ctx, scene, s);
    renderer.setCamera(base.camera);
    const SceneSummary& sum = renderer.summary();
    std::string models;
    for (auto& m : sum.models) models += (models.empty() ? "" : ",") + m;
    base.device = ctx.deviceName;
    base.driver = ctx.driverInfo;
    base.models = models;
    base.roughnessBins = sum.roughnessBins;
    if (!a.resume.empty()) {
      if (previous.device != ctx.deviceName && !a.quiet)
        std::fprintf(stderr, "warning: %s was rendered on %s; continuing on %s (not bit-identical to an uninterrupted render)\n",
                     a.resume.c_str(), previous.device.c_str(), ctx.deviceName.c_str());
      else if (previous.settings.traversal != renderer.settings().traversal && !a.quiet)
        std::fprintf(stderr, "warning: %s was traced with --traversal %s; continuing with %s (not bit-identical to an "
                             "uninterrupted render)\n",
                     a.resume.c_str(), traversalName(previous.settings.traversal),
                     traversalName(renderer.settings().traversal));
    }
    if (!a.quiet) {
      char structures[128];
      if (sum.traversal == Traversal::RayQuery)
        std::snprintf(structures, sizeof structures, "acceleration structures %.1f MiB in %.3f s",
                      sum.accelerationBytes / 1048576.0, sum.accelerationSeconds);
      else
        std::snprintf(structures, sizeof structures, "BVH %u nodes in %.3f s", sum.bvhNodes, sum.bvhSeconds);
      std::fprintf(stderr, "scene: %s: %zu triangles, %zu materials (models: %s), %zu lights; %s\n",
                   scene.sourcePath.c_str(), sum.triangles, sum.materials, models.c_str(), sum.lights, structures);
      if (base.environment != "none")
        std::fprintf(stderr, "environment: %s, scale %g, rotated %g degrees about +Y\n", base.environment.c_str(),
                     base.envScale, base.envRotate);
      if (sum.samplerTrees && s.sampler == SamplerKind::Tabulated)
        std::fprintf(stderr, "sampler: %u tabulated tables (%.1f MiB) in %.2f s\n", sum.samplerTrees,
                     sum.samplerBytes / 1048576.0, sum.samplerSeconds);
      else if (sum.samplerTrees)
        std::fprintf(stderr, "sampler: %u quadtrees (%.1f MiB) in %.2f s (cache: %u hits, %u built, %u rejected)\n",
                     sum.samplerTrees, sum.samplerBytes / 1048576.0, sum.samplerSeconds, sum.samplerCacheHits,
                     sum.samplerCacheMisses, sum.samplerCacheRejected);
      if (sum.constantBrdfs)
        std::fprintf(stderr, "sampler: %u material%s or component%s with a constant BRDF (lambert) sampled by cosine, "
                             "the exact sampler its quadtree would be\n",
                     sum.constantBrdfs, sum.constantBrdfs == 1 ? "" : "s", sum.constantBrdfs == 1 ? "" : "s");
      if (sum.roughnessBins)
        std::fprintf(stderr, "sampler: textured gltf_pbr sampled with %u roughness bins (spacing %g, %.1f MiB of the trees)\n",
                     sum.roughnessBins, s.roughnessBinSpacing, sum.binBytes / 1048576.0);
      std::string budget = a.timeBudget > 0 ? ", time budget " + std::to_string(a.timeBudget) + " s" : "";
      std::fprintf(stderr, "device: %s (%s); %ux%u, %s spp%s%s (%u per pass), max depth %u, seed %u, lighting %s, rng %s, sampler %s, "
                           "roulette %s, traversal %s, integrator %s%s\n",
                   ctx.deviceName.c_str(), ctx.driverInfo.c_str(), s.width, s.height,
                   targetSpp == (1u << 30) ? "unlimited" : std::to_string(targetSpp).c_str(),
                   a.resume.empty() ? "" : (" (resuming from " + std::to_string(previous.spp) + ")").c_str(),
                   budget.c_str(), renderer.samplesPerPass(), s.maxDepth, s.seed, lightingModeName(s.lighting), rngModeName(s.rng),
                   samplerName(s.sampler), rouletteModeName(s.roulette), traversalName(sum.traversal),
                   integratorName(s.integrator), s.guiding ? (", guiding on (" + std::to_string(sum.guideTrainSpp) + " training spp)").c_str() : "");
    }

    if (!a.resume.empty()) {
      if (renderer.guide()) {
        // The guide is not in the file: training is deterministic, so the same samples train the
        // same guide again; its hash in the file says whether it did.
        if (!a.quiet)
          std::fprintf(stderr, "guiding: training the guide again on the first %u spp of %s\n",
                       std::min(previous.spp, renderer.summary().guideTrainSpp), a.resume.c_str());
        renderer.retrainGuide(previous.spp);
        const std::string hash = renderer.guide()->hashText();
        if (previous.guideHash != hash && !a.quiet)
          std::fprintf(stderr, "warning: %s: the guide trained again (hash %s) differs from the one the render had "
                               "(%s); the render continues unbiased but is not bit-identical to an uninterrupted one\n",
                       a.resume.c_str(), hash.c_str(), previous.guideHash.empty() ? "not recorded" : previous.guideHash.c_str());
      }
      renderer.restoreAccumulation(saved, previous.spp);
      renderer.addStats(previous.stats);
    }
    base.totalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();  // set-up
    RenderLoopOptions lo;
    lo.spp = targetSpp;
    lo.timeBudget = a.timeBudget;
    lo.checkpointSeconds = a.checkpointSeconds;
    lo.output = output;
    lo.variance = a.variance;
    lo.quiet = a.quiet;
    // With a time budget the automatic training ends where the budget says (docs/guiding.md).
    lo.trainingWithinBudget = s.guiding && a.timeBudget > 0 && a.guideTrain == 0 && a.resume.empty();
    RenderLoop loop(renderer, base, previous, lo);
    loop.run();
    RenderRecord rec = loop.record(false);
    if (const DeviceGuide* guide = renderer.guide(); guide && !a.quiet) {
      for (const guiding::IterationReport& r : guide->reports())
        std::fprintf(stderr, "guiding: iteration %s: %llu splats; %u regions, %llu direction nodes, %.2f MiB of %.2f MiB "
                             "(rho %g)%s; the guide sampled in %u regions (mean alpha %.3f)\n",
                     (r.photons ? "photons " + std::to_string(r.iteration) : std::to_string(r.iteration)).c_str(), static_cast<unsigned long long>(r.splats), r.leaves,
                     static_cast<unsigned long long>(r.dirNodes), r.bytes / 1048576.0, s.guideMemory / 1048576.0,
                     r.dirThreshold, r.capped ? ", memory cap reached" : "", r.guidedLeaves, r.meanAlpha);
      // A render that stopped (--time, an interrupt) before the end of training says so.
      const std::uint32_t planned = renderer.summary().guideTrainSpp;
      const std::uint32_t trained = std::min<std::uint64_t>(planned, rec.spp);
      std::string why = trained < planned ? " of " + std::to_string(planned) + " (stopped during training)" : "";
      if (loop.trainingEndedAt())
        why = " (ended by the time budget: the next iteration would have left less than twice its own time to sample its guide)";
      std::fprintf(stderr, "guiding: %u training spp%s, %.3f s of CPU time reading records, splatting and refining\n",
                   trained, why.c_str(), guide->trainingSeconds());
    }
    if (const MltIntegrator* mlt = renderer.mlt(); mlt && !a.quiet && mlt->report().noCaustics) {
      std::fprintf(stderr, "mlt: no material has a delta lobe, so no path carries caustic light: the chains stayed idle "
                           "and the path-traced pass rendered all light (--mlt-chain-light, docs/mlt.md)\n");
    } else if (const MltIntegrator* mlt = renderer.mlt(); mlt && !a.quiet) {
      const MltReport& m = mlt->report();
      std::fprintf(stderr, "mlt: %u chains of %u primary draws; bootstrap %u paths (%llu with f > 0), b = %.6g, in %.2f s; "
                           "%s; %llu mutations, acceptance %.1f %% (large steps %.1f %% of them, accepted %.1f %%)\n",
                   m.chains, m.dims, m.bootstrapPaths, static_cast<unsigned long long>(m.nonzeroBootstrap), m.b,
                   m.bootstrapSeconds,
                   m.bPrime > 0 ? ("Kelemen weights, b' = " + std::to_string(m.bPrime)).c_str() : "plain splats", static_cast<unsigned long long>(m.proposals), 100.0 * m.acceptance(),
                   m.proposals ? 100.0 * double(m.largeProposals) / double(m.proposals) : 0.0,
                   m.largeProposals ? 100.0 * double(m.largeAccepted) / double(m.largeProposals) : 0.0);
      if (const std::uint32_t n = mltRestartSpp(rec.settings, std::uint64_t(rec.settings.width) * rec.settings.height))
        std::fprintf(stderr, "mlt: the chains started again %u time(s), each from the path-traced pass's last %u sample(s) "
                             "per pixel (--mlt-restart)\n", m.restarts, n);
      if (m.startMismatches)
        std::fprintf(stderr, "mlt: warning: %llu chain start(s) re-traced to a path other than their pool path's (a bug: "
                             "the image may be biased)\n", static_cast<unsigned long long>(m.startMismatches));
    }
    if (const VegasIntegrator* vegas = renderer.vegas(); vegas && !a.quiet) {
      const VegasReport& v = vegas->report();
      std::fprintf(stderr, "vegas: %u axes (%u bounces) of %u bins, %u primary draws per path; %u tables learned from "
                           "%llu paths in %.3f s; largest density per bounce (light choice, light point x y, bsdf x y):",
                   v.axes, v.bounces, v.bins, v.dims, v.refinements, static_cast<unsigned long long>(v.learnedPaths),
                   v.learnSeconds);
      for (std::uint32_t a = 0; a < v.axes; ++a)
        std::fprintf(stderr, "%s%.2f", a % VEGAS_AXES_PER_BOUNCE == 0 ? (a ? " | " : " ") : " ", v.maxDensity[a]);
      std::fprintf(stderr, "\n");
    }
    if (rec.interrupted)
      std::fprintf(stderr, "interrupted by %s after %u of %u spp: writing what has accumulated\n",
                   g_stopSignal == SIGINT ? "SIGINT" : "SIGTERM", rec.spp, targetSpp);

    if (rec.spp > previous.spp) {
      loop.write(output, false, a.png, a.exposure);
      if (!a.quiet) {
        std::fprintf(stderr, "wrote %s (%u spp)%s%s\n", output.c_str(), rec.spp, a.png.empty() ? "" : " and ",
                     a.png.c_str());
        if (rec.stats.nonFiniteSamples)
          std::fprintf(stderr, "warning: %llu non-finite samples were dropped\n",
                       static_cast<unsigned long long>(rec.stats.nonFiniteSamples));
        if (rec.stats.bvhStackOverflows)
          std::fprintf(stderr, "warning: %llu BVH traversals overflowed their stack\n",
                       static_cast<unsigned long long>(rec.stats.bvhStackOverflows));
      }
    } else {
      std::fprintf(stderr, "no sample was completed: nothing written\n");
    }
    if (rec.interrupted) status = kExitInterrupted;
  }
  std::uint64_t messages = ctx.validationMessages.load();
  vk::destroyContext(ctx);
  if (messages) {
    std::fprintf(stderr, "error: %llu Vulkan validation messages\n", static_cast<unsigned long long>(messages));
    if (status == kExitOk) status = kExitFailure;
  }
  return status;
}

// Combines partial renders of disjoint sample ranges (--spp-offset) into one, weighted by spp:
// the sums add. Equals a single render of the same samples up to float rounding of the sums.
int mergeCommand(const std::vector<std::string>& inputs, const std::string& output) {
  if (inputs.size() < 2) throw Error("merge: give at least two images");
  checkOutputPath(output, "-o");
  Image total;
  RenderRecord merged;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    ImageMetadata meta;
    Image img = readExr(inputs[k], &meta);
    RenderRecord r = readRecord(inputs[k], meta);
    if (r.settings.integrator == IntegratorKind::Mlt)
      throw Error(inputs[k] + ": rendered with --integrator mlt; merging Metropolis renders is not supported (docs/mlt.md)");
    if (r.settings.integrator == IntegratorKind::Vegas)
      throw Error(inputs[k] + ": rendered with --integrator vegas; merging VEGAS renders is not supported (each part "
                  "learned its own warp: the merge would not be one render of those samples; docs/vegas.md)");
    r.settings.width = static_cast<std::uint32_t>(img.width);
    r.settings.height = static_cast<std::uint32_t>(img.height);
    if (img.sum.empty() || img.sumSq.empty())
      throw Error(inputs[k] + ": no accumulation channels (sum.R/G/B, sumSq.R/G/B): not a nusselt render");
    if (k == 0) {
      total = img;
      merged = r;
      merged.source = "merge";
      merged.spp = 0;
      merged.stats = RenderStats{};
      merged.renderSeconds = merged.totalSeconds = 0;
    } else {
      // Files that predate the camera record were rendered from their scene's camera: equal.
      if (!r.cameraRecorded || !merged.cameraRecorded) r.camera = merged.camera;
      const std::string d = firstDifference(merged, r);
      if (!d.empty()) throw Error(inputs[k] + ": " + d + " (" + inputs[0] + " vs this file): only renders of the same "
                                  "scene and settings can be merged");
      if (r.settings.traversal != merged.settings.traversal)
        std::fprintf(stderr, "note: %s was traced with --traversal %s, %s with %s (both estimate the same image); the "
                             "merged header names %s\n",
                     inputs[k].c_str(), traversalName(r.settings.traversal), inputs[0].c_str(),
                     traversalName(merged.settings.traversal), traversalName(merged.settings.traversal));
      for (std::size_t i = 0; i < total.sum.size(); ++i) {
        total.sum[i] += img.sum[i];
        total.sumSq[i] += img.sumSq[i];
      }
    }
    for (auto [lo, n] : ranges)
      if (r.settings.sampleOffset < lo + n && lo < r.settings.sampleOffset + r.spp)
        throw Error(inputs[k] + ": its samples [" + std::to_string(r.settings.sampleOffset) + ", " +
                    std::to_string(r.settings.sampleOffset + r.spp) + ") overlap another input's [" +
                    std::to_string(lo) + ", " + std::to_string(lo + n) + "): partial renders need distinct --spp-offset ranges");
    ranges.push_back({r.settings.sampleOffset, r.spp});
    merged.spp += r.spp;
    merged.settings.sampleOffset = std::min(merged.settings.sampleOffset, r.settings.sampleOffset);
    merged.interrupted = merged.interrupted || r.interrupted;
    merged.stats.add(r.stats);
    merged.renderSeconds += r.renderSeconds;
    merged.totalSeconds += r.totalSeconds;
  }
  Film::resolve(total, float(merged.spp), true);
  writeExr(output, total, makeMetadata(merged));
  std::fprintf(stderr, "merged %zu renders into %s (%u spp)\n", inputs.size(), output.c_str(), merged.spp);
  return kExitOk;
}

int devicesCommand() {
  auto devices = vk::listDevices();
  if (devices.empty()) {
    std::printf("no Vulkan devices (install mesa-vulkan-drivers for lavapipe, or your GPU's driver)\n");
    return kExitFailure;
  }
  for (const auto& d : devices)
    std::printf("%u: %s (%s, Vulkan %u.%u, driver %s, %.0f MiB device-local, %s)%s%s\n", d.index, d.name.c_str(),
                d.type.c_str(), VK_API_VERSION_MAJOR(d.apiVersion), VK_API_VERSION_MINOR(d.apiVersion),
                d.driverInfo.c_str(), d.deviceLocalBytes / 1048576.0,
                d.rayQuery ? "ray queries" : "no ray queries: BVH traversal", d.suitable ? "" : ": not usable: ",
                d.whyNot.c_str());
  return kExitOk;
}

struct BenchArgs {
  std::vector<std::string> scenes;
  std::uint32_t spp = 16;
  std::uint32_t width = 256, height = 256;
  std::uint32_t maxDepth = 8;
  std::uint32_t samplesPerPass = 0;
  int device = -1;
  std::string rng = rngModeName(RenderSettings{}.rng);
  std::vector<std::string> traversals{"auto"};
  std::uint32_t repeats = 1;
  std::string guiding = "off";
  std::uint32_t guideTrain = 15;
  std::string guideAlpha = "auto";  // what render --guiding on samples (until 2026-12-07: 0.5)
  EnvironmentArgs env;
};

double cpuSecondsUsed() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The figures of one timed render of bench render (medians over repeats).
struct BenchRun {
  double setupSeconds = 0;   // the Renderer: BVH or acceleration structures, quadtrees, pipelines
  double warmupSeconds = 0;  // the untimed first pass (lavapipe compiles each pipeline at its first dispatch)
  double samplesPerSecond = 0;
  double mraysPerSecond = 0;
  double cpuCores = 0;
};

// One render of `scene` with `traversal`: prints its row, its GPU time by stage and shade
// pipeline, and the paths alive per bounce.
BenchRun benchRenderOnce(vk::Context& ctx, const Scene& scene, const std::string& path, const BenchArgs& a,
                         Traversal traversal) {
  RenderSettings s;
  s.width = a.width;
  s.height = a.height;
  s.spp = a.spp;
  s.maxDepth = a.maxDepth;
  s.samplesPerPass = a.samplesPerPass;
  parseRngMode(a.rng, s.rng);
  s.timeStages = true;
  s.traversal = traversal;
  s.guiding = a.guiding == "on";
  s.guideTrainSpp = a.guideTrain;
  s.guideAlpha = parseGuideAlpha(a.guideAlpha, 1.0f);
  BenchRun run;
  const auto tSetup = std::chrono::steady_clock::now();
  Renderer r(ctx, scene, s);
  const auto tWarm = std::chrono::steady_clock::now();
  // Warm-up, untimed: one pass (lavapipe compiles each pipeline at its first dispatch), and for a
  // guided run all of its training, so that the timed passes sample the trained guide (the
  // training's own cost is in render's summary).
  const std::uint32_t warmSpp = s.guiding ? std::max(1u, guideTrainingSpp(s)) : 1u;
  r.render(warmSpp);
  run.setupSeconds = std::chrono::duration<double>(tWarm - tSetup).count();
  run.warmupSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tWarm).count();
  const std::vector<std::pair<std::string, double>> warm = r.stageSeconds();
  const std::vector<std::uint64_t> warmRays = r.raysPerBounce();
  const RenderStats before = r.stats();
  const double cpu0 = cpuSecondsUsed();
  const auto t0 = std::chrono::steady_clock::now();
  r.render(warmSpp + a.spp);
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpuSecondsUsed() - cpu0;
  const RenderStats after = r.stats();
  const double rays = double(after.rays - before.rays + after.shadowRays - before.shadowRays);
  const double samples = double(a.spp) * s.width * s.height;
  run.samplesPerSecond = samples / sec;
  run.mraysPerSecond = rays / sec / 1e6;
  run.cpuCores = cpu / sec;
  char size[32];
  std::snprintf(size, sizeof size, "%ux%u", s.width, s.height);
  std::printf("%-34s %9zu %9s %9s %5u %6u %8.3f %11.0f %8.3f %9.2f %8.3f %9.3f\n",
              path.empty() ? "default (cornell-box)" : std::filesystem::path(path).filename().c_str(),
              r.summary().triangles, size, traversalName(r.settings().traversal), a.spp, r.samplesPerPass(), sec,
              run.samplesPerSecond, run.mraysPerSecond, run.cpuCores, run.setupSeconds, run.warmupSeconds);
  double gpu = 0;
  std::vector<std::pair<std::string, double>> timed;
  for (auto& [name, t] : r.stageSeconds()) {
    double w = 0;
    for (auto& [n0, t0s] : warm)
      if (n0 == name) w = t0s;
    timed.push_back({name, t - w});
    gpu += t - w;
  }
  if (gpu > 0) {
    std::string stages, shades;
    for (auto& [name, t] : timed) {
      char buf[96];
      const bool shade = name.rfind("shade ", 0) == 0;
      std::snprintf(buf, sizeof buf, "%s%s %.1f%%", (shade ? shades : stages).empty() ? "" : ", ",
                    shade ? name.c_str() + 6 : name.c_str(), 100.0 * t / gpu);
      (shade ? shades : stages) += buf;
    }
    std::printf("    GPU time %.3f s by stage: %s\n", gpu, stages.c_str());
    if (!shades.empty()) std::printf("    shade pipelines (model: share of GPU time): %s\n", shades.c_str());
  }
  std::string perBounce;
  const std::vector<std::uint64_t>& bounces = r.raysPerBounce();
  for (std::size_t b = 0; b < bounces.size(); ++b) {
    const std::uint64_t n = bounces[b] - (b < warmRays.size() ? warmRays[b] : 0);
    if (n == 0) continue;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%s%zu:%.3g", perBounce.empty() ? "" : " ", b, double(n) / samples);
    perBounce += buf;
  }
  std::printf("    paths per sample alive at bounce (bounce:fraction): %s\n", perBounce.c_str());
  std::fflush(stdout);
  return run;
}

// "median [min-max]" of the values picked from runs.
template <class F>
std::string medianRange(const std::vector<BenchRun>& runs, F pick, const char* format) {
  std::vector<double> v;
  for (const BenchRun& r : runs) v.push_back(pick(r));
  std::sort(v.begin(), v.end());
  double median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  char buf[96];
  std::string f = std::string(format) + " [" + format + "-" + format + "]";
  std::snprintf(buf, sizeof buf, f.c_str(), median, v.front(), v.back());
  return buf;
}

// Throughput of the path tracer: for each scene (and traversal, interleaved within each repeat),
// samples/s and rays/s over `spp` samples per pixel after a warm-up pass (lavapipe compiles a
// pipeline at its first dispatch), the CPU time the process used per second of wall time (a CPU
// device should keep every core busy), GPU time per stage and per shade pipeline (timestamps; a
// barrier after each shade pipeline in this mode), the extension rays per bounce (the queue
// sizes the wavefront works through), and the set-up (BVH or acceleration structures, quadtrees,
// pipelines) and warm-up times. With repeats, the medians and ranges per traversal.
int benchRenderCommand(const BenchArgs& a) {
  std::vector<std::string> scenes = a.scenes;
  if (scenes.empty()) {
    scenes.push_back("");
    std::string dragon = std::string(NUSSELT_SCENES_DIR) + "/dragon/dragon.gltf";
    if (std::filesystem::exists(dragon)) scenes.push_back(dragon);
    else std::fprintf(stderr, "note: %s not found; benchmarking the default scene only\n", dragon.c_str());
  }
  std::vector<Traversal> traversals;
  for (const std::string& t : a.traversals) {
    Traversal v = Traversal::Auto;
    parseTraversal(t, v);
    traversals.push_back(v);
  }
  vk::Context ctx;
  vk::ContextOptions co;
  co.deviceIndex = a.device;
  co.reusePipelines = false;  // every repeat's set-up as a render process's
  vk::createContext(ctx, co);
  std::printf("device: %s (%s), %u CPU threads, %s\n", ctx.deviceName.c_str(), ctx.driverInfo.c_str(),
              std::thread::hardware_concurrency(), ctx.rayQuery ? "ray queries" : "no ray queries");
  std::printf("%-34s %9s %9s %9s %5s %6s %8s %11s %8s %9s %8s %9s\n", "scene", "triangles", "size", "traversal", "spp",
              "spp/pass", "seconds", "samples/s", "Mrays/s", "CPU cores", "setup s", "warm-up s");
  for (const std::string& path : scenes) {
    Scene scene = loadSceneOrDefault(path, "");
    applyEnvironmentOptions(scene, a.env, false);
    std::vector<std::vector<BenchRun>> runs(traversals.size());
    for (std::uint32_t rep = 0; rep < a.repeats; ++rep)
      for (std::size_t k = 0; k < traversals.size(); ++k)
        runs[k].push_back(benchRenderOnce(ctx, scene, path, a, traversals[k]));
    if (a.repeats > 1)
      for (std::size_t k = 0; k < traversals.size(); ++k) {
        const std::vector<BenchRun>& rs = runs[k];
        std::printf("  %s, %s, median [min-max] of %u: %s samples/s, %s Mrays/s, %s CPU cores, setup %s s, warm-up %s s\n",
                    path.empty() ? "default (cornell-box)" : std::filesystem::path(path).filename().c_str(),
                    traversalName(resolveTraversal(ctx, traversals[k])), a.repeats,
                    medianRange(rs, [](auto& r) { return r.samplesPerSecond; }, "%.0f").c_str(),
                    medianRange(rs, [](auto& r) { return r.mraysPerSecond; }, "%.3f").c_str(),
                    medianRange(rs, [](auto& r) { return r.cpuCores; }, "%.2f").c_str(),
                    medianRange(rs, [](auto& r) { return r.setupSeconds; }, "%.3f").c_str(),
                    medianRange(rs, [](auto& r) { return r.warmupSeconds; }, "%.3f").c_str());
      }
  }
  vk::destroyContext(ctx);
  return kExitOk;
}

int infoCommand(const std::vector<std::string>& files) {
  for (const std::string& f : files) {
    ImageMetadata meta;
    Image img = readExr(f, &meta);
    double sum[3] = {0, 0, 0};
    for (std::size_t i = 0; i < img.rgb.size(); ++i) sum[i % 3] += img.rgb[i];
    double n = double(img.width) * img.height;
    std::printf("%s: %dx%d, mean RGB %.6g %.6g %.6g%s\n", f.c_str(), img.width, img.height, sum[0] / n, sum[1] / n,
                sum[2] / n, img.variance.empty() ? "" : ", with variance channels");
    for (auto& [k, v] : meta.strings) std::printf("  %s: %s\n", k.c_str(), v.c_str());
    for (auto& [k, v] : meta.ints) std::printf("  %s: %lld\n", k.c_str(), static_cast<long long>(v));
    for (auto& [k, v] : meta.doubles) std::printf("  %s: %.6g\n", k.c_str(), v);
  }
  return kExitOk;
}

int diffCommand(const std::string& a, const std::string& b, const std::string& regionText, const std::string& mapPath) {
  std::vector<double> region;
  if (!regionText.empty()) {
    std::size_t at = 0;
    while (at <= regionText.size()) {
      std::size_t comma = std::min(regionText.find(',', at), regionText.size());
      const std::string part = regionText.substr(at, comma - at);
      std::size_t used = 0;
      double v = 0;
      try {
        v = std::stod(part, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (part.empty() || used != part.size())
        throw Error("--region '" + regionText + "': '" + part + "' is not a number (expected x0,y0,x1,y1)");
      region.push_back(v);
      at = comma + 1;
    }
    if (region.size() != 4)
      throw Error("--region '" + regionText + "': expected four fractions x0,y0,x1,y1, got " + std::to_string(region.size()));
  }
  Image ia = readExr(a), ib = readExr(b);
  if (!region.empty()) {
    if (ia.width != ib.width || ia.height != ib.height) compareImages(ia, ib);  // its size error, before cropping
    ia = cropImage(ia, region[0], region[1], region[2], region[3], "--region");
    ib = cropImage(ib, region[0], region[1], region[2], region[3], "--region");
  }
  ImageDifference d = compareImages(ia, ib);
  std::printf("relMSE %.6g  MSE %.6g  mean %.6g (%s) vs %.6g (%s)  max |diff| %.6g\n", d.relMse, d.mse, d.meanA,
              a.c_str(), d.meanB, b.c_str(), d.maxAbs);
  // A second line only where the reference has variance channels (scripts read the first).
  if (d.referenceRelMse >= 0)
    std::printf("relMSE less the reference's own %.6g (its var channels; for an image independent of it): %.6g\n",
                d.referenceRelMse, d.relMse - d.referenceRelMse);
  if (!mapPath.empty()) writePng(mapPath, errorMap(ia, ib));
  return kExitOk;
}

// Pipeline creation and first-dispatch compile time for a one-model scene and a scene with
// every model: a render compiles only the shade stages its scene uses.
int benchPipelinesCommand(int device) {
  // Mesa's on-disk shader cache would hide the compile cost after the first run.
  const bool cacheWasSet = std::getenv("MESA_SHADER_CACHE_DISABLE") != nullptr;
  if (!cacheWasSet) setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  vk::Context ctx;
  vk::ContextOptions co;
  co.deviceIndex = device;
  co.reusePipelines = false;  // each scene's pipelines created, as a render process would
  vk::createContext(ctx, co);
  std::printf("device: %s; Mesa shader cache %s\n", ctx.deviceName.c_str(),
              cacheWasSet ? "as set by MESA_SHADER_CACHE_DISABLE" : "disabled for this measurement");
  std::printf("%-34s %7s %14s %16s %12s\n", "scene", "models", "pipelines (s)", "first pass (s)", "next pass (s)");
  std::string materials = std::string(NUSSELT_SCENES_DIR) + "/materials/materials.gltf";
  std::string combined = std::string(NUSSELT_SCENES_DIR) + "/tests/combined.gltf";
  for (const std::string& path : {std::string(), materials, combined}) {
    if (!path.empty() && !std::filesystem::exists(path)) {
      std::printf("%s not found\n", path.c_str());
      continue;
    }
    Scene scene = loadSceneOrDefault(path, "");
    RenderSettings s;
    s.width = s.height = 32;
    s.maxDepth = 2;
    s.samplesPerPass = 1;  // the second pass times one sample per pixel
    auto t0 = std::chrono::steady_clock::now();
    Renderer r(ctx, scene, s);
    double create = r.summary().pipelineSeconds;
    auto t1 = std::chrono::steady_clock::now();
    r.renderPass();
    auto t2 = std::chrono::steady_clock::now();
    r.renderPass();
    auto t3 = std::chrono::steady_clock::now();
    (void)t0;
    std::printf("%-34s %7zu %14.3f %16.3f %12.3f\n",
                path.empty() ? "default (cornell-box)" : path == materials ? "materials (one sphere per model)"
                                                                           : "combined (combined materials)",
                r.summary().models.size(), create, std::chrono::duration<double>(t2 - t1).count(),
                std::chrono::duration<double>(t3 - t2).count());
  }
  vk::destroyContext(ctx);
  return kExitOk;
}

struct AlbedoArgs {
  std::string model;
  std::string file;  // measured models
  std::vector<std::string> params;
  std::string set;
  double theta = 0;
  double phi = 0;
};

// The directional albedo: cosine-weighted integral of the BRDF over the hemisphere for the
// incident direction at polar angle theta (azimuth phi), by adaptive quadrature.
int albedoCommand(const AlbedoArgs& a) {
  const ModelSpec* spec = findModel(a.model);
  if (!spec) throw Error("--model " + a.model + ": unknown model (known: " + knownModelNames() + ")");
  if (!(a.theta >= 0 && a.theta <= 90)) throw Error("--theta must be in [0, 90] degrees");
  NamedParams values;
  if (a.set == "typical") values = typicalParams(*spec);
  else if (a.set == "hard") values = hardParams(*spec);
  for (const std::string& p : a.params) {
    auto kv = parseParamArgument(p);
    values.erase(std::remove_if(values.begin(), values.end(), [&](auto& e) { return e.first == kv.first; }), values.end());
    values.push_back(kv);
  }
  BrdfParams params = spec->measured ? measuredParams(*spec, a.file, a.params)
                                     : packParams(*spec, values, "--model " + spec->name);
  if (!spec->measured && !a.file.empty()) throw Error("--file: only measured models (merl) read a file");
  double rgb[3];
  directionalAlbedoRgb(spec->id, params, a.theta, a.phi, rgb);
  double lum = directionalAlbedo(spec->id, params, a.theta, a.phi);
  std::printf("%.9g\n", lum);
  std::fprintf(stderr, "%s at theta %g deg, phi %g deg: albedo (luminance) %.9g, RGB %.9g %.9g %.9g%s\n",
               spec->name.c_str(), a.theta, a.phi, lum, rgb[0], rgb[1], rgb[2], spec->delta ? " (delta model: 0)" : "");
  return kExitOk;
}

}  // namespace

int runCli(int argc, char** argv) {
  // A file-size limit (ulimit -f) makes write() fail with EFBIG, reported like a full disk,
  // instead of killing the process with SIGXFSZ before it can say anything.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"nusselt: a physically based renderer with generic BRDF sampling on Vulkan compute"};
  app.set_version_flag("--version", NUSSELT_VERSION);
  app.require_subcommand(1);
  // A repeated option takes its last value (scripts can append overrides).
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);

  RenderArgs ra;
  CLI::App* render = app.add_subcommand("render", "Render a glTF scene (default: the built-in Cornell box) to OpenEXR");
  render->add_option("scene", ra.scene, "glTF 2.0 scene (.gltf or .glb); omitted: the built-in Cornell box");
  render->add_option("-o,--output", ra.output, "Output OpenEXR file (32-bit float RGB; default render.exr, or the --resume file)");
  CLI::Option* sppOption =
      render->add_option("--spp", ra.spp, "Samples per pixel (with --time: at most this many)")->capture_default_str()
          ->check(CLI::Range(0u, 1u << 30));
  render->add_option("--time", ra.timeBudget, "Time budget in seconds: stop at the first pass boundary after it and "
                                              "write the image with its true spp (--spp, if given, still caps it)")
      ->check(CLI::Range(0.0, 1e9));
  render->add_option("--width", ra.width, "Image width in pixels (default 512, or from --height and the camera's aspect ratio)")
      ->check(CLI::Range(1u, 65536u));
  render->add_option("--height", ra.height, "Image height in pixels (default from the width and the camera's aspect ratio)")
      ->check(CLI::Range(1u, 65536u));
  render->add_option("--seed", ra.seed, "Random seed; same scene, settings and seed give a bit-identical image")
      ->capture_default_str();
  render->add_option("--max-depth", ra.maxDepth, "Maximum path depth (0: emitted light only, 1: direct lighting)")
      ->capture_default_str()->check(CLI::Range(0u, 1024u));
  render->add_option("--samples-per-pass", ra.samplesPerPass,
                     "Samples per pixel traced together in one pass (0: enough for about 2^18 paths in flight on a "
                     "CPU device, 2^21 on a GPU, at most 64); the image does not depend on it")
      ->capture_default_str()->check(CLI::Range(0u, 4096u));
  render->add_option("--png", ra.png, "Also write a tone-mapped sRGB PNG");
  render->add_option("--exposure", ra.exposure, "Exposure of the PNG, in stops")->capture_default_str();
  render->add_option("--camera", ra.camera, "Use the glTF camera with this name (default: the first camera)");
  render->add_option("--device", ra.device, "Vulkan device index (see `nusselt devices`; default: a discrete GPU if any)");
  render->add_option("--lighting", ra.lighting, "Light transport estimator: mis (NEE + BSDF sampling, power heuristic), "
                                                "nee (light sampling only), bsdf (BSDF sampling only)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kLightingNames)));
  render->add_option("--resume", ra.resume, "Continue the render saved in this EXR up to --spp samples in all "
                                            "(same scene and settings; written back to it unless -o is given)");
  render->add_option("--spp-offset", ra.sppOffset, "First sample index of this render: split a frame across machines "
                                                   "into disjoint ranges and combine them with `nusselt merge`")
      ->capture_default_str();
  render->add_option("--sampler", ra.sampler, "BSDF sampling of non-delta models: quadtree (the generic sampler: "
                                              "density proportional to BRDF x cos for any model), cosine, uniform, analytic (the model's "
                                              "own importance sampling, cosine where it has none), tabulated")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kSamplerNames)));
  render->add_option("--roughness-bins", ra.roughnessBins, "quadtree: roughness bins of the binned sampler of gltf_pbr "
                                                          "materials whose textures vary their parameters (0: cosine "
                                                          "sampling for those; docs/scenes.md)")
      ->capture_default_str()->check(CLI::Range(0u, 64u) & !CLI::IsMember({1u}));
  render->add_option("--roughness-bin-spacing", ra.roughnessBinSpacing, "quadtree: bin j of K at roughness (j / (K - 1))^spacing")
      ->capture_default_str()->check(CLI::Range(0.25f, 4.0f));
  render->add_option("--components", ra.components, "Component choice of combined materials: albedo (probability = "
                                                    "the component's albedo for the current direction, the rest ends "
                                                    "the walk: the random-walk source's estimator) or uniform "
                                                    "(probability 1/n and a separate albedo roulette)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kComponentNames)));
  render->add_option("--roulette", ra.roulette, "Russian roulette: throughput (continue with the path throughput's "
                                                "largest channel from the third bounce on; never amplifies a colour "
                                                "channel) or albedo (the random-walk source's: continue with the "
                                                "sample's luminance albedo; its survivors' saturated channels grow, "
                                                "docs/performance.md)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kRouletteNames)));
  render->add_option("--traversal", ra.traversal, "Ray traversal: rayquery (the device's ray queries against "
                                                  "acceleration structures), bvh (the GLSL BVH, every device), auto "
                                                  "(rayquery on a GPU that offers it, else bvh: on CPU devices such as "
                                                  "lavapipe the BVH is faster, docs/performance.md)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kTraversalNames)));
  render->add_option("--rng", ra.rng, "Random numbers: qmc (padded Owen-scrambled Sobol points, one (0,2)-sequence per decision of the walk) or "
                                          "pcg (independent hashes)")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kRngNames)));
  render->add_option("--checkpoint", ra.checkpointSeconds, "Write the image so far to the output every this many seconds "
                                                          "(resumable with --resume; 0: never)")
      ->capture_default_str()->check(CLI::Range(0.0, 1e9));
  render->add_option("--integrator", ra.integrator, "Integrator: path (the wavefront path tracer), mlt (primary-"
                                                   "sample-space Metropolis over it; docs/mlt.md) or vegas (the path "
                                                   "tracer with a learned separable warp of its first draws; "
                                                   "docs/vegas.md)")
      ->capture_default_str();
  render->add_option("--mlt-chains", ra.mltChains, "mlt: Markov chains in flight (each a path per mutation)")
      ->capture_default_str()->check(CLI::Range(64u, 4194240u));
  render->add_option("--mlt-bootstrap", ra.mltBootstrap, "mlt: independent bootstrap paths for the normalisation and "
                                                         "the chains' starts (0: 16 x chains, at least 2^21)")
      ->capture_default_str();
  render->add_option("--mlt-large-step", ra.mltLargeStep, "mlt: probability of a large step (an independent path)")
      ->capture_default_str()->check(CLI::Range(0.0f, 1.0f));
  render->add_option("--mlt-sigma", ra.mltSigma, "mlt: standard deviation of a small step per primary coordinate")
      ->capture_default_str()->check(CLI::Range(1e-6f, 1.0f));
  render->add_option("--mlt-weights", ra.mltWeights, "mlt: splat weights: kelemen (large steps also count as "
                                                     "independent path samples, combined with the chain) or plain "
                                                     "(expected-value splats only; docs/mlt.md)")
      ->capture_default_str()->check(CLI::IsMember({"kelemen", "plain"}));
  render->add_option("--mlt-chain-light", ra.mltChainLight,
                     "mlt: the light the chains carry: caustic (light that reached a diffuse or glossy surface "
                     "through mirrors or glass from the light, which next-event estimation cannot sample) or "
                     "indirect (two or more scatterings); a per-pixel path-traced pass adds the rest (docs/mlt.md)")
      ->capture_default_str()->check(CLI::IsMember({"caustic", "indirect"}));
  render->add_option("--mlt-steps", ra.mltSteps, "mlt: steps of every chain per iteration (one sample per pixel of "
                                                 "the render's count, with --mlt-pass-spp path-traced samples)")
      ->capture_default_str()->check(CLI::Range(1u, 1024u));
  render->add_option("--mlt-pass-spp,--mlt-direct-spp", ra.mltPassSpp,
                     "mlt: path-traced samples per pixel per iteration of the light the chains do not carry "
                     "(--mlt-chain-light); 0: the chains carry all light (docs/mlt.md)")
      ->capture_default_str()->check(CLI::Range(0u, 64u));
  render->add_option("--mlt-restart", ra.mltRestart,
                     "mlt: start the caustic chains again from the path-traced pass's paths whenever it has traced "
                     "this many samples per pixel since their last start; auto: as many as make a bootstrap pool "
                     "(--mlt-bootstrap) of paths; off: never (docs/mlt.md, \"Restarts\")")
      ->capture_default_str();
  render->add_option("--vegas-bins", ra.vegasBins, "vegas: bins of each warped axis's density (1 .. 4096)")
      ->capture_default_str();
  render->add_option("--vegas-bounces", ra.vegasBounces, "vegas: bounces whose light choice, light point and BSDF "
                                                         "draws are warped (1 .. max depth + 1)")
      ->capture_default_str();
  render->add_option("--vegas-alpha", ra.vegasAlpha, "vegas: share of the uniform density in each learned one "
                                                     "(0.01 .. 1; keeps every bin's density >= alpha)")
      ->capture_default_str();
  render->add_option("--vegas-learn", ra.vegasLearn, "vegas: tables learned, one after each pass; then the table is "
                                                     "frozen and the rest of the render samples it with the render's "
                                                     "own (QMC) numbers (docs/vegas.md)")
      ->capture_default_str()->check(CLI::Range(1u, 1000000u));
  render->add_option("--guiding", ra.guiding, "Path guiding (docs/guiding.md): on = sample directions from a guide "
                                              "learned from the render's first samples (one-sample MIS with the BSDF "
                                              "sampler), off = BSDF sampling only")
      ->capture_default_str()->check(CLI::IsMember({"off", "on"}));
  render->add_option("--guide-train", ra.guideTrain, "Training samples per pixel of the guide, in iterations of 1, 2, 4, "
                                                     "... spp (0: the largest 2^k - 1 up to half of --spp, at most 127; "
                                                     "with --time, ended earlier when the next iteration would leave less "
                                                     "than twice its own time to sample its guide)")
      ->capture_default_str()->check(CLI::Range(0u, 1u << 30));
  render->add_option("--guide-memory", ra.guideMemoryMiB, "Memory cap of the guide's trees on the device, MiB")
      ->capture_default_str()->check(CLI::Range(0.01, 4096.0));
  render->add_option("--guide-spatial", ra.guideSpatial, "The guide's spatial split rule: a region splits after c "
                                                         "sqrt(2^k) training splats in iteration k (Mueller et al.: "
                                                         "12000, for 1280 x 720 images)")
      ->capture_default_str()->check(CLI::Range(1.0, 1e12));
  render->add_option("--guide-alpha", ra.guideAlpha, "Probability of sampling the guide (one-sample MIS with the BSDF "
                                                     "sampler): auto = learned per region during training (0, no "
                                                     "guide, where it does not lower the variance), or a number in "
                                                     "[0, 0.99] for every region that learned something")
      ->capture_default_str();
  render->add_option("--guide-filter", ra.guideFilter, "The guide's directional splat filter: box = each training "
                                                       "splat shared among the cells a box of its cell's size "
                                                       "overlaps, none = the one cell it lands in (docs/guiding.md)")
      ->capture_default_str()->check(CLI::IsMember({"box", "none"}));
  render->add_option("--guide-spatial-filter", ra.guideSpatialFilter, "The guide's spatial splat filter: box = each "
                                                                      "training splat shared among the regions a box "
                                                                      "of its region's size overlaps, none = its own "
                                                                      "region")
      ->capture_default_str()->check(CLI::IsMember({"box", "none"}));
  render->add_option("--guide-floor", ra.guideFloor, "Weight of the uniform sphere density mixed into the learned "
                                                     "guide (0: none)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.5));
  render->add_option("--guide-learn", ra.guideLearn, "What the guide learns: product = the incident radiance times the "
                                                     "BSDF and cosine of the vertices that trained it, radiance = the "
                                                     "incident radiance alone (docs/guiding.md)")
      ->capture_default_str()->check(CLI::IsMember({"product", "radiance"}));
  render->add_option("--guide-photons", ra.guidePhotons, "Photons of the guide's pre-pass: traced from the lights before "
                                                         "training, their indirect arrivals train the guide of the first "
                                                         "iteration (0: none; docs/guiding.md)")
      ->capture_default_str()->check(CLI::Range(0u, 1u << 30));
  render->add_flag("--variance", ra.variance, "Also write the per-pixel variance of the mean (channels var.R, var.G, var.B)");
  render->add_flag("--validation", ra.validation, "Enable the Vulkan validation layer (also NUSSELT_VALIDATION=1); any message fails the render");
  render->add_flag("-q,--quiet", ra.quiet, "No progress or summary output");
  addEnvironmentOptions(*render, ra.env);

  CLI::App* devices = app.add_subcommand("devices", "List the Vulkan devices and whether nusselt can use them");

  BenchArgs ba;
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print figures");
  bench->require_subcommand(1);
  CLI::App* benchRender = bench->add_subcommand("render", "Samples/s and rays/s for the default scene and the dragon");
  benchRender->add_option("scenes", ba.scenes, "Scenes to measure (default: the Cornell box and scenes/dragon)");
  benchRender->add_option("--spp", ba.spp, "Timed samples per pixel (after an untimed warm-up: one pass, or a guided run's training)")->capture_default_str()
      ->check(CLI::Range(1u, 1u << 20));
  benchRender->add_option("--width", ba.width, "Image width")->capture_default_str()->check(CLI::Range(1u, 65536u));
  benchRender->add_option("--height", ba.height, "Image height")->capture_default_str()->check(CLI::Range(1u, 65536u));
  benchRender->add_option("--max-depth", ba.maxDepth, "Maximum path depth")->capture_default_str()
      ->check(CLI::Range(0u, 1024u));
  benchRender->add_option("--samples-per-pass", ba.samplesPerPass,
                          "Samples per pixel per pass (0: chosen for the device, as render does)")
      ->capture_default_str()->check(CLI::Range(0u, 4096u));
  benchRender->add_option("--device", ba.device, "Vulkan device index");
  benchRender->add_option("--rng", ba.rng, "Random numbers, as render --rng: qmc or pcg")
      ->capture_default_str()->check(CLI::IsMember(enumNames(kRngNames)));
  benchRender->add_option("--traversal", ba.traversals, "Traversals to measure, interleaved within each repeat "
                                                         "(auto, rayquery, bvh; comma-separated or repeated)")
      ->capture_default_str()->delimiter(',')->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::IsMember(enumNames(kTraversalNames)));
  benchRender->add_option("--guiding", ba.guiding, "Path guiding: on or off (docs/guiding.md)")
      ->capture_default_str()->check(CLI::IsMember({"off", "on"}));
  benchRender->add_option("--guide-train", ba.guideTrain, "Guided: training spp, rendered in the untimed warm-up: the "
                                                          "timed passes sample the trained guide (the training's cost: "
                                                          "render's summary)")
      ->capture_default_str()->check(CLI::Range(1u, 1u << 30));
  benchRender->add_option("--guide-alpha", ba.guideAlpha, "Guided: probability of sampling the guide in [0, 1] (0: the "
                                                          "guided pipelines run but never take the guide's branch), "
                                                          "or auto (learned per region)")
      ->capture_default_str();
  benchRender->add_option("--repeats", ba.repeats, "Repeats of every scene and traversal; with more than one, the "
                                                   "medians and ranges are printed")
      ->capture_default_str()->check(CLI::Range(1u, 1000u));
  addEnvironmentOptions(*benchRender, ba.env);

  AlbedoArgs aa;
  CLI::App* albedo = app.add_subcommand("albedo", "Directional albedo of a reflectance model (cosine-weighted integral of its "
                                                  "luminance over the hemisphere), to at least 6 significant digits");
  albedo->add_option("--model", aa.model, "Model name (docs/models.md)")->required();
  albedo->add_option("--param", aa.params, "name=value, name=r,g,b or name=[JSON] as in NUSSELT_brdf (lafortune: lobes=[[Cx,Cy,Cz,n],...]); repeatable; others take their defaults");
  albedo->add_option("--file", aa.file, "Measured models (merl): the MERL binary file (docs/measured.md)");
  albedo->add_option("--set", aa.set, "Start from the catalogue's typical or hard parameter set")
      ->check(CLI::IsMember({"typical", "hard"}));
  albedo->add_option("--theta", aa.theta, "Polar angle of the incident direction, degrees")->required();
  albedo->add_option("--phi", aa.phi, "Azimuth of the incident direction, degrees (anisotropic models)")->capture_default_str();
  albedo->get_option("--param")->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);

  int pipelinesDevice = -1;
  CLI::App* benchPipelines = bench->add_subcommand("pipelines", "Pipeline creation and first-dispatch compile time: a one-model "
                                                                "scene, the scene with every model, and combined materials");
  benchPipelines->add_option("--device", pipelinesDevice, "Vulkan device index");

  std::vector<std::string> mergeInputs;
  std::string mergeOutput;
  CLI::App* merge = app.add_subcommand("merge", "Combine partial renders of disjoint sample ranges (--spp-offset) into one");
  merge->add_option("inputs", mergeInputs, "Partial renders (EXR written by nusselt render)")->required();
  merge->add_option("-o,--output", mergeOutput, "Merged image")->required();

  std::vector<std::string> infoFiles;
  CLI::App* info = app.add_subcommand("info", "Print the size, mean and header attributes of OpenEXR images");
  info->add_option("files", infoFiles, "EXR files")->required();
  std::string diffA, diffB;
  CLI::App* diff = app.add_subcommand("diff", "Compare two EXR images: relMSE (reference = second), MSE, means, max difference; with a reference that has var channels (render --variance), also the relMSE less the reference's own noise");
  diff->add_option("image", diffA, "Image")->required();
  diff->add_option("reference", diffB, "Reference image")->required();
  std::string diffRegion;
  diff->add_option("--region", diffRegion,
                   "Compare only the region x0,y0,x1,y1, fractions of the width and height from the top left "
                   "(e.g. 0.25,0.5,0.75,1 for the middle of the lower half)");
  std::string diffMap;
  diff->add_option("--map", diffMap,
                   "Also write a PNG of where the error is: each pixel grey at its relative RMS error (the root of "
                   "its relMSE), white at 100 % or more (of the region, with --region)");

  CommandRunner run;
  registerSamplerCommands(app, *bench, run);
  registerPreviewCommand(app, run);
  registerModelsCommand(app, run);
  registerGuideViewCommand(app, run);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  try {
    if (run) return run();
    if (*render) {
      ra.sppGiven = sppOption->count() > 0;
      return renderCommand(ra);
    }
    if (*devices) return devicesCommand();
    if (*benchRender) return benchRenderCommand(ba);
    if (*benchPipelines) return benchPipelinesCommand(pipelinesDevice);
    if (*info) return infoCommand(infoFiles);
    if (*merge) return mergeCommand(mergeInputs, mergeOutput);
    if (*albedo) return albedoCommand(aa);
    if (*diff) return diffCommand(diffA, diffB, diffRegion, diffMap);
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitFailure;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of host memory\n");
    return kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace nusselt
