// Punctual lights against their analytic direct illumination, and a scene whose triangle buffer
// alone exceeds lavapipe's 128 MiB storage-buffer binding limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "../support/test_support.h"

using namespace nusselt;

namespace {

const float kRho = 0.5f;

// A floor quad [-2, 2]^2 at z = 0 (normal +z), Lambert rho, seen by an orthographic camera from
// above that covers it exactly, so pixel (x, y) sees the floor square of that pixel.
Scene floorScene(int quadsPerSide = 1) {
  Scene s;
  s.sourcePath = "generated floor";
  s.materials.push_back(catalogueMaterial("lambert", {{"rho", ParamValue::num(kRho)}}, "floor"));
  const float step = 4.0f / quadsPerSide;
  for (int j = 0; j < quadsPerSide; ++j)
    for (int i = 0; i < quadsPerSide; ++i) {
      glm::vec3 a(-2 + i * step, -2 + j * step, 0), b(a.x + step, a.y, 0), c(a.x + step, a.y + step, 0),
          d(a.x, a.y + step, 0);
      for (glm::vec3 p : {a, b, c, a, c, d}) {
        s.positions.push_back(p);
        s.normals.push_back(glm::vec3(0, 0, 1));
      }
      s.triangleMaterial.push_back(0);
      s.triangleMaterial.push_back(0);
    }
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.position = glm::vec3(0, 0, 5);
  s.camera.forward = glm::vec3(0, 0, -1);
  s.camera.up = glm::vec3(0, 1, 0);
  s.camera.xmag = s.camera.ymag = 2.0f;
  return s;
}

// Every pixel's estimate is an average of the exact radiance at jittered points of its footprint,
// so it must lie within the range of the exact radiance over the footprint. The range is taken
// over a 9x9 grid widened by the largest step between grid neighbours (the function is smooth).
void expectWithinFootprint(const Image& img, const std::function<glm::vec3(float, float)>& radiance) {
  int bad = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        float lo = INFINITY, hi = -INFINITY, step = 0;
        float prevRow[9];
        for (int v = 0; v < 9; ++v)
          for (int u = 0; u < 9; ++u) {
            float px = -2.0f + 4.0f * (x + u / 8.0f) / img.width;
            float py = 2.0f - 4.0f * (y + v / 8.0f) / img.height;
            float f = radiance(px, py)[c];
            lo = std::min(lo, f);
            hi = std::max(hi, f);
            if (v > 0) step = std::max(step, std::fabs(f - prevRow[u]));
            prevRow[u] = f;
          }
        float value = img.rgb[3 * (y * img.width + x) + c];
        float slack = step + 1e-5f * hi;
        if (value < lo - slack || value > hi + slack) {
          if (++bad < 5)
            ADD_FAILURE() << "pixel (" << x << ", " << y << ") channel " << c << ": " << value << " outside [" << lo
                          << ", " << hi << "] +- " << slack;
        }
      }
    }
  EXPECT_EQ(bad, 0);
}

RenderSettings directOnly() {
  RenderSettings s;
  s.width = s.height = 24;
  s.spp = 16;
  s.maxDepth = 1;  // direct lighting only: the bounce off the floor escapes
  return s;
}

}  // namespace

TEST(PunctualLights, PointLightMatchesInverseSquareLaw) {
  Scene s = floorScene();
  PunctualLight l;
  l.type = LightType::Point;
  l.position = glm::vec3(0.3f, -0.2f, 1.0f);
  l.intensity = glm::vec3(2.0f, 1.0f, 0.5f);
  s.lights.push_back(l);
  test::Rendered r = test::render(s, directOnly());
  expectWithinFootprint(r.image, [&](float x, float y) {
    glm::vec3 d = l.position - glm::vec3(x, y, 0);
    float d2 = glm::dot(d, d);
    float cosT = d.z / std::sqrt(d2);
    return (kRho / float(M_PI)) * l.intensity * cosT / d2;
  });
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(PunctualLights, SpotLightConeFalloff) {
  Scene s = floorScene();
  PunctualLight l;
  l.type = LightType::Spot;
  l.position = glm::vec3(0.0f, 0.0f, 1.5f);
  l.direction = glm::normalize(glm::vec3(0.2f, 0.0f, -1.0f));
  l.intensity = glm::vec3(3.0f);
  l.innerConeAngle = 0.3f;
  l.outerConeAngle = 0.6f;
  s.lights.push_back(l);
  test::Rendered r = test::render(s, directOnly());
  const float ci = std::cos(l.innerConeAngle), co = std::cos(l.outerConeAngle);
  expectWithinFootprint(r.image, [&](float x, float y) {
    glm::vec3 d = l.position - glm::vec3(x, y, 0);
    float dist = glm::length(d);
    float cd = glm::dot(-d / dist, l.direction);
    float t = std::clamp((cd - co) / (ci - co), 0.0f, 1.0f);
    return (kRho / float(M_PI)) * l.intensity * (t * t) * (d.z / dist) / (dist * dist);
  });
}

TEST(PunctualLights, DirectionalLightIsCosineWeightedIrradiance) {
  Scene s = floorScene();
  PunctualLight l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(glm::vec3(0.3f, 0.2f, -1.0f));
  l.intensity = glm::vec3(1.0f, 2.0f, 3.0f);
  s.lights.push_back(l);
  test::Rendered r = test::render(s, directOnly());
  expectWithinFootprint(r.image, [&](float, float) { return (kRho / float(M_PI)) * l.intensity * -l.direction.z; });
}

TEST(LargeScene, TrianglesBeyondOneStorageBufferBindingStillRender) {
  // 1200 x 1200 quads = 2.88M triangles: 138 MB of intersection data alone (> 128 MiB, the
  // largest storage-buffer binding lavapipe allows). Buffer device addresses make it render; the
  // image must equal the same floor made of two triangles (same pixel jitter, same light).
  const int quads = 1200;
  ASSERT_GT(2.0 * quads * quads * sizeof(shared::GpuTriangle), 128.0 * 1024 * 1024);
  PunctualLight l;
  l.type = LightType::Point;
  l.position = glm::vec3(0.3f, -0.2f, 1.0f);
  l.intensity = glm::vec3(2.0f);
  RenderSettings rs = directOnly();
  rs.spp = 2;
  Scene small = floorScene(1);
  small.lights.push_back(l);
  Image a = test::render(small, rs).image;
  Image b;
  {
    Scene big = floorScene(quads);
    big.lights.push_back(l);
    b = test::render(big, rs).image;
  }
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  for (std::size_t i = 0; i < a.rgb.size(); ++i)
    ASSERT_NEAR(a.rgb[i], b.rgb[i], 1e-4f * std::max(1.0f, a.rgb[i])) << "value " << i;
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(ShadeQueues, EachHitIsShadedByItsOwnModel) {
  // A checkerboard floor of two models (lambert rho 0.2 and minnaert rho 0.8 with k = 1, which
  // is Lambertian too) under a directional light, direct lighting only: every pixel inside a
  // tile has the exact value of its tile. Hits of one subgroup go to different shade queues; if
  // a path were queued for the wrong model's stage, its pixel would take the other value.
  // 11 tiles across 64 pixels: tile edges fall inside subgroups of 8 consecutive pixels.
  const int tiles = 11;
  Scene s = floorScene(tiles);
  s.materials[0] = catalogueMaterial("lambert", {{"rho", ParamValue::num(0.2)}}, "floor");
  s.materials.push_back(catalogueMaterial("minnaert", {{"rho", ParamValue::num(0.8)}, {"k", ParamValue::num(1.0)}}, "minnaert"));
  for (std::size_t t = 0; t < s.triangleMaterial.size(); ++t) {
    int quad = int(t / 2), i = quad % tiles, j = quad / tiles;
    s.triangleMaterial[t] = (i + j) % 2;
  }
  PunctualLight l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(glm::vec3(0.2f, 0.1f, -1.0f));
  l.intensity = glm::vec3(1.0f);
  s.lights.push_back(l);
  RenderSettings rs = directOnly();
  rs.width = rs.height = 64;
  rs.spp = 4;
  test::Rendered r = test::render(s, rs);
  const float cosT = -l.direction.z;
  int checked = 0, wrong = 0;
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x) {
      // Tile of each pixel corner (image rows go down, the floor's y goes up); skip pixels that
      // straddle a tile edge.
      auto tileX = [&](double px) { return int(std::floor(px * tiles / rs.width)); };
      int i = tileX(x + 0.001), j = tiles - 1 - tileX(y + 0.001);
      if (tileX(x + 0.999) != i || tiles - 1 - tileX(y + 0.999) != j) continue;
      float rho = (i + j) % 2 == 0 ? 0.2f : 0.8f;
      float expected = rho / float(M_PI) * cosT;
      float got = r.image.rgb[3 * (y * rs.width + x)];
      ++checked;
      if (std::fabs(got - expected) > 1e-5f * expected) ++wrong;
    }
  EXPECT_GT(checked, 2500);
  EXPECT_EQ(wrong, 0) << "of " << checked << " pixels";
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
  EXPECT_EQ(test::validationMessages(), 0u);
}
