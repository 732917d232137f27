// test_binned_sampling.cpp: binned sampling of gltf_pbr materials whose textures vary their
// parameters (shaders/shared/bsdf_sampling.h, "Binned sampling"), on the CPU (the shared code):
//   - chi-square goodness of fit of binnedSample's directions against binnedPdf (the exact mixture
//     density that MIS uses), with equal-probability bins from an independent pilot run and one
//     more bin for failed samples (tests/unit/test_quadtree_chi2.h), significance 0.01 with
//     Bonferroni over the cases; the pdf's integral over the hemisphere must be 1 - failures;
//   - unbiasedness: the mean of luminance(f) cos / pdf (failures count 0) agrees with
//     directionalAlbedo of the texel's parameters within 5 standard errors (> the Bonferroni z of
//     0.01 over the cases) plus 2e-3 relative (the albedo quadrature's error).
// Texel parameter sets: a rough dielectric, a glossy metal between two bins, a near-mirror metal
// (below the first bin above 0), roughness exactly on a bin; 4 uniform bins, tables only at the
// cases' angles (tables, and between tables).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "../../shaders/shared/bsdf_sampling.h"
#include "brdf/albedo.h"
#include "quadtree/roughness_bins.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::shared;

namespace {

struct BinCase {
  const char* name;
  vec3 base;
  float metallic, roughness;
  double thetaDeg;
};

constexpr std::uint32_t kBins = 4;
constexpr std::uint32_t kSamples = 1u << 20;
constexpr std::uint32_t kPilot = 1u << 15;

// r_1 = 1/3 exactly as the code computes it (pow(1/3, 1)).
float onBin() {
  RoughnessBins B{0u, kBins, 1.0f, 0u};
  return binRoughness(B, 1u);
}

std::vector<BinCase> cases() {
  return {{"rough dielectric", vec3(0.8f, 0.5f, 0.3f), 0.0f, 0.8f, 37.3},
          {"glossy metal between bins", vec3(0.95f, 0.64f, 0.54f), 1.0f, 0.2f, 60.0},
          {"near-mirror metal", vec3(0.9f, 0.9f, 0.9f), 1.0f, 0.06f, 30.0},
          {"half metal on a bin, grazing", vec3(0.6f, 0.7f, 0.2f), 0.5f, onBin(), 85.0},
          {"dielectric glossy, normal", vec3(0.2f, 0.3f, 0.8f), 0.0f, 0.15f, 0.0}};
}

BrdfParams texel(const BinCase& c) {
  BrdfParams p{};
  p.v[0] = vec4(c.base, c.metallic);
  p.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = c.roughness;
  return p;
}

// The bins' trees (4 uniform bins) and Fresnel moments, tables only at the cases' angles, built once.
const quadtree::SamplerTables& binTables() {
  static quadtree::SamplerTables t = [] {
    return quadtree::buildRoughnessBinTables(RoughnessBins{0u, kBins, 1.0f, 0u}, qttest::testSettings());
  }();
  return t;
}

// n samples (direction, pdf; pdf 0: failed) and their luminance weights, u from rng2 (seed).
void draw(const BinCase& c, std::uint32_t n, std::uint32_t seed, std::vector<vec4>& out, std::vector<double>* weights) {
  quadtree::QuadHostScope scope(binTables());
  RoughnessBins B{0u, kBins, 1.0f, 0u};
  BrdfParams p = texel(c);
  vec3 v = qttest::knownDirection(qttest::Case{"gltf_pbr", false, c.thetaDeg, 0});
  out.resize(n);
  if (weights) weights->assign(n, 0.0);
  for (std::uint32_t i = 0; i < n; ++i) {
    vec2 u = rng2(i, 0u, RNG_DIM_BSDF, seed);
    vec3 wi, f;
    float pdf;
    if (!binnedSample(B, p, v, u, wi, pdf, f)) {
      out[i] = vec4(0.0f);
      continue;
    }
    out[i] = vec4(wi, pdf);
    if (weights) (*weights)[i] = double(luminance(f)) * wi.z / pdf;
  }
}

}  // namespace

TEST(BinnedSampling, ChiSquareAgainstItsOwnPdf) {
  const double alpha = 0.01 / double(cases().size());
  for (const BinCase& c : cases()) {
    std::vector<vec4> pilot, samples;
    draw(c, kPilot, 7u, pilot, nullptr);
    draw(c, kSamples, 1u, samples, nullptr);
    RoughnessBins B{0u, kBins, 1.0f, 0u};
    BrdfParams p = texel(c);
    vec3 v = qttest::knownDirection(qttest::Case{"gltf_pbr", false, c.thetaDeg, 0});
    qttest::Binning bins = qttest::quantileBinning(pilot, 16, 32);
    std::vector<double> prob = qttest::binProbabilities([&](vec3 w) { return double(binnedPdf(B, p, v, w)); }, bins, pilot,
                                                        [&]() { return std::make_shared<quadtree::QuadHostScope>(binTables()); });
    qttest::Chi2Result r = qttest::chiSquare(bins, prob, samples);
    std::printf("%-32s theta %5.1f: chi2 %.1f, dof %d, p %.3g, pdf integral %.6f, failed %.0f\n", c.name, c.thetaDeg, r.chi2,
                r.dof, r.pValue, r.expectedTotal, r.failedObserved);
    EXPECT_GT(r.pValue, alpha) << c.name << "\n" << r.dump;
    // The density integrates to 1 but for the failures (the trees' rejection cap: almost never).
    EXPECT_NEAR(r.expectedTotal, 1.0 - r.failedObserved / kSamples, 2e-3) << c.name;
  }
}

TEST(BinnedSampling, WeightsEstimateTheTexelAlbedo) {
  for (const BinCase& c : cases()) {
    std::vector<vec4> samples;
    std::vector<double> w;
    draw(c, kSamples, 3u, samples, &w);
    double s = 0, s2 = 0;
    for (double x : w) {
      s += x;
      s2 += x * x;
    }
    const double n = double(w.size()), mean = s / n, se = std::sqrt(std::max(0.0, s2 / n - mean * mean) / n);
    const double ref = directionalAlbedo(MODEL_GLTF_PBR, texel(c), c.thetaDeg);
    std::printf("%-32s theta %5.1f: mean weight %.5f +- %.5f, albedo %.5f, relative variance %.4f\n", c.name, c.thetaDeg,
                mean, se, ref, (s2 / n - mean * mean) / (mean * mean));
    EXPECT_NEAR(mean, ref, 5 * se + 2e-3 * ref) << c.name;
  }
}

TEST(BinnedSampling, BinsAroundARoughness) {
  RoughnessBins B{0u, 5u, 2.0f, 0u};  // 0, 1/16, 1/4, 9/16, 1
  for (float r : {0.0f, 0.01f, 0.0625f, 0.1f, 0.25f, 0.3f, 0.5625f, 0.9f, 1.0f}) {
    std::uint32_t j;
    float t;
    binLocate(B, r, j, t);
    ASSERT_LE(j + 1, 4u);
    const float r0 = binRoughness(B, j), r1 = binRoughness(B, j + 1);
    EXPECT_LE(r0, r) << r;
    EXPECT_GE(r1, r) << r;
    EXPECT_NEAR(t, (r - r0) / (r1 - r0), 1e-6f) << r;
  }
}

// The bins' Fresnel moments (binFresnelMoments, which c_d reads) rebuild the texel's albedo: at a
// roughness on a bin and a table direction, lum((1 - f0) cdiff)(1 - B5) + lum(f0) A1 + (1 - lum(f0)) A5
// (A1 the table's mass) is the texel's directionalAlbedo, up to the moments' 64 x 64 midpoint
// rules and unorm16 storage and the quadrature of directionalAlbedo: within 1% + 1e-3 (deterministic).
TEST(BinnedSampling, FresnelMomentsGiveTheTexelAlbedo) {
  const RoughnessBins B{0u, kBins, 1.0f, 0u};
  quadtree::QuadHostScope scope(binTables());
  for (std::uint32_t j : {0u, 1u, 2u, 3u})
    for (float metallic : {0.0f, 0.5f, 1.0f})
      for (double theta : {0.0, 30.0, 60.0, 85.0}) {
        const vec3 base(0.8f, 0.5f, 0.3f);
        BrdfParams p{};
        p.v[0] = vec4(base, metallic);
        p.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] = binRoughness(B, j);
        const vec3 v = qttest::knownDirection(qttest::Case{"gltf_pbr", false, theta, 0});
        const vec2 m = binFresnelMoments(j, v.z, 0.0f);
        const float a1 = quadAlbedo(j, v.z, 0.0f);
        const vec3 f0 = mix(vec3(0.04f), base, metallic);
        const double lf0 = luminance(f0);
        const double d = luminance((vec3(1.0f) - f0) * base) * (1.0 - metallic) * (1.0 - m.y);
        const double s = lf0 * a1 + (1 - lf0) * m.x;
        const double ref = directionalAlbedo(MODEL_GLTF_PBR, p, theta);
        std::printf("r %.3f metallic %.1f theta %4.1f: A1 %.5f A5 %.5f B5 %.5f; diffuse %.5f + specular %.5f = %.5f, "
                    "albedo %.5f\n", binRoughness(B, j), metallic, theta, a1, m.x, m.y, d, s, d + s, ref);
        EXPECT_NEAR(d + s, ref, 0.01 * ref + 1e-3) << "r " << binRoughness(B, j) << " metallic " << metallic << " theta " << theta;
      }
}
