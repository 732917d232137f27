// --param arguments of `albedo` and `sample`: every parameter a scene can set, the command line can
// set, in the NUSSELT_brdf extension's own JSON where a plain name=value cannot say it (lafortune's
// lobes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "brdf/registry.h"
#include "util/error.h"

using namespace nusselt;

namespace {

BrdfParams packOne(const char* model, const std::string& argument) {
  const ModelSpec* m = findModel(model);
  EXPECT_NE(m, nullptr);
  return packParams(*m, {parseParamArgument(argument)}, "--param");
}

}  // namespace

TEST(ParamArguments, LafortuneLobesAsTheExtensionsJson) {
  // The typical set's lobe, written as in a scene file, packs to the typical set's parameters.
  const ModelSpec* m = findModel("lafortune");
  ASSERT_NE(m, nullptr);
  const BrdfParams typical = packParams(*m, typicalParams(*m), "typical");
  NamedParams values = typicalParams(*m);
  auto lobes = std::find_if(values.begin(), values.end(), [](auto& e) { return e.first == "lobes"; });
  ASSERT_NE(lobes, values.end());
  ASSERT_EQ(lobes->second.items.size(), 1u);
  std::string json = "lobes=[[";
  for (int c = 0; c < 4; ++c) json += (c ? "," : "") + std::to_string(lobes->second.items[0].items[c].number);
  json += "]]";
  *lobes = parseParamArgument(json);
  const BrdfParams parsed = packParams(*m, values, "--param");
  // std::to_string keeps 6 decimals: compare within that rounding.
  for (int i = 0; i < BRDF_PARAM_VEC4S; ++i)
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(parsed.v[i][c], typical.v[i][c], 1e-6f) << "param " << 4 * i + c;
  // Two lobes.
  const BrdfParams two = packOne("lafortune", "lobes=[[-1,-1,1,20],[0.5,0.5,0.5,2]]");
  EXPECT_EQ(brdfParam(two, LAFORTUNE_LOBE_COUNT), 2.0f);
}

TEST(ParamArguments, BadJsonIsAnErrorNamingTheArgument) {
  for (const char* bad : {"lobes=[[-1,-1,1,20]", "lobes=[{\"a\":1}]", "lobes=[true]", "lobes=[[[[[[1]]]]]]",
                          "lobes=[[-1,-1,1]]", "lobes=[[-1,-1,1,-5]]"}) {
    try {
      packOne("lafortune", bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::strstr(e.what(), "lobe"), nullptr) << bad << ": " << e.what();
    }
  }
}

TEST(ParamArguments, PlainFormsUnchanged) {
  const BrdfParams a = packOne("lambert", "rho=0.25,0.5,0.75");
  EXPECT_EQ(brdfParam(a, 0), 0.25f);
  EXPECT_EQ(brdfParam(a, 2), 0.75f);
  const BrdfParams b = packOne("lambert", "rho=[0.25,0.5,0.75]");
  EXPECT_EQ(0, std::memcmp(&a, &b, sizeof a));
}
