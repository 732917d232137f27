// renderer.cpp: a render put together from the device scene, the material table, the film and
// the path integrator; the stage globals.
#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>

#include "../../shaders/shared/layout.h"
#include "brdf/merl.h"
#include "render/environment.h"
#include "render/guide.h"
#include "render/mlt_integrator.h"
#include "render/path_integrator.h"
#include "render/texture_table.h"
#include "render/vegas_integrator.h"
#include "../../shaders/shared/vegas.h"
#include "util/error.h"

namespace nusselt {

using shared::Globals;

// ---- Stage globals ------------------------------------------------------------------------------

StageGlobals::StageGlobals(vk::Context& ctx, std::uint32_t pushBytes) : m_ctx(ctx), m_host(new Globals{}) {
  m_buffer = vk::createBuffer(m_ctx, sizeof(Globals), 0, true, "globals");
  m_binding = vk::createGlobalsBinding(m_ctx, m_buffer.buffer, pushBytes);
}

StageGlobals::~StageGlobals() {
  vk::destroyGlobalsBinding(m_ctx, m_binding);
  vk::destroyBuffer(m_ctx, m_buffer);
  delete m_host;
}

void StageGlobals::upload() { std::memcpy(m_buffer.mapped, m_host, sizeof(Globals)); }

// ---- Renderer -----------------------------------------------------------------------------------

namespace {

glm::vec4 v4(glm::vec3 v, float w = 0.0f) { return glm::vec4(v, w); }

}  // namespace

Traversal resolveTraversal(const vk::Context& ctx, Traversal requested) {
  if (requested == Traversal::Auto)
    return ctx.rayQuery && ctx.properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU ? Traversal::RayQuery : Traversal::Bvh;
  if (requested == Traversal::RayQuery && !ctx.rayQuery)
    throw Error("--traversal rayquery: " + ctx.deviceName + " (" + ctx.driverInfo + ") does not offer ray queries "
                "(VK_KHR_ray_query with VK_KHR_acceleration_structure); use --traversal bvh or auto");
  return requested;
}

Renderer::Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings)
    : m_ctx(ctx), m_settings(settings) {
  if (settings.width == 0 || settings.height == 0) throw Error("image size must be at least 1x1");
  const bool mlt = settings.integrator == IntegratorKind::Mlt;
  if (mlt && settings.guiding) throw Error("--integrator mlt with --guiding on: not supported (docs/mlt.md)");
  if (mlt && (settings.mltChains == 0 || settings.mltChains > 65535u * WORKGROUP_SIZE))
    throw Error("--mlt-chains " + std::to_string(settings.mltChains) + ": between 1 and " +
                std::to_string(65535u * WORKGROUP_SIZE));
  const bool vegas = settings.integrator == IntegratorKind::Vegas;
  if (vegas) {
    if (settings.guiding) throw Error("--integrator vegas with --guiding on: not supported (docs/vegas.md)");
    if (settings.vegasBins == 0 || settings.vegasBins > 4096)
      throw Error("--vegas-bins " + std::to_string(settings.vegasBins) + ": between 1 and 4096");
    if (settings.vegasBounces == 0 || settings.vegasBounces > settings.maxDepth + 1)
      throw Error("--vegas-bounces " + std::to_string(settings.vegasBounces) + ": between 1 and max depth + 1 (" +
                  std::to_string(settings.maxDepth + 1) + ")");
    if (!(settings.vegasAlpha >= 0.01f && settings.vegasAlpha <= 1.0f)) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", double(settings.vegasAlpha));
      throw Error(std::string("--vegas-alpha ") + value +
                  ": between 0.01 and 1 (the uniform share that keeps every bin's density > 0)");
    }
  }
  m_settings.traversal = resolveTraversal(ctx, settings.traversal);
  m_summary.traversal = m_settings.traversal;
  const std::uint64_t pixels = std::uint64_t(settings.width) * settings.height;
  if (pixels > (1ull << 28)) throw Error("image too large: at most 2^28 pixels");
  m_summary.triangles = scene.triangleCount();
  m_summary.materials = scene.materials.size();

  // Refuse before allocating when the render cannot fit the device: a clear message instead of
  // an allocation failure halfway (or the driver swapping).
  {
    std::size_t lightBound = scene.lights.size();
    for (std::uint32_t m : scene.triangleMaterial) lightBound += scene.materials[m].emits() ? 1 : 0;
    m_samplesPerPass = mlt ? std::min(MltIntegrator::iterationsPerPassFor(settings), std::max(settings.spp, 1u))
                           : PathIntegrator::samplesPerPassFor(settings, pixels,
                                                               m_ctx.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU);
    const std::uint32_t capacity = mlt ? MltIntegrator::pathSlotsFor(settings, pixels)
                                       : PathIntegrator::capacityFor(settings, pixels, m_samplesPerPass);
    const std::uint32_t primaryDims = settings.primarySamples || mlt ? PathIntegrator::primaryDimsFor(settings.maxDepth)
                                      : vegas                        ? shared::vegasPrimaryDims(settings.vegasBounces)
                                                                     : 0;
    auto mib = [](std::uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
    const std::uint64_t envBytes = environmentBytes(effectiveEnvironment(scene));
    if (m_ctx.maxAllocation && envBytes > m_ctx.maxAllocation)
      throw Error("environment map '" + scene.environment.path + "' (" + std::to_string(scene.environment.width) + "x" +
                  std::to_string(scene.environment.height) + ") needs " + mib(envBytes) + " of device memory, more than " +
                  m_ctx.deviceName + " allows in one allocation (" + mib(m_ctx.maxAllocation) + "): use a smaller map");
    // Measured (merl) tables: each distinct file once (MaterialTable), as floats.
    std::set<std::uint32_t> measured;
    for (const Material& m : scene.materials) {
      if (m.model == MODEL_MERL && m.components.empty()) measured.insert(merlSlot(m.params));
      for (const MaterialComponent& c : m.components)
        if (c.model == MODEL_MERL) measured.insert(merlSlot(c.params));
    }
    const std::uint64_t need = DeviceScene::bytesFor(scene.triangleCount(), lightBound + 1,
                                                     m_settings.traversal == Traversal::RayQuery) + envBytes +
                               textureDeviceBytes(scene) + measured.size() * MERL_TABLE_FLOATS * sizeof(float) +
                               std::max<std::size_t>(scene.materials.size(), 1) * sizeof(shared::GpuMaterial) +
                               Film::bytesFor(pixels) +
                               PathIntegrator::bytesFor(capacity, MAX_MODEL_SLOTS, primaryDims) +
                               (mlt ? MltIntegrator::bytesFor(settings.mltChains, capacity, primaryDims, mltBootstrapPaths(settings), pixels,
                                                                 mltRestartSpp(settings, pixels)) : 0) +
                               (vegas ? VegasIntegrator::bytesFor(settings) : 0) +
                               (settings.guiding ? DeviceGuide::bytesFor(settings.guideMemory, capacity, settings.maxDepth) : 0);
    const std::uint64_t have = vk::deviceLocalHeapSize(m_ctx);
    // The film is the largest single buffer (16 bytes per pixel, twice): one allocation each.
    if (m_ctx.maxAllocation && pixels * 16 > m_ctx.maxAllocation)
      throw Error("a " + std::to_string(settings.width) + "x" + std::to_string(settings.height) + " film needs " +
                  mib(pixels * 16) + " of device memory in one allocation, more than " + m_ctx.deviceName +
                  " allows (" + mib(m_ctx.maxAllocation) + "): use a smaller image (at most " +
                  std::to_string(m_ctx.maxAllocation / 16) + " pixels)");
    if (have && need > have)
      throw Error("the render needs about " + mib(need) + " of device memory (" + std::to_string(scene.triangleCount()) +
                  " triangles, " + std::to_string(settings.width) + "x" + std::to_string(settings.height) + " pixels" +
                  (textureDeviceBytes(scene) ? ", " + mib(textureDeviceBytes(scene)) + " of textures" : std::string()) +
                  (measured.empty() ? std::string() : ", " + std::to_string(measured.size()) + " measured tables") +
                  ") but " + m_ctx.deviceName + " has " + mib(have) + ": use a smaller image or a simpler scene");
  }

  m_globals = std::make_unique<StageGlobals>(m_ctx, STAGE_PUSH_BYTES);
  TraversalStructures structures;
  structures.bvh = m_settings.traversal == Traversal::Bvh;
  structures.accelerationStructures = m_settings.traversal == Traversal::RayQuery;
  m_scene = std::make_unique<DeviceScene>(m_ctx, scene, structures);
  m_summary.lights = m_scene->lights();
  m_summary.bvhSeconds = m_scene->bvhSeconds();
  m_summary.bvhNodes = m_scene->bvhNodes();
  m_summary.accelerationSeconds = m_scene->accelerationSeconds();
  m_summary.accelerationBytes = m_scene->accelerationBytes();
  m_materials = std::make_unique<MaterialTable>(m_ctx, scene, settings);
  m_summary.models = m_materials->slotNames();
  const SamplerPlanSummary& plan = m_materials->samplerPlan();
  m_summary.samplerSeconds = plan.seconds;
  m_summary.samplerTrees = plan.tables;
  m_summary.samplerBytes = plan.bytes;
  m_summary.samplerCacheHits = plan.cacheHits;
  m_summary.samplerCacheMisses = plan.cacheMisses;
  m_summary.samplerCacheRejected = plan.cacheRejected;
  m_summary.roughnessBins = plan.roughnessBins;
  m_summary.binBytes = plan.binBytes;
  m_summary.constantBrdfs = plan.constantBrdfs;
  m_film = std::make_unique<Film>(m_ctx, settings.width, settings.height);

  Globals& g = m_globals->host();
  m_scene->fillGlobals(g);
  m_materials->fillGlobals(g);
  m_film->fillGlobals(g);
  g.display = 0;
  g.seed = settings.seed;
  g.lighting = static_cast<std::uint32_t>(settings.lighting);
  g.radiancePart = settings.radiancePart;
  g.rngMode = static_cast<std::uint32_t>(settings.rng);
  g.componentChoice = static_cast<std::uint32_t>(settings.components);
  g.roulette = static_cast<std::uint32_t>(settings.roulette);
  m_camera = scene.hasCamera ? scene.camera : frameScene(scene);
  writeCamera(m_camera);

  if (settings.guiding) {
    if (m_settings.guideTrainPass == 0) m_settings.guideTrainPass = m_samplesPerPass;
    // The guide's root box: the scene's bounds.
    glm::vec3 lo(0.0f), hi(0.0f);
    if (!scene.positions.empty()) lo = hi = scene.positions[0];
    for (const glm::vec3& p : scene.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    guiding::GuideSettings gs;
    gs.memoryCap = settings.guideMemory;
    gs.alpha = settings.guideAlpha;
    gs.spatialThreshold = settings.guideSpatialThreshold;
    gs.dirFilter = settings.guideDirFilter;
    gs.spatialFilter = settings.guideSpatialFilter;
    gs.floor = settings.guideFloor;
    gs.product = settings.guideProduct;
    m_guide = std::make_unique<DeviceGuide>(m_ctx, lo, hi, gs,
                                            PathIntegrator::capacityFor(settings, pixels, m_samplesPerPass),
                                            settings.maxDepth);
    m_guide->fillGlobals(g);
    m_summary.guiding = true;
    m_summary.guideTrainSpp = guideTrainingSpp(settings);
  }
  PathOptions paths;
  if (settings.primarySamples || mlt) paths.primaryDims = PathIntegrator::primaryDimsFor(settings.maxDepth);
  else if (vegas) paths.primaryDims = shared::vegasPrimaryDims(settings.vegasBounces);
  if (mlt) {
    paths.imageSamples = true;
    paths.capacity = MltIntegrator::pathSlotsFor(settings, pixels);
  }
  auto integrator = std::make_unique<PathIntegrator>(m_ctx, *m_globals, m_settings, m_materials->slotKeys(), pixels,
                                                     m_samplesPerPass, m_materials->slotNames(), m_guide.get(), paths);
  m_summary.pipelineSeconds = integrator->pipelineSeconds();
  m_paths = integrator.get();
  if (mlt) {
    MltScene chainScene;
    chainScene.deltaMaterials = false;
    for (const Material& m : scene.materials) {
      chainScene.deltaMaterials |= m.components.empty() && shared::modelIsDelta(m.model);
      for (const MaterialComponent& c : m.components) chainScene.deltaMaterials |= shared::modelIsDelta(c.model);
    }
    auto chains = std::make_unique<MltIntegrator>(m_ctx, *m_globals, m_settings, std::move(integrator), pixels, chainScene);
    m_mlt = chains.get();
    m_integrator = std::move(chains);
  } else if (vegas) {
    auto warped = std::make_unique<VegasIntegrator>(m_ctx, *m_globals, m_settings, std::move(integrator), pixels);
    m_vegas = warped.get();
    m_integrator = std::move(warped);
  } else {
    m_integrator = std::move(integrator);
  }
  m_globals->upload();
  m_summary.deviceBytes = m_scene->deviceBytes() + m_materials->deviceBytes() + m_film->deviceBytes() +
                          m_integrator->deviceBytes() + sizeof(Globals) + (m_guide ? m_guide->deviceBytes() : 0);
}

Renderer::~Renderer() {
  vkDeviceWaitIdle(m_ctx.device);
  m_integrator.reset();
  m_guide.reset();
  m_film.reset();
  m_materials.reset();
  m_scene.reset();
  m_globals.reset();
}

void Renderer::renderPass(std::uint32_t samples) {
  // Fault injection for the tests of device loss (no GPU can be lost on purpose):
  // NUSSELT_FAULT_DEVICE_LOST_AFTER=N makes the pass after N samples fail as a lost device would.
  static const char* fault = std::getenv("NUSSELT_FAULT_DEVICE_LOST_AFTER");
  if (fault && m_samples >= std::strtoul(fault, nullptr, 10)) VK_CHECK(VK_ERROR_DEVICE_LOST);
  samples = samples == 0 ? m_samplesPerPass : std::min(samples, m_samplesPerPass);
  // Path guiding's training: iteration k covers samples [2^k - 1, 2^(k+1) - 1) of the first
  // guideTrainingSpp the guide has seen (m_guideSamples: the film's samples, except that a reset
  // (a preview's camera or lighting change) keeps the guide and its count); a pass never crosses
  // an iteration's end, where the guide is refined.
  const std::uint32_t trainSpp = m_guide ? guideTrainingSpp(m_settings) : 0;
  const bool training = m_guideSamples < trainSpp;
  std::uint32_t iteration = 0, iterationEnd = 0;
  if (training) {
    while ((2u << iteration) - 1 <= m_guideSamples) ++iteration;
    iterationEnd = std::min((2u << iteration) - 1, trainSpp);
    samples = std::min({samples, iterationEnd - m_guideSamples, m_settings.guideTrainPass});
  }
  // The photon pre-pass (docs/guiding.md): before the first training iteration, its photons train
  // the guide that iteration samples (again on a resume: retrainGuide starts from 0 samples).
  if (training && m_guideSamples == 0 && !m_photonsTraced && m_settings.guidePhotons > 0) {
    m_paths->photonPass(m_settings.guidePhotons);
    // The photons split space as a pass of one photon per pixel would (as many paths as the first
    // iteration's 1 spp): more photons refine the directions, not the regions, which the camera
    // iterations' splats could not fill.
    const double pixels = double(m_settings.width) * m_settings.height;
    m_guide->endPhotons(std::min(1.0, pixels / m_settings.guidePhotons));
    m_photonsTraced = true;
  }
  if (m_guide) m_guide->setRecording(training);
  m_integrator->renderPass(m_settings.sampleOffset + m_samples, samples);
  m_samples += samples;
  m_guideSamples += samples;
  if (training && m_guideSamples == iterationEnd) m_guide->endIteration(iteration);
}

bool Renderer::endTraining() {
  if (!m_guide) return false;
  const std::uint32_t trained = m_guideSamples;
  if (!guideIterationEnds(trained) || trained >= guideTrainingSpp(m_settings)) return false;
  m_settings.guideTrainSpp = trained;
  m_summary.guideTrainSpp = trained;
  m_guide->setRecording(false);
  return true;
}

void Renderer::render(std::uint32_t spp) {
  while (m_samples < spp) renderPass(spp - m_samples);
}

void Renderer::restoreAccumulation(const Image& saved, std::uint32_t spp) {
  m_film->restore(saved, spp);
  m_samples = m_guideSamples = spp;
}

std::uint32_t Renderer::retrainGuide(std::uint32_t spp) {
  if (!m_guide) return 0;
  const std::uint32_t until = std::min(spp, guideTrainingSpp(m_settings));
  // renderPass(until - done) asks for what the render loop asked for (the rest of its target),
  // which the training iterations and samplesPerPass cut into the same passes.
  while (m_guideSamples < until) renderPass(until - m_guideSamples);
  m_film->clear();
  m_samples = 0;
  m_paths->clearCounters();
  return until;
}

void Renderer::writeCamera(const Camera& cam) {
  Globals& g = m_globals->host();
  glm::vec3 f = glm::normalize(cam.forward);
  glm::vec3 right = glm::normalize(glm::cross(f, cam.up));
  glm::vec3 up = glm::cross(right, f);
  float aspect = float(m_settings.width) / float(m_settings.height);
  g.camPosition = v4(cam.position, cam.orthographic ? 1.0f : 0.0f);
  g.camForward = v4(f);
  if (cam.orthographic) {
    g.camRight = v4(right * cam.xmag);
    g.camUp = v4(up * cam.ymag);
  } else {
    float th = std::tan(0.5f * cam.yfov);
    g.camRight = v4(right * (th * aspect));
    g.camUp = v4(up * th);
  }
}

void Renderer::reset() {
  m_film->clear();
  m_samples = 0;
}

void Renderer::setCamera(const Camera& camera) {
  m_camera = camera;
  writeCamera(camera);
  reset();
}

void Renderer::setLighting(LightingMode mode) {
  m_settings.lighting = mode;
  m_globals->host().lighting = static_cast<std::uint32_t>(mode);
  m_globals->upload();
  reset();
}

void Renderer::setDisplayBuffer(VkDeviceAddress address) {
  m_globals->host().display = address;
  m_globals->upload();
}

}  // namespace nusselt
