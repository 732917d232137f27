// quadtree::constantInSampledDirection: which BRDFs renders sample by cosine under the quadtree,
// because their tree would be the uniform disc (docs/sampler.md, "Constant BRDFs"). Exactly the
// BRDFs that do not depend on the sampled direction pass: lambert, and oren_nayar at sigma = 0
// (its formula reduces to rho / pi); every other model's typical and hard parameter sets fail, so
// none of them loses its tree.
#include <gtest/gtest.h>

#include "brdf/registry.h"
#include "quadtree/sampler_tables.h"

using namespace nusselt;

namespace {

shared::BrdfParams presetParams(const ModelSpec& m, bool hard) {
  return packParams(m, hard ? hardParams(m) : typicalParams(m), m.name);
}

}  // namespace

TEST(ConstantBrdf, LambertAndSmoothOrenNayarAreConstant) {
  const ModelSpec& lambert = *findModel("lambert");
  EXPECT_TRUE(quadtree::constantInSampledDirection(lambert.id, presetParams(lambert, false)));
  EXPECT_TRUE(quadtree::constantInSampledDirection(lambert.id, presetParams(lambert, true)));
  const ModelSpec& on = *findModel("oren_nayar");
  NamedParams smooth = typicalParams(on);
  bool found = false;
  for (auto& [name, value] : smooth)
    if (name == "sigma") value = ParamValue::num(0.0), found = true;
  ASSERT_TRUE(found) << "oren_nayar has no parameter sigma";
  EXPECT_TRUE(quadtree::constantInSampledDirection(on.id, packParams(on, smooth, "oren_nayar sigma 0")));
}

TEST(ConstantBrdf, EveryOtherModelKeepsItsTree) {
  int checked = 0;
  for (const ModelSpec& m : allModels()) {
    if (m.name == "lambert") continue;
    for (bool hard : {false, true}) {
      EXPECT_FALSE(quadtree::constantInSampledDirection(m.id, presetParams(m, hard)))
          << m.name << (hard ? " hard" : " typical");
      ++checked;
    }
  }
  EXPECT_GE(checked, 2 * 20);  // the model list is not empty
}
