// guide_view.cpp: `nusselt guide-view` (issue 16, docs/guiding.md): what the path guide learned,
// seen from one pixel. It trains the guide as `render --guiding on` does (the same scene, settings
// and seed give the same trees), finds the pixel's first hit (the ray through the pixel's centre,
// every triangle tested), and draws two densities per steradian over the guide's equal-area map of
// the sphere of world directions (column: u = (z + 1) / 2, row: v = phi / (2 pi), phi from +x
// towards +y; guiding.h): the guide's learned density in the region holding the hit, and beside
// it the density of the material's BRDF sampler (the quadtree, f cos over the albedo) for the
// direction towards the camera. Each panel is grey on a log scale, white at its maximum, black
// three decades below it; the printed integrals (midpoint rule over the map) check both.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "io/image.h"
#include "quadtree/sampler_tables.h"
#include "render/guide.h"
#include "render/renderer.h"
#include "render/settings.h"
#include "scene/bvh.h"
#include "util/error.h"
#include "vk/vk.h"
#include "../../shaders/shared/guiding.h"
#include "../../shaders/shared/quadtree.h"
#include "../../shaders/shared/warp.h"

namespace nusselt {
namespace {

struct GuideViewArgs {
  std::string scene;
  std::string output = "guide-view.png";
  std::string exr;
  std::string camera;
  std::vector<std::uint32_t> pixel;  // x y
  std::uint32_t width = 0, height = 0;
  std::uint32_t train = 15;
  std::uint32_t maxDepth = 8;
  std::uint32_t seed = 0;
  std::uint32_t size = 256;
  double guideSpatial = 12000;
  double guideMemoryMiB = 16;
  std::string guideFilter = "box";
  std::string guideSpatialFilter = "none";
  double guideFloor = 0.0;
  std::string guideLearn = "product";
  std::uint32_t guidePhotons = 0;
  int device = -1;
  bool quiet = false;
  EnvironmentArgs env;
};

// The first surface the ray meets: every triangle against it, the GPU's Moller-Trumbore.
bool firstHit(const Scene& scene, glm::vec3 o, glm::vec3 d, float& t, std::uint32_t& tri, float& b1, float& b2) {
  t = std::numeric_limits<float>::infinity();
  bool hit = false;
  for (std::uint32_t i = 0; i < scene.triangleCount(); ++i) {
    const glm::vec3 v0 = scene.positions[3 * i], v1 = scene.positions[3 * i + 1], v2 = scene.positions[3 * i + 2];
    float ti, c1, c2;
    if (intersectTriangle(o, d, v0, v1 - v0, v2 - v0, 0.0f, t, ti, c1, c2)) {
      t = ti;
      tri = i;
      b1 = c1;
      b2 = c2;
      hit = true;
    }
  }
  return hit;
}

// One panel: density per steradian at each cell centre of the map (row-major, size x size).
template <class F>
std::vector<double> panel(std::uint32_t size, F&& density) {
  std::vector<double> v(std::size_t(size) * size);
  for (std::uint32_t row = 0; row < size; ++row)
    for (std::uint32_t col = 0; col < size; ++col)
      v[std::size_t(row) * size + col] = density(shared::vec2((col + 0.5f) / size, (row + 0.5f) / size));
  return v;
}

// The integral over the sphere of a panel's density (each cell is 4 pi / size^2 steradians).
double integral(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s * 4.0 * M_PI / double(v.size());
}

// Writes panel v into image columns [x0, x0 + size): grey, log scale over three decades below
// its maximum (an all-zero panel stays black).
void drawPanel(Image& im, std::uint32_t x0, std::uint32_t size, const std::vector<double>& v) {
  const double top = *std::max_element(v.begin(), v.end());
  for (std::uint32_t row = 0; row < size; ++row)
    for (std::uint32_t col = 0; col < size; ++col) {
      const double x = v[std::size_t(row) * size + col];
      const float g = top > 0 && x > 0 ? float(std::clamp(1.0 + std::log10(x / top) / 3.0, 0.0, 1.0)) : 0.0f;
      for (int c = 0; c < 3; ++c) im.rgb[(std::size_t(row) * im.width + x0 + col) * 3 + c] = g;
    }
}

int guideViewCommand(const GuideViewArgs& a) {
  if (a.pixel.size() != 2) throw Error("--pixel: give the pixel as two numbers, X Y");
  if (a.train == 0) throw Error("--train 0: the guide needs at least one training sample per pixel");
  checkOutputPath(a.output, "-o");
  if (!a.exr.empty()) checkOutputPath(a.exr, "--exr");
  ScopedStopSignals signals;

  Scene scene = loadCommandScene(a.scene, a.camera, a.env, a.quiet);

  RenderSettings s;
  s.seed = a.seed;
  s.maxDepth = a.maxDepth;
  imageSize(scene, a.width, a.height, 128u, s.width, s.height);
  const std::uint32_t px = a.pixel[0], py = a.pixel[1];
  if (px >= s.width || py >= s.height)
    throw Error("--pixel " + std::to_string(px) + " " + std::to_string(py) + ": outside the " + std::to_string(s.width) +
                "x" + std::to_string(s.height) + " image (pixels count from 0, top left)");
  s.guiding = true;
  s.guideTrainSpp = a.train;
  s.guideSpatialThreshold = a.guideSpatial;
  s.guideMemory = static_cast<std::uint64_t>(a.guideMemoryMiB * 1048576.0);
  s.guideDirFilter = a.guideFilter == "box";
  s.guideSpatialFilter = a.guideSpatialFilter == "box";
  s.guideFloor = a.guideFloor;
  s.guideProduct = a.guideLearn == "product";
  s.guidePhotons = a.guidePhotons;
  s.spp = a.train;

  // The pixel's first hit, with the camera the render uses.
  const Camera cam = scene.hasCamera ? scene.camera : frameScene(scene);
  const glm::vec3 f = glm::normalize(cam.forward), right = glm::normalize(glm::cross(f, cam.up)),
                  up = glm::cross(right, f);
  const float sx = ((float(px) + 0.5f) / float(s.width)) * 2.0f - 1.0f;
  const float sy = 1.0f - ((float(py) + 0.5f) / float(s.height)) * 2.0f;
  glm::vec3 origin = cam.position, dir;
  if (cam.orthographic) {
    origin += sx * cam.xmag * right + sy * cam.ymag * up;
    dir = f;
  } else {
    const float th = std::tan(0.5f * cam.yfov);
    dir = glm::normalize(f + sx * th * (float(s.width) / float(s.height)) * right + sy * th * up);
  }
  float t, b1, b2;
  std::uint32_t tri = 0;
  if (!firstHit(scene, origin, dir, t, tri, b1, b2))
    throw Error("--pixel " + std::to_string(px) + " " + std::to_string(py) + ": the ray through its centre meets no "
                "surface (the guide lives at surfaces)");
  const glm::vec3 x = origin + t * dir;
  // The hit's geometric normal on the camera's side: its orientation class picks the guide's
  // spatial root (guideOrientation), as the shade stage does.
  const glm::vec3 ngFront = glm::normalize(glm::cross(scene.positions[3 * tri + 1] - scene.positions[3 * tri],
                                                      scene.positions[3 * tri + 2] - scene.positions[3 * tri]));
  const glm::vec3 ng = glm::dot(ngFront, dir) < 0.0f ? ngFront : -ngFront;
  const std::uint32_t orientation = shared::guideOrientation(shared::vec3(ng.x, ng.y, ng.z));
  const Material& mat = scene.materials[scene.triangleMaterial[tri]];

  vk::Context ctx;
  vk::ContextOptions co;
  co.deviceIndex = a.device;
  co.validation = validationFromEnvironment();
  vk::createContext(ctx, co);
  int status = kExitOk;
  {
    Renderer renderer(ctx, scene, s);
    renderer.setCamera(cam);
    if (!a.quiet)
      std::fprintf(stderr, "guide-view: training the guide on %ux%u pixels, %u spp (max depth %u, seed %u)...\n",
                   s.width, s.height, a.train, s.maxDepth, s.seed);
    renderer.render(a.train);
    const DeviceGuide* guide = renderer.guide();
    if (!guide) throw Error("guide-view: the render has no guide");
    const guiding::GuideTree& tree = guide->tree();
    std::vector<shared::GuideSpatialNode> spatial;
    std::vector<shared::GuideDirNode> dirNodes;
    tree.flatten(spatial, dirNodes);
    shared::GuideView view;
    view.g.boundsMin = shared::vec4(tree.boundsMin(), 0.0f);
    view.g.boundsMax = shared::vec4(tree.boundsMax(), 0.0f);
    view.g.info.z = tree.settings().orientations;
    view.spatial = spatial.data();
    view.dir = dirNodes.data();
    const shared::uvec4 leafInfo = shared::guideLeafInfo(view, x, orientation);
    const std::uint32_t leaf = tree.findLeaf(x, orientation);
    const float alpha = glm::uintBitsToFloat(leafInfo.z);
    const std::vector<double> guidePanel =
        panel(a.size, [&](shared::vec2 p) { return double(shared::guideSquarePdf(view, leafInfo.y, p)) / (4.0 * M_PI); });

    // The BRDF sampler's density for the direction towards the camera, in the shade stage's frame
    // (the interpolated shading normal on the side the ray came from; normal maps not applied).
    std::vector<double> brdfPanel(std::size_t(a.size) * a.size, 0.0);
    std::string brdfNote;
    const ModelSpec& spec = modelById(mat.model);
    if (mat.combined()) brdfNote = "not drawn: a combined material (its components have their own samplers)";
    else if (spec.delta) brdfNote = "not drawn: " + spec.name + " is a delta model (no density)";
    else if (spec.measured) brdfNote = "not drawn: a measured material";
    else {
      glm::vec3 ns = glm::normalize((1.0f - b1 - b2) * scene.normals[3 * tri] + b1 * scene.normals[3 * tri + 1] +
                                    b2 * scene.normals[3 * tri + 2]);
      if (glm::dot(ns, ng) < 0.0f) ns = -ns;
      glm::vec3 tt, bb;
      shared::makeFrame(ns, tt, bb);
      glm::vec3 wo = shared::toLocal(-dir, tt, bb, ns);
      if (wo.z <= 0.0f) {
        ns = ng;
        shared::makeFrame(ns, tt, bb);
        wo = shared::toLocal(-dir, tt, bb, ns);
      }
      std::vector<std::uint32_t> setOf;
      quadtree::QuadtreeSettings qs;
      const quadtree::SamplerTables tables = quadtree::buildSamplerTables({{mat.model, mat.params}}, qs, setOf);
      quadtree::QuadHostScope scope(tables);
      brdfPanel = panel(a.size, [&](shared::vec2 p) {
        const glm::vec3 w = shared::toLocal(shared::guideSquareToDirection(p), tt, bb, ns);
        return double(shared::quadPdf(setOf[0], mat.model, mat.params, wo, w));
      });
    }
    const std::uint32_t gap = std::max(2u, a.size / 32);
    Image im;
    im.width = int(2 * a.size + gap);
    im.height = int(a.size);
    im.rgb.assign(std::size_t(im.width) * im.height * 3, 0.0f);
    for (std::uint32_t row = 0; row < a.size; ++row)
      for (std::uint32_t c = 0; c < gap; ++c)
        for (int k = 0; k < 3; ++k) im.rgb[(std::size_t(row) * im.width + a.size + c) * 3 + k] = 0.5f;
    drawPanel(im, 0, a.size, guidePanel);
    drawPanel(im, a.size + gap, a.size, brdfPanel);
    writePng(a.output, im);
    if (!a.exr.empty()) {  // the densities themselves, guide panel left (same layout, gap 0)
      Image raw;
      raw.width = int(2 * a.size + gap);
      raw.height = int(a.size);
      raw.rgb.assign(std::size_t(raw.width) * raw.height * 3, 0.0f);
      for (std::uint32_t row = 0; row < a.size; ++row)
        for (std::uint32_t col = 0; col < a.size; ++col)
          for (int k = 0; k < 3; ++k) {
            raw.rgb[(std::size_t(row) * raw.width + col) * 3 + k] = float(guidePanel[std::size_t(row) * a.size + col]);
            raw.rgb[(std::size_t(row) * raw.width + a.size + gap + col) * 3 + k] =
                float(brdfPanel[std::size_t(row) * a.size + col]);
          }
      writeExr(a.exr, raw);
    }
    std::printf("pixel %u %u: first hit (%.4g, %.4g, %.4g), triangle %u, material '%s' (%s)\n", px, py, x.x, x.y, x.z,
                tri, mat.name.c_str(), mat.combined() ? "combined" : spec.name.c_str());
    const guiding::DirTree& learned = tree.samplingTree(leaf);
    std::printf("region %u of %u: a directional tree of %zu nodes, depth %u; the guide is chosen with probability "
                "%.3g%s\n", leaf, tree.leafCount(), learned.nodeCount(), learned.depth(), alpha,
                alpha > 0.0f ? "" : " (not guided here)");
    std::printf("guide density: integral over the sphere %.4f (1 where the region learned something)\n",
                integral(guidePanel));
    if (brdfNote.empty())
      std::printf("BRDF sampler density: integral over the sphere %.4f (1 up to the midpoint rule)\n",
                  integral(brdfPanel));
    else
      std::printf("BRDF sampler density: %s\n", brdfNote.c_str());
    std::printf("wrote %s (left: guide, right: BRDF sampler; u = (z + 1) / 2 across, phi / 2 pi down)%s%s\n",
                a.output.c_str(), a.exr.empty() ? "" : ", ", a.exr.c_str());
  }
  vk::destroyContext(ctx);
  return status;
}

}  // namespace

void registerGuideViewCommand(CLI::App& app, CommandRunner& run) {
  auto a = std::make_shared<GuideViewArgs>();
  CLI::App* c = app.add_subcommand(
      "guide-view", "Draw the path guide's learned density seen from a pixel's first hit, with the BRDF sampler's "
                    "beside it (docs/guiding.md)");
  c->add_option("scene", a->scene, "glTF 2.0 scene (.gltf or .glb); omitted: the built-in Cornell box");
  c->add_option("--pixel", a->pixel, "The pixel X Y (from 0, top left) whose first hit is viewed")->expected(2)->required();
  c->add_option("-o,--output", a->output, "Output PNG (default guide-view.png)");
  c->add_option("--exr", a->exr, "Also write the two densities (per steradian) as OpenEXR");
  addEnvironmentOptions(*c, a->env);
  c->add_option("--width", a->width, "Width of the training render (default 128, or from --height and the camera)")
      ->check(CLI::Range(1u, 65536u));
  c->add_option("--height", a->height, "Height of the training render (default from the width and the camera)")
      ->check(CLI::Range(1u, 65536u));
  c->add_option("--train", a->train, "Training samples per pixel (iterations of 1, 2, 4, ...; as render --guide-train)")
      ->capture_default_str()->check(CLI::Range(1u, 1u << 20));
  c->add_option("--max-depth", a->maxDepth, "Maximum path depth of the training render")
      ->capture_default_str()->check(CLI::Range(0u, 1024u));
  c->add_option("--seed", a->seed, "Random seed of the training render")->capture_default_str();
  c->add_option("--guide-spatial", a->guideSpatial, "The guide's spatial split rule (as render --guide-spatial)")
      ->capture_default_str()->check(CLI::Range(1.0, 1e12));
  c->add_option("--guide-memory", a->guideMemoryMiB, "Memory cap of the guide's trees, MiB")
      ->capture_default_str()->check(CLI::Range(0.01, 4096.0));
  c->add_option("--guide-filter", a->guideFilter, "The training splats' directional filter (as render --guide-filter)")
      ->capture_default_str()->check(CLI::IsMember({"box", "none"}));
  c->add_option("--guide-spatial-filter", a->guideSpatialFilter,
                "The training splats' spatial filter (as render --guide-spatial-filter)")
      ->capture_default_str()->check(CLI::IsMember({"box", "none"}));
  c->add_option("--guide-floor", a->guideFloor, "Uniform density mixed into the guide (as render --guide-floor)")
      ->capture_default_str()->check(CLI::Range(0.0, 0.5));
  c->add_option("--guide-learn", a->guideLearn, "What the guide learns: product or radiance (as render --guide-learn)")
      ->capture_default_str()->check(CLI::IsMember({"product", "radiance"}));
  c->add_option("--guide-photons", a->guidePhotons, "Photons of the guide's pre-pass (as render --guide-photons)")
      ->capture_default_str()->check(CLI::Range(0u, 1u << 30));
  c->add_option("--size", a->size, "Side of each panel in pixels")->capture_default_str()->check(CLI::Range(16u, 4096u));
  c->add_option("--camera", a->camera, "Use the glTF camera with this name (default: the first camera)");
  c->add_option("--device", a->device, "Vulkan device index (see `nusselt devices`)");
  c->add_flag("-q,--quiet", a->quiet, "No progress output");
  c->callback([a, &run] { run = [a] { return guideViewCommand(*a); }; });
}

}  // namespace nusselt
