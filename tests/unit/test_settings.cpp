// The render modes' name tables (src/render/settings.h) and the counter list (NUSSELT_STATS in
// shaders/shared/layout.h): every value the shaders test has exactly one name, names parse back to
// their values, and the counters fold, add and visit as one list.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "render/settings.h"

using namespace nusselt;

namespace {

template <class E, std::size_t N>
void expectRoundTrip(const EnumName<E> (&table)[N]) {
  std::set<std::string> names;
  std::set<std::uint32_t> values;
  for (const EnumName<E>& e : table) {
    EXPECT_TRUE(names.insert(e.name).second) << "name " << e.name << " twice";
    EXPECT_TRUE(values.insert(static_cast<std::uint32_t>(e.value)).second) << e.name << ": value twice";
    E parsed{};
    EXPECT_TRUE(parseEnum(table, e.name, parsed)) << e.name;
    EXPECT_EQ(parsed, e.value) << e.name;
    EXPECT_STREQ(enumName(table, e.value), e.name);
  }
  E untouched = table[0].value;
  EXPECT_FALSE(parseEnum(table, "no-such-name", untouched));
  EXPECT_EQ(untouched, table[0].value);
  EXPECT_EQ(enumNames(table).size(), N);
}

}  // namespace

TEST(Settings, NameTablesRoundTrip) {
  expectRoundTrip(kLightingNames);
  expectRoundTrip(kSamplerNames);
  expectRoundTrip(kRngNames);
  expectRoundTrip(kComponentNames);
  expectRoundTrip(kRouletteNames);
}

TEST(Settings, EnumValuesAreTheShadersIds) {
  // The shaders compare Globals fields with these ids: the C++ values are defined from them.
  EXPECT_EQ(static_cast<std::uint32_t>(SamplerKind::Tabulated), SAMPLER_TABULATED);
  EXPECT_EQ(static_cast<std::uint32_t>(LightingMode::BsdfOnly), LIGHTING_BSDF_ONLY);
  EXPECT_EQ(static_cast<std::uint32_t>(RouletteMode::Albedo), ROULETTE_ALBEDO);
  EXPECT_EQ(static_cast<std::uint32_t>(RngMode::Qmc), RNG_QMC);
  EXPECT_EQ(static_cast<std::uint32_t>(ComponentSelection::Uniform), COMPONENTS_UNIFORM);
  EXPECT_EQ(enumNames(kSamplerNames).size(), 5u) << "every strategy of bsdf_sampling.h has a name";
}

TEST(Settings, CountersAreOneList) {
  // The device's counters fold by their STAT_* index into the field of the same entry.
  std::uint32_t device[STAT_COUNT] = {};
  device[shared::STAT_RAYS] = 7;
  device[shared::STAT_SAMPLER_TRIAL_FAILURES] = 2;
  RenderStats s;
  s.addDevice(device);
  EXPECT_EQ(s.rays, 7u);
  EXPECT_EQ(s.samplerTrialFailures, 2u);
  EXPECT_EQ(s.shadowRays, 0u);
  RenderStats t = s;
  t.add(s);
  EXPECT_EQ(t.rays, 14u);
  // forEach visits every counter once, with the header name the record writes.
  std::set<std::string> visited;
  std::uint64_t sum = 0;
  t.forEach([&](const char* name, const char* what, std::uint64_t value) {
    EXPECT_TRUE(visited.insert(name).second) << name;
    EXPECT_GT(std::string(what).size(), 0u) << name;
    sum += value;
  });
  EXPECT_EQ(visited.size(), 6u);
  EXPECT_TRUE(visited.count("rays") && visited.count("samplerBoundViolations"));
  EXPECT_EQ(sum, 18u);
}

// --mlt-restart auto (docs/mlt.md, "Restarts"): a bootstrap pool's worth of samples per pixel,
// rounded up, capped at kMltMaxRestartPaths paths; off for chains without a caustic pass and for
// images whose single sample of every pixel is a larger pool; an explicit value as given.
TEST(Settings, MltRestartAutoResolves) {
  RenderSettings s;
  EXPECT_EQ(mltRestartSpp(s, 256ull * 256), 32u);       // 2^21 / 2^16
  EXPECT_EQ(mltRestartSpp(s, 100ull * 100), 210u);      // ceil(2097152 / 10000)
  EXPECT_EQ(mltRestartSpp(s, 4096ull * 4096), 1u);      // at least one sample
  EXPECT_EQ(mltRestartSpp(s, (1ull << 26) + 1), 0u);    // one sample is too large a pool
  s.mltBootstrap = 1u << 30;
  EXPECT_EQ(mltRestartSpp(s, 256ull * 256), 1024u);     // capped: 2^26 / 2^16
  s.mltBootstrap = 0;
  s.mltChainLight = RADIANCE_INDIRECT;
  EXPECT_EQ(mltRestartSpp(s, 256ull * 256), 0u);
  s.mltChainLight = RADIANCE_CAUSTIC;
  s.mltPassSpp = 0;
  EXPECT_EQ(mltRestartSpp(s, 256ull * 256), 0u);
  s.mltRestart = 7;
  EXPECT_EQ(mltRestartSpp(s, 256ull * 256), 7u);        // explicit: the integrator refuses it without a pass
}
