// The shared inverse trigonometry agrees with the C library to a few ulps over its domain.
#include <gtest/gtest.h>

#include <cmath>

#include "../../shaders/shared/prelude.h"

using namespace nusselt::shared;

TEST(Prelude, PortableInverseTrigonometryIsAccurate) {
  double worst = 0;
  for (int i = -100000; i <= 100000; ++i) {
    float x = float(i) / 100000.0f;
    double e1 = std::fabs(portableAcos(x) - std::acos(double(x))) / std::max(1e-30, std::acos(double(x)));
    double e2 = std::fabs(portableAsin(x) - std::asin(double(x))) / std::max(1e-30, std::fabs(std::asin(double(x))));
    if (x == 0.0f) e2 = std::fabs(portableAsin(x));
    worst = std::max({worst, e1, e2});
  }
  // Relative error of a few float ulps (2^-23 = 1.2e-7), near +-1 included.
  EXPECT_LT(worst, 8 * std::ldexp(1.0, -23));
  for (float y : {-3.0f, -1.0f, -1e-6f, 0.0f, 1e-6f, 0.5f, 2.0f, 1e6f})
    for (float x : {-3.0f, -1.0f, -1e-6f, 0.0f, 1e-6f, 0.5f, 2.0f, 1e6f}) {
      if (x == 0.0f && y == 0.0f) continue;
      EXPECT_NEAR(portableAtan2(y, x), std::atan2(double(y), double(x)), 4e-7 * M_PI) << y << ", " << x;
    }
}

TEST(Prelude, PortableLogIsAccurate) {
  double worst = 0;
  for (float x = 1e-30f; x < 1e30f; x *= 1.0137f) {
    double exact = std::log(double(x));
    worst = std::max(worst, std::fabs(portableLog(x) - exact) / std::max(1e-3, std::fabs(exact)));
  }
  for (int i = 1; i < 100000; ++i) {  // near 1, where the absolute error matters
    float x = 0.5f + float(i) / 66666.0f;
    double exact = std::log(double(x));
    if (exact != 0) worst = std::max(worst, std::fabs(portableLog(x) - exact) / std::fabs(exact));
  }
  EXPECT_LT(worst, 8 * std::ldexp(1.0, -23));
  EXPECT_EQ(portableLog(0.0f), -3.4e38f);
}
