// Combined materials (the random-walk source's sum of elementary BRDFs) in the white furnace of
// test_furnace.cpp: inside a closed sphere emitting Le uniformly on its inside, a material whose
// total directional albedo is A for every direction gives Le / (1 - A) everywhere (the Neumann
// series Le sum A^n), and with a depth cap D the finite series Le sum_{n<=D} A^n. Where a
// component's albedo depends on the direction (phong's clipped lobe, a conductor's Fresnel), the
// furnace radiance lies between the values of the smallest and the largest total albedo (the
// series is monotone in A); the test then asks the estimate not to be significantly outside
// that interval. Thresholds come from the statistics (pooled variance, Bonferroni), never tuned.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/test_support.h"
#include "brdf/albedo.h"
#include "brdf/registry.h"
#include "util/error.h"

using namespace nusselt;

namespace {

MaterialComponent component(const std::string& model, const NamedParams& params, float weight = 1.0f) {
  return catalogueComponent(model, params, weight);
}

ParamValue rgb(double r, double g, double b) {
  return arrayValue({ParamValue::num(r), ParamValue::num(g), ParamValue::num(b)});
}

// The furnace scene with its one material replaced by a combination of `components`, and flat
// shading normals: with the sphere's interpolated normals some reflected directions point below
// their facet, which the integrator rejects (no light leaks through a surface), an energy loss
// of ~0.1 % per bounce that the exact expectations here would detect after a few bounces.
Scene furnace(const std::vector<MaterialComponent>& components) {
  Scene scene = test::loadTestScene("scenes/tests/furnace.gltf");
  EXPECT_EQ(scene.materials.size(), 1u);
  setComponents(scene.materials[0], components);
  for (std::size_t t = 0; t < scene.triangleCount(); ++t) {
    glm::vec3 n = glm::normalize(glm::cross(scene.positions[3 * t + 1] - scene.positions[3 * t],
                                            scene.positions[3 * t + 2] - scene.positions[3 * t]));
    if (glm::dot(n, scene.normals[3 * t]) < 0.0f) n = -n;
    for (int j = 0; j < 3; ++j) scene.normals[3 * t + j] = n;
  }
  return scene;
}

struct Estimate {
  double mean[3];
  double se[3];
};

// Renders and tests blocks of kBlock x kBlock pixels and the image mean of each channel against
// [lo, hi] (an exact value when lo == hi), at significance alpha for the whole test (Bonferroni
// over the 3 x (blocks + 1) tests), with the variance pooled over the pixels (they all estimate
// the same quantity with the same distribution; see test_furnace.cpp). Blocks, not pixels: the
// colour ratio f_c / lum(f) makes single samples skewed, and a pixel mean of 128 of them is too
// far from normal for a per-pixel z-test; a block holds 36 x 128 samples.
constexpr int kBlock = 6;

Estimate expectFurnace(const Scene& scene, RenderSettings s, const double lo[3], const double hi[3],
                       double alpha = 0.01) {
  test::Rendered r = test::render(scene, s);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(r.stats.bvhStackOverflows, 0u);
  EXPECT_EQ(r.stats.samplerTrialFailures, 0u);
  const int w = int(s.width), h = int(s.height), n = w * h;
  const int blocks = (w / kBlock) * (h / kBlock);
  const double zMax = test::normalQuantileUpper(alpha / (3.0 * (blocks + 1)) / 2);
  auto outside = [](double x, double a, double b) { return x < a ? x - a : (x > b ? x - b : 0.0); };
  Estimate e{};
  for (int c = 0; c < 3; ++c) {
    double sum = 0, var = 0;
    for (int i = 0; i < n; ++i) {
      sum += r.image.rgb[3 * i + c];
      var += r.image.variance[3 * i + c];
    }
    EXPECT_GT(var, 0.0);
    const double pooled = var / n;  // variance of one pixel's mean
    int bad = 0;
    for (int by = 0; by + kBlock <= h; by += kBlock)
      for (int bx = 0; bx + kBlock <= w; bx += kBlock) {
        double b = 0;
        for (int y = by; y < by + kBlock; ++y)
          for (int x = bx; x < bx + kBlock; ++x) b += r.image.rgb[3 * (y * w + x) + c];
        b /= kBlock * kBlock;
        if (std::fabs(outside(b, lo[c], hi[c])) / std::sqrt(pooled / (kBlock * kBlock)) >= zMax && ++bad <= 5)
          ADD_FAILURE() << "channel " << c << " block (" << bx << ", " << by << "): " << b << " vs [" << lo[c] << ", "
                        << hi[c] << "]";
      }
    e.mean[c] = sum / n;
    e.se[c] = std::sqrt(var) / n;
    EXPECT_LT(std::fabs(outside(e.mean[c], lo[c], hi[c])) / e.se[c], zMax)
        << "channel " << c << " mean " << e.mean[c] << " +- " << e.se[c] << " vs [" << lo[c] << ", " << hi[c] << "]";
    std::printf("[ furnace  ] channel %d: mean %.5f +- %.5f, expected [%.5f, %.5f], z outside %.2f (limit %.2f)\n", c,
                e.mean[c], e.se[c], lo[c], hi[c], outside(e.mean[c], lo[c], hi[c]) / e.se[c], zMax);
  }
  EXPECT_EQ(test::validationMessages(), 0u);
  return e;
}

RenderSettings furnaceSettings() {
  RenderSettings s;
  s.width = 24;
  s.height = 24;
  s.spp = 128;
  s.maxDepth = 64;  // truncation bias <= A^65 < 0.75^65 ~ 1e-8: far below the resolution
  s.seed = 7;
  return s;
}

// Le / (1 - A) per channel for constant total albedos A.
void neumann(double le, const double a[3], double out[3]) {
  for (int c = 0; c < 3; ++c) out[c] = le / (1.0 - a[c]);
}

// Range of the luminance directional albedo of a model over theta_o in [0, 89.5] degrees.
void albedoRange(std::uint32_t model, const BrdfParams& p, double& lo, double& hi) {
  lo = 1e30;
  hi = -1e30;
  for (double t = 0; t <= 89.5; t += 0.5) {
    double a = directionalAlbedo(model, p, t);
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
}

}  // namespace

// Colour and a quadtree-sampled model other than lambert: lambert (coloured) + phong with ks = 0
// (its albedo is kd for every direction). Per channel the series is Le / (1 - A_c) although the
// choice uses luminance: the colour ratio f_c / lum(f) in the weight is exact.
TEST(CombinedFurnace, ColouredLambertPlusPhongDiffuse) {
  Scene scene = furnace({component("lambert", {{"rho", rgb(0.5, 0.3, 0.1)}}, 0.5f),
                         component("phong", {{"kd", rgb(0.2, 0.4, 0.6)}, {"ks", ParamValue::num(0)}})});
  const double a[3] = {0.5 * 0.5 + 0.2, 0.5 * 0.3 + 0.4, 0.5 * 0.1 + 0.6};
  double expected[3];
  neumann(scene.materials[0].emission.x, a, expected);
  expectFurnace(scene, furnaceSettings(), expected, expected);
}

// lambert + phong with a glossy lobe: the lobe loses energy below the horizon at grazing wo, so
// the furnace value lies between Le / (1 - A_min) and Le / (1 - A_max).
TEST(CombinedFurnace, LambertPlusPhong) {
  Scene scene = furnace({component("lambert", {{"rho", ParamValue::num(0.3)}}),
                         component("phong", {{"kd", ParamValue::num(0)}, {"ks", ParamValue::num(0.4)},
                                             {"n", ParamValue::num(40)}})});
  double pmin, pmax;
  albedoRange(MODEL_PHONG, scene.materials[0].components[1].params, pmin, pmax);
  const double le = scene.materials[0].emission.x;
  const double lo[3] = {le / (0.7 - pmin), le / (0.7 - pmin), le / (0.7 - pmin)};
  const double hi[3] = {le / (0.7 - pmax), le / (0.7 - pmax), le / (0.7 - pmax)};
  expectFurnace(scene, furnaceSettings(), lo, hi);
}

// lambert + mirror (a near-perfect conductor: eta 0.01, k 20 reflects 1 - O(1e-4) at every
// angle; the interval covers the rest): delta component, prevPdf 0, no light samples for it.
TEST(CombinedFurnace, LambertPlusMirror) {
  Scene scene = furnace({component("lambert", {{"rho", ParamValue::num(0.4)}}),
                         component("mirror", {{"eta", ParamValue::num(0.01)}, {"k", ParamValue::num(20)}}, 0.35f)});
  const BrdfParams mp = scene.materials[0].components[1].params;
  double fmin = 1, fmax = 0;
  for (int i = 0; i <= 1000; ++i) {
    double f = shared::luminance(shared::mirrorReflectance(mp, i / 1000.0f));
    fmin = std::min(fmin, f);
    fmax = std::max(fmax, f);
  }
  const double le = scene.materials[0].emission.x;
  const double lo1 = le / (1 - 0.4 - 0.35 * fmin), hi1 = le / (1 - 0.4 - 0.35 * fmax);
  const double lo[3] = {lo1, lo1, lo1}, hi[3] = {hi1, hi1, hi1};
  expectFurnace(scene, furnaceSettings(), lo, hi);
}

// lambert + dielectric: the sphere's inside faces the camera, so refracted rays leave the
// furnace into the background B, scaled by 1 / eta^2. With B = eta^2 L the transmitted radiance
// equals the reflected one (R L + T B / eta^2 = L at every angle), so the interface has albedo 1
// and L = Le / (1 - rho - w) exactly.
TEST(CombinedFurnace, LambertPlusDielectric) {
  const double eta = 1.5, rho = 0.3, w = 0.45;
  Scene scene = furnace({component("lambert", {{"rho", ParamValue::num(rho)}}),
                         component("dielectric", {{"eta", ParamValue::num(eta)}}, float(w))});
  const double le = scene.materials[0].emission.x;
  const double l = le / (1 - rho - w);
  scene.background = glm::vec3(float(eta * eta * l));
  const double expected[3] = {l, l, l};
  expectFurnace(scene, furnaceSettings(), expected, expected);
}

// A non-energy-conserving set (total albedo 1.2 > 1): the choice probabilities are normalised
// (the walk never ends at the choice) and the weight stays honest (1.2 per bounce), so with the
// depth cap D the pixel is the finite series Le sum_{n<=D} 1.2^n.
TEST(CombinedFurnace, NonEnergyConservingSetIsTheFiniteSeries) {
  Scene scene = furnace({component("lambert", {{"rho", ParamValue::num(0.5)}}),
                         component("lambert", {{"rho", ParamValue::num(0.7)}})});
  RenderSettings s = furnaceSettings();
  s.maxDepth = 5;
  const double le = scene.materials[0].emission.x;
  double sum = 0;
  for (std::uint32_t n = 0; n <= s.maxDepth; ++n) sum += std::pow(1.2, n);
  const double expected[3] = {le * sum, le * sum, le * sum};
  expectFurnace(scene, s, expected, expected);
}

// Uniform choice estimates the same value as the albedo choice (three components, one of them
// delta), under both roulettes: with the albedo roulette (the source's choice P_k = a_k against
// uniform choice plus a separate albedo roulette) and with the throughput roulette (the
// proportional choice by the largest channel against uniform choice). A two-sample z-test of the
// image means per channel at significance 0.001 (Bonferroni over 3 channels x 2 roulettes),
// different seeds (independent estimates).
TEST(CombinedFurnace, UniformSelectionMatchesAlbedoSelection) {
  Scene scene = furnace({component("lambert", {{"rho", ParamValue::num(0.25)}}),
                         component("phong", {{"kd", ParamValue::num(0)}, {"ks", ParamValue::num(0.3)},
                                             {"n", ParamValue::num(20)}}),
                         component("mirror", {{"eta", ParamValue::num(0.96)}, {"k", ParamValue::num(6.69)}}, 0.2f)});
  // Any value: only the two modes are compared here (the interval tests above check the level).
  const double lo[3] = {0, 0, 0}, hi[3] = {1e9, 1e9, 1e9};
  const double zMax = test::normalQuantileUpper(0.001 / 6 / 2);
  for (RouletteMode roulette : {RouletteMode::Albedo, RouletteMode::Throughput}) {
    RenderSettings s = furnaceSettings();
    s.roulette = roulette;
    Estimate albedo = expectFurnace(scene, s, lo, hi);
    s.components = ComponentSelection::Uniform;
    s.seed = 8;
    Estimate uniform = expectFurnace(scene, s, lo, hi);
    for (int c = 0; c < 3; ++c) {
      double z = (albedo.mean[c] - uniform.mean[c]) / std::hypot(albedo.se[c], uniform.se[c]);
      std::printf("[ furnace  ] %s roulette, channel %d: albedo %.5f +- %.5f, uniform %.5f +- %.5f, z = %.2f\n",
                  rouletteModeName(roulette), c, albedo.mean[c], albedo.se[c], uniform.mean[c], uniform.se[c], z);
      EXPECT_LT(std::fabs(z), zMax) << rouletteModeName(roulette) << " roulette, channel " << c;
    }
  }
}

// rough_dielectric and rough_thin_dielectric (transmitting non-delta models) under a strategy that
// samples the upper hemisphere only (cosine here) are refused with a message naming the material
// and the model, not rendered as their reflection alone: alone and as a component of a combined
// material (which the quadtree renders: RoughTransmission.PartialRoughTransmission* in
// test_textures_render.cpp).
TEST(Combined, RoughTransmissionIsRefusedWhereNotSupported) {
  RenderSettings s;
  s.width = s.height = 8;
  s.spp = 1;
  s.sampler = SamplerKind::Cosine;
  for (const std::string model : {"rough_dielectric", "rough_thin_dielectric"})
    for (bool combined : {false, true}) {
      Scene scene = test::loadTestScene("scenes/tests/furnace.gltf");
      ASSERT_EQ(scene.materials.size(), 1u);
      if (combined)
        setComponents(scene.materials[0], {catalogueComponent("lambert", {}, 0.5f), catalogueComponent(model, {}, 0.5f)});
      else
        scene.materials[0] = catalogueMaterial(model, {}, scene.materials[0].name);
      try {
        Renderer r(test::context(), scene, s);
        ADD_FAILURE() << "a scene with " << model << " was accepted (combined " << combined << ")";
      } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("model " + model + " transmits through a rough surface, which only the quadtree sampler "
                         "samples (--sampler quadtree); the cosine strategy"),
                  std::string::npos)
            << m;
        EXPECT_NE(m.find("material " + scene.materials[0].name), std::string::npos) << m;
      }
    }
}
