// The component choice of combined materials (shaders/shared/combined.h) on the CPU: the choice
// follows the albedos (P_k = a_k, the rest ends the walk), non-energy-conserving sets are
// normalised, uniform mode is uniform, and the per-component albedo estimates are the ones the
// docs state (mirror: Fresnel, dielectric: 1, tabulated: interpolated).
#include <gtest/gtest.h>

#include "../../shaders/shared/combined.h"

using namespace nusselt::shared;

namespace {

// Frequencies of combinedPick over a regular grid of u (a deterministic, exact quadrature of
// the choice: each frequency is its probability up to 1 / grid).
void frequencies(uint mode, uint count, vec4 a, double freq[5], vec4& pkSeen) {
  const int grid = 1 << 20;
  for (int i = 0; i < 5; ++i) freq[i] = 0;
  pkSeen = vec4(0.0f);
  for (int i = 0; i < grid; ++i) {
    float u = (i + 0.5f) / grid;
    uint k;
    float pk;
    if (combinedPick(mode, count, a, u, k, pk)) {
      freq[k] += 1.0 / grid;
      pkSeen[k] = pk;
    } else {
      freq[4] += 1.0 / grid;
    }
  }
}

}  // namespace

TEST(CombinedChoice, FollowsTheAlbedosAndEndsWithTheRest) {
  const vec4 a(0.2f, 0.0f, 0.35f, 0.1f);
  double f[5];
  vec4 pk;
  frequencies(COMPONENTS_ALBEDO, 4, a, f, pk);
  const vec4 P = combinedChoiceProbabilities(COMPONENTS_ALBEDO, 4, a);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(f[k], a[k], 1e-5) << k;
    EXPECT_FLOAT_EQ(P[k], a[k]) << k;
    if (a[k] > 0) EXPECT_FLOAT_EQ(pk[k], a[k]) << "the weight must divide by the probability used";
  }
  EXPECT_NEAR(f[4], 1.0 - 0.65, 1e-5) << "the walk ends with probability 1 - sum a";
  // MIS: the probabilities given that the walk continues.
  const vec4 c = combinedMisProbabilities(P);
  EXPECT_NEAR(c.x + c.y + c.z + c.w, 1.0, 1e-6);
  EXPECT_NEAR(c.z, 0.35 / 0.65, 1e-6);
}

TEST(CombinedChoice, NonEnergyConservingSetsAreNormalised) {
  const vec4 a(0.9f, 0.6f, 0.3f, 0.0f);  // sum 1.8
  double f[5];
  vec4 pk;
  frequencies(COMPONENTS_ALBEDO, 3, a, f, pk);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(f[k], a[k] / 1.8, 1e-5) << k;
    EXPECT_NEAR(pk[k], a[k] / 1.8, 1e-6) << k;
  }
  EXPECT_EQ(f[4], 0.0) << "a set with sum > 1 never ends at the choice";
  // The largest u never falls into a rounding gap.
  uint k;
  float p;
  EXPECT_TRUE(combinedPick(COMPONENTS_ALBEDO, 3, a, NUSSELT_ONE_MINUS_EPS, k, p));
  EXPECT_EQ(k, 2u);
}

TEST(CombinedChoice, ProportionalModeNeverEndsTheWalk) {
  // The throughput roulette's choice: P_k = a_k / S whatever S is (here S = 0.65 < 1).
  const vec4 a(0.2f, 0.0f, 0.35f, 0.1f);
  double f[5];
  vec4 pk;
  frequencies(COMPONENTS_PROPORTIONAL, 4, a, f, pk);
  const vec4 P = combinedChoiceProbabilities(COMPONENTS_PROPORTIONAL, 4, a);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(f[k], a[k] / 0.65, 1e-5) << k;
    EXPECT_NEAR(P[k], a[k] / 0.65, 1e-6) << k;
    if (a[k] > 0) EXPECT_FLOAT_EQ(pk[k], P[k]) << "the weight must divide by the probability used";
  }
  EXPECT_EQ(f[4], 0.0) << "the choice never ends the walk: the throughput roulette does";
  uint k;
  float p;
  EXPECT_TRUE(combinedPick(COMPONENTS_PROPORTIONAL, 4, a, NUSSELT_ONE_MINUS_EPS, k, p));
  EXPECT_EQ(k, 3u);
  EXPECT_FALSE(combinedPick(COMPONENTS_PROPORTIONAL, 4, vec4(0.0f), 0.5f, k, p)) << "no component to pick";
  // The modes a render derives from (components, roulette).
  EXPECT_EQ(combinedChoiceMode(COMPONENTS_ALBEDO, ROULETTE_THROUGHPUT), COMPONENTS_PROPORTIONAL);
  EXPECT_EQ(combinedChoiceMode(COMPONENTS_ALBEDO, ROULETTE_ALBEDO), COMPONENTS_ALBEDO);
  EXPECT_EQ(combinedChoiceMode(COMPONENTS_UNIFORM, ROULETTE_THROUGHPUT), COMPONENTS_UNIFORM);
}

TEST(CombinedChoice, MaxChannelChoiceWeights) {
  // Proportional mode weighs a component by the largest channel of its albedo: the table for
  // non-delta models, the largest Fresnel channel for a mirror, 1 for a dielectric.
  GpuComponent c{};
  c.data = vec4(0.5f, 0.0f, 0.0f, 0.0f);
  c.albedoLo = vec4(0.6f);
  c.albedoHi = vec4(0.6f);
  const vec3 wo(0.0f, 0.6f, 0.8f);
  EXPECT_NEAR(componentChoiceMaxAlbedo(MODEL_LAMBERT, c, wo), 0.3f, 1e-6);
  EXPECT_FLOAT_EQ(componentChoiceMaxAlbedo(MODEL_DIELECTRIC, c, wo), 0.5f);
  EXPECT_FLOAT_EQ(componentChoiceMaxAlbedo(MODEL_MIRROR, c, wo),
                  0.5f * maxComponent(mirrorReflectance(c.params, wo.z)));
  EXPECT_EQ(componentChoiceMaxAlbedo(MODEL_LAMBERT, c, vec3(0.0f, 0.0f, -1.0f)), 0.0f);
}

TEST(ThroughputRoulette, NeverAmplifiesAChannel) {
  // Before ROULETTE_MIN_BOUNCE every path goes on unchanged.
  vec3 beta(0.57f, 0.043f, 0.044f);
  EXPECT_TRUE(throughputRoulette(ROULETTE_MIN_BOUNCE - 1u, beta, 1.0f, 0.99f));
  EXPECT_EQ(beta.x, 0.57f);
  // From it on, q = max channel: survivors' largest channel becomes 1, the others stay below it.
  EXPECT_FALSE(throughputRoulette(ROULETTE_MIN_BOUNCE, beta, 1.0f, 0.6f));
  EXPECT_TRUE(throughputRoulette(ROULETTE_MIN_BOUNCE, beta, 1.0f, 0.5f));
  EXPECT_FLOAT_EQ(beta.x, 1.0f);
  EXPECT_LT(beta.y, 0.1f);
  // Unbiased: the expectation over u of the surviving throughput is the throughput.
  const int grid = 1 << 16;
  double mean = 0;
  for (int i = 0; i < grid; ++i) {
    vec3 b(0.3f, 0.1f, 0.2f);
    if (throughputRoulette(ROULETTE_MIN_BOUNCE + 2u, b, 1.0f, (i + 0.5f) / grid)) mean += b.x / grid;
  }
  EXPECT_NEAR(mean, 0.3, 1e-4);
  // Inside glass (etaScale 2.25 undoes the 1/1.5^2 radiance scaling) a path of throughput 0.44 is not
  // killed for being inside.
  vec3 inside(0.44f);
  EXPECT_TRUE(throughputRoulette(ROULETTE_MIN_BOUNCE, inside, 2.25f, 0.98f));
  EXPECT_FLOAT_EQ(transmissionEtaScale(MODEL_LAMBERT, BrdfParams{}, false), 1.0f);
}

TEST(CombinedChoice, UniformModeIsUniform) {
  const vec4 a(0.9f, 0.01f, 0.3f, 0.0f);
  double f[5];
  vec4 pk;
  frequencies(COMPONENTS_UNIFORM, 3, a, f, pk);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(f[k], 1.0 / 3, 1e-5) << k;
    EXPECT_FLOAT_EQ(pk[k], 1.0f / 3) << k;
  }
  EXPECT_EQ(f[3], 0.0);
  EXPECT_EQ(f[4], 0.0);
  EXPECT_FLOAT_EQ(combinedUniformContinuation(a), 1.0f);
  EXPECT_FLOAT_EQ(combinedUniformContinuation(vec4(0.2f, 0.1f, 0.0f, 0.0f)), 0.3f);
}

TEST(CombinedChoice, ComponentAlbedoEstimates) {
  const vec3 wo = normalize(vec3(0.3f, 0.1f, 0.8f));
  GpuComponent c{};
  c.info = uvec4(MODEL_MIRROR, INVALID_INDEX, 0u, 0u);
  c.data = vec4(0.5f, 0.0f, 0.0f, 0.0f);
  c.params.v[0] = vec4(0.96f, 0.96f, 0.96f, 6.69f);  // eta rgb, k.x
  c.params.v[1] = vec4(6.69f, 6.69f, 0.0f, 0.0f);    // k.y, k.z
  EXPECT_FLOAT_EQ(componentChoiceAlbedo(SAMPLER_COSINE, MODEL_MIRROR, c, wo),
                  0.5f * luminance(mirrorReflectance(c.params, wo.z)));
  // A clear dielectric (tint 1) is lossless: exactly its weight; a tinted one reflects R and
  // transmits (1 - R) x the tint's luminance.
  GpuComponent d = c;
  d.params = BrdfParams{};
  d.params.v[0] = vec4(1.5f, 1.0f, 1.0f, 1.0f);  // eta, tint rgb
  EXPECT_EQ(componentChoiceAlbedo(SAMPLER_COSINE, MODEL_DIELECTRIC, d, wo), 0.5f);
  d.params.v[0] = vec4(1.5f, 0.8f, 0.5f, 0.2f);
  const float R = fresnelDielectric(wo.z, 1.5f);
  EXPECT_FLOAT_EQ(componentChoiceAlbedo(SAMPLER_COSINE, MODEL_DIELECTRIC, d, wo),
                  0.5f * (R + (1.0f - R) * luminance(vec3(0.8f, 0.5f, 0.2f))));
  // A tabulated (non-quadtree) component: linear in cos theta between the nodes i / 7.
  c.info.x = MODEL_LAMBERT;
  c.albedoLo = vec4(0.0f, 0.1f, 0.2f, 0.3f);
  c.albedoHi = vec4(0.4f, 0.5f, 0.6f, 0.7f);
  EXPECT_NEAR(componentChoiceAlbedo(SAMPLER_COSINE, MODEL_LAMBERT, c, wo), 0.5f * 0.7f * wo.z, 1e-6);
  EXPECT_NEAR(componentTableAlbedo(c.albedoLo, c.albedoHi, 1.0f), 0.7f, 1e-6);
  EXPECT_NEAR(componentTableAlbedo(c.albedoLo, c.albedoHi, 0.0f), 0.0f, 1e-6);
  // Weight 0 or wo below the surface: never chosen.
  c.data.x = 0.0f;
  EXPECT_EQ(componentChoiceAlbedo(SAMPLER_COSINE, MODEL_LAMBERT, c, wo), 0.0f);
}
