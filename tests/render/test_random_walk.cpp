// The random walk's ideal reflection and refraction (the random-walk source): a mirror shows an
// emitter where geometry puts it with the Fresnel-weighted radiance; a lossless glass sphere in
// a uniform environment is invisible; a glass slab transmits (1 - R) / (1 + R) of the light
// behind it (Fresnel at both faces, all internal reflections summed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/test_support.h"
#include "brdf/registry.h"

using namespace nusselt;

namespace {

using test::addQuad;

void addSphere(Scene& s, glm::vec3 centre, float radius, std::uint32_t material, int nu = 96, int nv = 48) {
  auto p = [&](int i, int j) {
    float u = 2.0f * float(M_PI) * i / nu, v = float(M_PI) * j / nv;
    return glm::vec3(std::sin(v) * std::cos(u), std::cos(v), std::sin(v) * std::sin(u));
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      glm::vec3 q[4] = {p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)};
      int tris[2][3] = {{0, 2, 1}, {0, 3, 2}};  // counter-clockwise seen from outside
      for (auto& t : tris) {
        glm::vec3 a = q[t[0]], b = q[t[1]], c = q[t[2]];
        if (glm::length(glm::cross(b - a, c - a)) < 1e-9f) continue;
        for (glm::vec3 n : {a, b, c}) {
          s.positions.push_back(centre + radius * n);
          s.normals.push_back(glm::cross(b - a, c - a));  // flat: the sphere is a polyhedron
        }
        glm::vec3 fn = glm::normalize(glm::cross(b - a, c - a));
        for (int k = 0; k < 3; ++k) s.normals[s.normals.size() - 1 - k] = fn;
        s.triangleMaterial.push_back(material);
      }
    }
}

}  // namespace

TEST(RandomWalk, MirrorShowsTheEmitterWhereGeometryPutsIt) {
  // Mirror floor z = 0 (aluminium-like, conductor Fresnel), an orthographic camera looking down
  // at 45 degrees along (1, 0, -1); reflected rays travel along (1, 0, 1) and meet a vertical
  // emitter at x = 6 (facing -x) spanning z in [2, 4], y in [-1, 1].
  Scene s;
  s.materials.push_back(catalogueMaterial("mirror", {}, "mirror"));
  s.materials.push_back(catalogueMaterial("lambert", {{"rho", ParamValue::num(0)}}, "emitter", glm::vec3(3.0f, 2.0f, 1.0f)));
  addQuad(s, {-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}, 0);
  addQuad(s, {6, -1, 2}, {6, -1, 4}, {6, 1, 4}, {6, 1, 2}, 1);  // normal -x
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.forward = glm::normalize(glm::vec3(1, 0, -1));
  s.camera.up = glm::normalize(glm::vec3(1, 0, 1));
  s.camera.position = glm::vec3(-5, 0, 5);  // looks at the origin
  s.camera.xmag = s.camera.ymag = 4.0f;
  RenderSettings rs;
  rs.width = rs.height = 48;
  rs.spp = 64;
  rs.maxDepth = 2;
  test::Rendered r = test::render(s, rs);

  // Expected value of a pixel whose whole footprint reflects onto the emitter: F(cos 45) * Le.
  // Lit pixels average F * Le over their samples (under the albedo roulette the walk would go on
  // with probability lum(F) carrying F / lum(F): a binomial average), so they are tested on their
  // mean with its variance; pixels that see no emitter must be exactly 0.
  BrdfParams mp = s.materials[0].params;
  glm::vec3 F = shared::mirrorReflectance(mp, std::sqrt(0.5f));
  const glm::vec3 right = glm::normalize(glm::cross(s.camera.forward, s.camera.up));
  const glm::vec3 up = glm::cross(right, s.camera.forward);
  auto hitsEmitter = [&](float px, float py) {  // pixel coordinates -> does the reflected ray hit it?
    float sx = px / rs.width * 2 - 1, sy = 1 - py / rs.height * 2;
    glm::vec3 o = s.camera.position + sx * 4.0f * right + sy * 4.0f * up;
    float t = -o.z / s.camera.forward.z;                        // to the mirror
    glm::vec3 m = o + t * s.camera.forward;
    if (std::fabs(m.x) > 10 || std::fabs(m.y) > 10) return false;
    glm::vec3 d(s.camera.forward.x, s.camera.forward.y, -s.camera.forward.z);  // reflected
    float t2 = (6 - m.x) / d.x;
    glm::vec3 e = m + t2 * d;
    return e.y > -1 && e.y < 1 && e.z > 2 && e.z < 4;
  };
  int lit = 0, dark = 0, bad = 0;
  double sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
  for (int y = 0; y < rs.height; ++y)
    for (int x = 0; x < rs.width; ++x) {
      bool c00 = hitsEmitter(x, y), c11 = hitsEmitter(x + 1, y + 1), c01 = hitsEmitter(x, y + 1),
           c10 = hitsEmitter(x + 1, y);
      if (c00 != c11 || c00 != c01 || c00 != c10) continue;  // footprint straddles the edge
      const int i = y * rs.width + x;
      for (int c = 0; c < 3; ++c) {
        if (c00) {
          sum[c] += r.image.rgb[3 * i + c];
          var[c] += r.image.variance[3 * i + c];
        } else if (r.image.rgb[3 * i + c] != 0.0f && ++bad < 6) {
          ADD_FAILURE() << "pixel (" << x << ", " << y << ") should see no emitter but has " << r.image.rgb[3 * i + c];
        }
      }
      (c00 ? lit : dark)++;
    }
  for (int c = 0; c < 3; ++c) {
    double expected = F[c] * s.materials[1].emission[c], mean = sum[c] / lit, se = std::sqrt(var[c]) / lit;
    // Without a roulette this early every lit sample is F Le itself (se = 0): the GPU's float Fresnel
    // then differs from this CPU value by rounding only (relative 1e-5 is ~100 float ulps).
    EXPECT_LE(std::fabs(mean - expected), std::max(test::normalQuantileUpper(0.0005 / 3) * se, 1e-5 * expected))
        << "channel " << c << ": mean " << mean << " +- " << se << " vs F Le = " << expected;
  }
  EXPECT_GT(lit, 20);
  EXPECT_GT(dark, 200);
  EXPECT_EQ(bad, 0) << "dark pixels that are not black (of " << dark << ")";
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(RandomWalk, LosslessGlassSphereIsInvisibleInAUniformEnvironment) {
  // Every path through lossless glass escapes with weight exactly 1 (Fresnel choice, the radiance
  // scaling 1/eta^2 on entering undone on leaving), so every pixel equals the environment.
  Scene s;
  s.materials.push_back(catalogueMaterial("dielectric", {{"eta", ParamValue::num(1.5)}}, "glass"));
  addSphere(s, glm::vec3(0), 1.0f, 0);
  s.background = glm::vec3(0.7f, 1.0f, 1.3f);
  s.hasCamera = true;
  s.camera.position = glm::vec3(0, 0, 4);
  s.camera.forward = glm::vec3(0, 0, -1);
  s.camera.yfov = 0.6f;
  RenderSettings rs;
  rs.width = rs.height = 32;
  rs.spp = 16;
  rs.maxDepth = 64;  // internal reflections in a sphere are partial (no total internal reflection)
  test::Rendered r = test::render(s, rs);
  int bad = 0;
  for (int i = 0; i < rs.width * rs.height; ++i)
    for (int c = 0; c < 3; ++c)
      if (std::fabs(r.image.rgb[3 * i + c] - s.background[c]) > 1e-4f * s.background[c]) ++bad;
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(r.stats.nonFiniteSamples, 0u);
}

TEST(RandomWalk, GlassSlabTransmitsFresnelFraction) {
  // A slab (eta 1.5, faces z = 0 and z = -0.2) in front of a large emitter (z = -3, facing +z);
  // the camera looks through it along -z at normal incidence, so R = ((eta-1)/(eta+1))^2 at both
  // faces and the slab transmits T^2 (1 + R^2 + R^4 + ...) = (1 - R) / (1 + R).
  const float eta = 1.5f;
  Scene s;
  s.materials.push_back(catalogueMaterial("dielectric", {{"eta", ParamValue::num(eta)}}, "glass"));
  s.materials.push_back(catalogueMaterial("lambert", {{"rho", ParamValue::num(0)}}, "emitter", glm::vec3(2.0f)));
  addQuad(s, {-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}, 0);          // front face, normal +z
  addQuad(s, {-5, -5, -0.2f}, {-5, 5, -0.2f}, {5, 5, -0.2f}, {5, -5, -0.2f}, 0);  // back, normal -z
  addQuad(s, {-50, -50, -3}, {50, -50, -3}, {50, 50, -3}, {-50, 50, -3}, 1);     // emitter, normal +z
  s.hasCamera = true;
  s.camera.orthographic = true;
  s.camera.position = glm::vec3(0, 0, 2);
  s.camera.forward = glm::vec3(0, 0, -1);
  s.camera.xmag = s.camera.ymag = 1.0f;
  RenderSettings rs;
  rs.width = rs.height = 16;
  rs.spp = 256;
  rs.maxDepth = 64;
  rs.lighting = LightingMode::BsdfOnly;  // delta surfaces only: no light sampling either way
  test::Rendered r = test::render(s, rs);
  const double R = std::pow((eta - 1) / (eta + 1), 2.0), expected = 2.0 * (1 - R) / (1 + R);
  double sum = 0, var = 0;
  const int n = rs.width * rs.height;
  for (int i = 0; i < n; ++i) {
    sum += r.image.rgb[3 * i];
    var += r.image.variance[3 * i];
  }
  double mean = sum / n, se = std::sqrt(var) / n;
  // Two-sided test at significance 0.001.
  EXPECT_LT(std::fabs(mean - expected), test::normalQuantileUpper(0.0005) * se)
      << "mean " << mean << " +- " << se << ", expected " << expected << " (R = " << R << ")";
  EXPECT_EQ(test::validationMessages(), 0u);
}
