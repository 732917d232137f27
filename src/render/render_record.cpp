// render_record.cpp: the EXR header of a render, written and read.
#include "render/render_record.h"

#include <cstdio>
#include <sstream>

#include "render/environment.h"
#include "util/error.h"
#include "util/format.h"

namespace nusselt {

namespace {

// "perspective px py pz fx fy fz ux uy uz yfov" or "orthographic ... xmag ymag": %.9g round-trips
// every float exactly, so a resumed render traces the very same rays.
std::string cameraText(const Camera& c) {
  char buf[512];
  if (c.orthographic)
    std::snprintf(buf, sizeof buf, "orthographic %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", c.position.x,
                  c.position.y, c.position.z, c.forward.x, c.forward.y, c.forward.z, c.up.x, c.up.y, c.up.z, c.xmag, c.ymag);
  else
    std::snprintf(buf, sizeof buf, "perspective %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", c.position.x,
                  c.position.y, c.position.z, c.forward.x, c.forward.y, c.forward.z, c.up.x, c.up.y, c.up.z, c.yfov);
  return buf;
}

bool parseCamera(const std::string& text, Camera& c) {
  std::istringstream in(text);
  std::string kind;
  in >> kind;
  c.orthographic = kind == "orthographic";
  if (!c.orthographic && kind != "perspective") return false;
  in >> c.position.x >> c.position.y >> c.position.z >> c.forward.x >> c.forward.y >> c.forward.z >> c.up.x >> c.up.y >>
      c.up.z;
  if (c.orthographic) in >> c.xmag >> c.ymag;
  else in >> c.yfov;
  return bool(in);
}

}  // namespace


// What a Metropolis render's chains carry and how many path-traced samples add the rest ("" for
// other integrators).
std::string mltSplitText(const RenderSettings& s) {
  if (s.integrator != IntegratorKind::Mlt) return "";
  if (!s.mltPassSpp) return "all light in the chains, " + std::to_string(s.mltSteps) + " step(s) of every chain per iteration";
  return mltChainLightName(s.mltChainLight) + " light in the chains, " + std::to_string(s.mltPassSpp) +
         " path-traced sample(s) per pixel per " + std::to_string(s.mltSteps) + " step(s) of every chain";
}

std::string describeEnvironment(const Scene& scene) {
  const Environment e = effectiveEnvironment(scene);
  if (e.kind == EnvironmentKind::Map) return "map " + e.path;
  if (e.kind == EnvironmentKind::Uniform) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "uniform %.9g,%.9g,%.9g", e.color.x, e.color.y, e.color.z);
    return buf;
  }
  return "none";
}

void recordEnvironment(RenderRecord& r, const Scene& scene) {
  const Environment e = effectiveEnvironment(scene);
  r.environment = describeEnvironment(scene);
  r.envScale = e.scale;
  r.envRotate = e.rotateDegrees;
  r.envSelect = e.selectByPower ? "power" : "half";
}

ImageMetadata makeMetadata(const RenderRecord& r) {
  ImageMetadata meta;
  meta.strings = {{"nusselt/version", NUSSELT_VERSION},
                  {"nusselt/scene", r.scene},
                  {"nusselt/device", r.device},
                  {"nusselt/driver", r.driver},
                  {"nusselt/source", r.source},
                  {"nusselt/integrator", std::string("wavefront path tracer: NEE + BSDF sampling, MIS power "
                                         "heuristic, ") + rouletteModeName(r.settings.roulette) + " Russian roulette"},
                  {"nusselt/roulette", rouletteModeName(r.settings.roulette)},
                  {"nusselt/lighting", lightingModeName(r.settings.lighting)},
                  {"nusselt/rng", rngModeName(r.settings.rng)},
                  {"nusselt/sampler", samplerName(r.settings.sampler)},
                  {"nusselt/components", componentSelectionName(r.settings.components)},
                  {"nusselt/traversal", traversalName(r.settings.traversal)},
                  {"nusselt/models", r.models},
                  {"nusselt/camera", cameraText(r.camera)},
                  {"nusselt/environment", r.environment},
                  {"nusselt/envSelect", r.envSelect}};
  meta.ints = {{"nusselt/spp", r.spp},
               {"nusselt/sppOffset", r.settings.sampleOffset},
               {"nusselt/seed", r.settings.seed},
               {"nusselt/maxDepth", r.settings.maxDepth},
               {"nusselt/interrupted", r.interrupted ? 1 : 0},
               {"nusselt/checkpoint", r.checkpoint ? 1 : 0},
               {"nusselt/droppedTriangles", static_cast<std::int64_t>(r.droppedTriangles)}};
  r.stats.forEach([&](const char* name, const char*, std::uint64_t value) {
    meta.ints.push_back({std::string("nusselt/") + name, static_cast<std::int64_t>(value)});
  });
  meta.doubles = {{"nusselt/renderSeconds", r.renderSeconds},
                  {"nusselt/totalSeconds", r.totalSeconds},
                  {"nusselt/envScale", r.envScale},
                  {"nusselt/envRotate", r.envRotate}};
  if (r.timeBudget > 0) meta.doubles.push_back({"nusselt/timeBudget", r.timeBudget});
  // Binned sampling (written only when the scene used bins: other headers are as before).
  if (r.roughnessBins > 0) {
    meta.ints.push_back({"nusselt/roughnessBins", r.roughnessBins});
    meta.doubles.push_back({"nusselt/roughnessBinSpacing", r.settings.roughnessBinSpacing});
  }
  // Path guiding (written only when on: unguided headers are as before).
  if (r.settings.guiding) {
    meta.strings.push_back({"nusselt/guiding", "on"});
    meta.ints.push_back({"nusselt/guideTrainSpp", guideTrainingSpp(r.settings)});
    meta.ints.push_back({"nusselt/guideTrainPass", r.settings.guideTrainPass});
    // The selection probability: "auto" (learned per region) as a string, a fixed one as before.
    if (r.settings.guideAlpha < 0)
      meta.strings.push_back({"nusselt/guideAlpha", "auto"});
    else
      meta.doubles.push_back({"nusselt/guideAlpha", r.settings.guideAlpha});
    meta.strings.push_back({"nusselt/guideFilter", r.settings.guideDirFilter ? "box" : "none"});
    meta.strings.push_back({"nusselt/guideSpatialFilter", r.settings.guideSpatialFilter ? "box" : "none"});
    meta.doubles.push_back({"nusselt/guideFloor", r.settings.guideFloor});
    meta.strings.push_back({"nusselt/guideLearn", r.settings.guideProduct ? "product" : "radiance"});
    meta.ints.push_back({"nusselt/guidePhotons", static_cast<std::int64_t>(r.settings.guidePhotons)});
    meta.doubles.push_back({"nusselt/guideSpatial", r.settings.guideSpatialThreshold});
    meta.doubles.push_back({"nusselt/guideMemory", double(r.settings.guideMemory)});
    if (!r.guideHash.empty()) meta.strings.push_back({"nusselt/guideHash", r.guideHash});
  }
  // The integrator's name (written only when it is not the path tracer: path headers are as
  // before); "nusselt/integrator" describes it.
  if (r.settings.integrator != IntegratorKind::Path) {
    meta.strings.push_back({"nusselt/integratorName", integratorName(r.settings.integrator)});
    if (r.settings.integrator == IntegratorKind::Mlt) {
      meta.ints.push_back({"nusselt/mltChains", r.settings.mltChains});
      meta.ints.push_back({"nusselt/mltBootstrap", mltBootstrapPaths(r.settings)});
      meta.doubles.push_back({"nusselt/mltLargeStep", r.settings.mltLargeStep});
      meta.doubles.push_back({"nusselt/mltSigma", r.settings.mltSigma});
      meta.ints.push_back({"nusselt/mltKelemen", r.settings.mltKelemen ? 1 : 0});
      meta.ints.push_back({"nusselt/mltPassSpp", r.settings.mltPassSpp});
      meta.ints.push_back({"nusselt/mltSteps", r.settings.mltSteps});
      meta.ints.push_back({"nusselt/mltRestart", mltRestartSpp(r.settings, std::uint64_t(r.settings.width) * r.settings.height)});
      if (r.settings.mltPassSpp) meta.strings.push_back({"nusselt/mltChainLight", mltChainLightName(r.settings.mltChainLight)});
    }
    if (r.settings.integrator == IntegratorKind::Vegas) {
      meta.ints.push_back({"nusselt/vegasBins", r.settings.vegasBins});
      meta.ints.push_back({"nusselt/vegasBounces", r.settings.vegasBounces});
      meta.doubles.push_back({"nusselt/vegasAlpha", r.settings.vegasAlpha});
      meta.ints.push_back({"nusselt/vegasLearn", r.settings.vegasLearn});
    }
    const bool mlt = r.settings.integrator == IntegratorKind::Mlt;
    for (auto& [name, value] : meta.strings)
      if (name == "nusselt/integrator")
        value = (mlt ? "primary-sample-space Metropolis (PSSMLT) over the wavefront path tracer ("
                     : "VEGAS (separable warp of the first bounces' primary draws, learned per pass) over the "
                       "wavefront path tracer (") +
                value + ")" + (mlt ? "; " + mltSplitText(r.settings) : "");
  }
  if (r.source == "preview") meta.doubles.push_back({"nusselt/exposure", r.displayExposure});
  return meta;
}

RenderRecord readRecord(const std::string& path, const ImageMetadata& meta) {
  auto str = [&](const char* name) {
    auto v = findString(meta, name);
    if (!v) throw Error(path + ": header attribute " + name + " is missing (not written by nusselt?)");
    return *v;
  };
  auto num = [&](const char* name) {
    auto v = findInt(meta, name);
    if (!v || *v < 0) throw Error(path + ": header attribute " + name + " is missing or negative");
    return *v;
  };
  RenderRecord r;
  r.scene = str("nusselt/scene");
  r.device = str("nusselt/device");
  r.driver = findString(meta, "nusselt/driver").value_or("");
  r.models = str("nusselt/models");
  r.source = findString(meta, "nusselt/source").value_or("render");
  if (!parseLighting(str("nusselt/lighting"), r.settings.lighting))
    throw Error(path + ": header attribute nusselt/lighting names an unknown estimator");
  if (!parseRngMode(findString(meta, "nusselt/rng").value_or("pcg"), r.settings.rng))
    throw Error(path + ": header attribute nusselt/rng names unknown random numbers");
  if (!parseSampler(str("nusselt/sampler"), r.settings.sampler))
    throw Error(path + ": header attribute nusselt/sampler names an unknown sampler");
  // Absent in files written before combined materials existed: those rendered in albedo mode.
  if (!parseComponentSelection(findString(meta, "nusselt/components").value_or("albedo"), r.settings.components))
    throw Error(path + ": header attribute nusselt/components names an unknown component selection");
  // Absent in files written before ray queries existed: those traced with the BVH. Not compared by
  // firstDifference: both traversals estimate the same image (their hits differ in float rounding).
  if (!parseTraversal(findString(meta, "nusselt/traversal").value_or("bvh"), r.settings.traversal))
    throw Error(path + ": header attribute nusselt/traversal names an unknown traversal");
  // Absent in files written before the throughput roulette existed: those used the albedo roulette.
  if (!parseRouletteMode(findString(meta, "nusselt/roulette").value_or("albedo"), r.settings.roulette))
    throw Error(path + ": header attribute nusselt/roulette names an unknown roulette");
  // Absent in files written before renders recorded their view: those used the scene's camera,
  // which the caller fills in (hasCamera false here means: not recorded).
  r.cameraRecorded = false;
  if (auto cam = findString(meta, "nusselt/camera")) {
    if (!parseCamera(*cam, r.camera)) throw Error(path + ": header attribute nusselt/camera is malformed");
    r.cameraRecorded = true;
  }
  r.spp = static_cast<std::uint32_t>(num("nusselt/spp"));
  r.settings.sampleOffset = static_cast<std::uint32_t>(num("nusselt/sppOffset"));
  r.settings.seed = static_cast<std::uint32_t>(num("nusselt/seed"));
  r.settings.maxDepth = static_cast<std::uint32_t>(num("nusselt/maxDepth"));
  r.interrupted = findInt(meta, "nusselt/interrupted").value_or(0) != 0;
  r.checkpoint = findInt(meta, "nusselt/checkpoint").value_or(0) != 0;
  r.stats.forEach([&](const char* name, const char*, std::uint64_t& value) {
    value = static_cast<std::uint64_t>(num((std::string("nusselt/") + name).c_str()));
  });
  r.droppedTriangles = num("nusselt/droppedTriangles");
  r.renderSeconds = findDouble(meta, "nusselt/renderSeconds").value_or(0);
  r.totalSeconds = findDouble(meta, "nusselt/totalSeconds").value_or(0);
  r.timeBudget = findDouble(meta, "nusselt/timeBudget").value_or(0);
  r.displayExposure = findDouble(meta, "nusselt/exposure").value_or(0);
  // Absent in files written before environments existed: those rendered without one.
  r.environment = findString(meta, "nusselt/environment").value_or("none");
  r.envScale = findDouble(meta, "nusselt/envScale").value_or(1);
  r.envRotate = findDouble(meta, "nusselt/envRotate").value_or(0);
  r.roughnessBins = static_cast<std::uint32_t>(findInt(meta, "nusselt/roughnessBins").value_or(0));
  if (r.roughnessBins > 0) {
    r.settings.roughnessBins = r.roughnessBins;
    r.settings.roughnessBinSpacing = static_cast<float>(findDouble(meta, "nusselt/roughnessBinSpacing").value_or(1));
  }
  r.envSelect = findString(meta, "nusselt/envSelect").value_or("half");
  // Absent in path-traced renders (and files written before other integrators existed).
  if (!parseIntegrator(findString(meta, "nusselt/integratorName").value_or("path"), r.settings.integrator))
    throw Error(path + ": header attribute nusselt/integratorName names an unknown integrator");
  if (r.settings.integrator == IntegratorKind::Mlt) {
    r.settings.mltChains = static_cast<std::uint32_t>(findInt(meta, "nusselt/mltChains").value_or(0));
    r.settings.mltBootstrap = static_cast<std::uint32_t>(findInt(meta, "nusselt/mltBootstrap").value_or(0));
    r.settings.mltLargeStep = static_cast<float>(findDouble(meta, "nusselt/mltLargeStep").value_or(0.3));
    r.settings.mltSigma = static_cast<float>(findDouble(meta, "nusselt/mltSigma").value_or(0.01));
    // Renders written before the key used the plain weights.
    r.settings.mltKelemen = findInt(meta, "nusselt/mltKelemen").value_or(0) != 0;
    // The path-traced samples of the light outside the chains: "mltDirectSpp" in renders written
    // before the caustic split (their chains carried indirect light), absent before the direct
    // pass (all light in the chains).
    // Renders written before the key moved every chain once per iteration.
    r.settings.mltSteps = static_cast<std::uint32_t>(findInt(meta, "nusselt/mltSteps").value_or(1));
    // Renders written before the key never restarted their chains.
    r.settings.mltRestart = static_cast<std::uint32_t>(findInt(meta, "nusselt/mltRestart").value_or(0));
    const auto passSpp = findInt(meta, "nusselt/mltPassSpp");
    r.settings.mltPassSpp = static_cast<std::uint32_t>(passSpp ? *passSpp : findInt(meta, "nusselt/mltDirectSpp").value_or(0));
    const std::string chainLight = findString(meta, "nusselt/mltChainLight").value_or(passSpp ? "" : "indirect");
    if (r.settings.mltPassSpp && !parseMltChainLight(chainLight, r.settings.mltChainLight))
      throw Error(path + ": header attribute nusselt/mltChainLight: '" + chainLight + "' is not caustic or indirect");
  }
  if (r.settings.integrator == IntegratorKind::Vegas) {
    r.settings.vegasBins = static_cast<std::uint32_t>(findInt(meta, "nusselt/vegasBins").value_or(64));
    r.settings.vegasBounces = static_cast<std::uint32_t>(findInt(meta, "nusselt/vegasBounces").value_or(1));
    r.settings.vegasAlpha = static_cast<float>(findDouble(meta, "nusselt/vegasAlpha").value_or(0.2));
    // Renders written before the key learned a table after every pass.
    r.settings.vegasLearn = static_cast<std::uint32_t>(findInt(meta, "nusselt/vegasLearn").value_or(0xffffffff));
  }
  // Absent in unguided renders (and files written before guiding existed).
  r.settings.guiding = findString(meta, "nusselt/guiding").value_or("off") == "on";
  r.settings.guideTrainSpp = static_cast<std::uint32_t>(findInt(meta, "nusselt/guideTrainSpp").value_or(0));
  // Absent in files written before it: 0, the resuming render's own samples per pass.
  r.settings.guideTrainPass = static_cast<std::uint32_t>(findInt(meta, "nusselt/guideTrainPass").value_or(0));
  // Files written before "auto" existed used a fixed alpha (0.5 by default).
  r.settings.guideAlpha = findString(meta, "nusselt/guideAlpha").value_or("") == "auto"
                              ? -1.0f
                              : static_cast<float>(findDouble(meta, "nusselt/guideAlpha").value_or(0.5));
  // Files written before the splat filters and the floor existed: unfiltered splats, no floor.
  r.settings.guideDirFilter = findString(meta, "nusselt/guideFilter").value_or("none") == "box";
  r.settings.guideSpatialFilter = findString(meta, "nusselt/guideSpatialFilter").value_or("none") == "box";
  r.settings.guideFloor = findDouble(meta, "nusselt/guideFloor").value_or(0.0);
  // Files from before --guide-learn were trained on radiance.
  r.settings.guideProduct = findString(meta, "nusselt/guideLearn").value_or("radiance") == "product";
  // Files written before the photon pre-pass: none.
  r.settings.guidePhotons = static_cast<std::uint32_t>(findInt(meta, "nusselt/guidePhotons").value_or(0));
  r.settings.guideSpatialThreshold = findDouble(meta, "nusselt/guideSpatial").value_or(12000);
  r.settings.guideMemory = static_cast<std::uint64_t>(findDouble(meta, "nusselt/guideMemory").value_or(16 << 20));
  r.guideHash = findString(meta, "nusselt/guideHash").value_or("");
  return r;
}

std::string firstDifference(const RenderRecord& a, const RenderRecord& b) {
  auto differ = [](const std::string& what, const std::string& x, const std::string& y) {
    return x == y ? std::string() : what + ": " + x + " vs " + y;
  };
  const RenderSettings &s = a.settings, &t = b.settings;
  for (const std::string& d :
       {differ("the integrator (--integrator)", integratorName(s.integrator), integratorName(t.integrator)),
        differ("the scene", a.scene, b.scene),
        differ("the image size", std::to_string(s.width) + "x" + std::to_string(s.height),
               std::to_string(t.width) + "x" + std::to_string(t.height)),
        differ("the seed (--seed)", std::to_string(s.seed), std::to_string(t.seed)),
        differ("the max depth (--max-depth)", std::to_string(s.maxDepth), std::to_string(t.maxDepth)),
        differ("the lighting (--lighting)", lightingModeName(s.lighting), lightingModeName(t.lighting)),
        differ("the random numbers (--rng)", rngModeName(s.rng), rngModeName(t.rng)),
        differ("the sampler (--sampler)", samplerName(s.sampler), samplerName(t.sampler)),
        // Compared when either used bins (a render about to resume has not built its bins yet:
        // its settings say what it will build).
        differ("the roughness bins (--roughness-bins, --roughness-bin-spacing)",
               a.roughnessBins || b.roughnessBins
                   ? std::to_string(s.roughnessBins) + " spaced " + formatNumber(s.roughnessBinSpacing) : "",
               a.roughnessBins || b.roughnessBins
                   ? std::to_string(t.roughnessBins) + " spaced " + formatNumber(t.roughnessBinSpacing) : ""),
        differ("the component selection (--components)", componentSelectionName(s.components),
               componentSelectionName(t.components)),
        differ("the roulette (--roulette)", rouletteModeName(s.roulette), rouletteModeName(t.roulette)),
        differ("the camera", cameraText(a.camera), cameraText(b.camera)),
        differ("the environment (--env, --env-color)", a.environment, b.environment),
        differ("the environment scale (--env-scale)", formatNumber(a.envScale), formatNumber(b.envScale)),
        differ("the environment rotation (--env-rotate)", formatNumber(a.envRotate), formatNumber(b.envRotate)),
        differ("the environment's selection (--env-select)", a.envSelect, b.envSelect),
        differ("path guiding (--guiding)", s.guiding ? "on" : "off", t.guiding ? "on" : "off"),
        // Compared when either is a Metropolis render.
        differ("mlt's light outside the chains and steps (--mlt-chain-light, --mlt-pass-spp, --mlt-steps)", mltSplitText(s), mltSplitText(t))})
    if (!d.empty()) return d;
  return {};
}

}  // namespace nusselt
