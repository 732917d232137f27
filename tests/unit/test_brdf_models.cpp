// test_brdf_models.cpp: the reflectance models of shaders/shared/brdf/ on the CPU: finiteness,
// non-negativity, reciprocity, isotropy, directional albedo (energy and closed forms, two
// independent quadratures), the delta models' Fresnel functions and parameter validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "brdf/albedo.h"
#include "brdf/registry.h"
#include "util/error.h"

namespace nusselt {
namespace {

using shared::vec3;

struct NamedSet {
  const ModelSpec* model;
  std::string set;  // "typical", "hard" or a variant name
  BrdfParams params;
};

std::vector<NamedSet> allSets(bool includeDelta = false) {
  std::vector<NamedSet> out;
  for (const ModelSpec& m : allModels()) {
    if (m.delta && !includeDelta) continue;
    out.push_back({&m, "typical", packParams(m, typicalParams(m), m.name + " typical")});
    out.push_back({&m, "hard", packParams(m, hardParams(m), m.name + " hard")});
    for (const auto& [name, values] : m.variants) out.push_back({&m, name, packParams(m, values, m.name + " " + name)});
  }
  return out;
}

std::pair<std::string, ParamValue> N_(const char* name, double v) { return {name, ParamValue::num(v)}; }

std::string label(const NamedSet& s) { return s.model->name + "/" + s.set; }

vec3 dirFromAngles(double theta, double phi) {
  return vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

// Random directions above the surface, with the special cases: the normal, within 1e-4 rad of
// grazing, near the mirror direction of each other.
struct DirectionPairs {
  std::vector<std::pair<vec3, vec3>> pairs;
  explicit DirectionPairs(unsigned seed, int n = 400) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const double halfPi = 0.5 * M_PI;
    auto randomTheta = [&]() {
      double r = U(rng);
      if (r < 0.1) return 0.0;
      if (r < 0.2) return halfPi - 1e-4 * U(rng) - 1e-6;
      if (r < 0.3) return halfPi - 0.05 * U(rng) - 1e-6;
      return std::acos(std::max(1e-4, U(rng)));
    };
    for (int i = 0; i < n; ++i) {
      double ti = randomTheta(), pi = 2 * M_PI * U(rng);
      double to = randomTheta(), po = 2 * M_PI * U(rng);
      if (i % 4 == 0) {  // near the mirror direction
        to = ti + 0.01 * (U(rng) - 0.5);
        to = std::min(std::max(to, 0.0), halfPi - 1e-6);
        po = pi + M_PI + 0.02 * (U(rng) - 0.5);
      }
      pairs.push_back({dirFromAngles(ti, pi), dirFromAngles(to, po)});
    }
    pairs.push_back({vec3(0, 0, 1), vec3(0, 0, 1)});
    pairs.push_back({dirFromAngles(halfPi - 1e-4, 0.0), dirFromAngles(halfPi - 1e-4, M_PI)});
    pairs.push_back({dirFromAngles(halfPi - 1e-4, 0.0), dirFromAngles(halfPi - 1e-4, 0.0)});
    pairs.push_back({vec3(0, 0, 1), dirFromAngles(halfPi - 1e-4, 1.0)});
  }
};

vec3 eval(const NamedSet& s, vec3 wi, vec3 wo) { return shared::brdfEval(s.model->id, s.params, wi, wo); }

TEST(BrdfModelEval, RegistryIsComplete) {
  std::set<std::uint32_t> ids;
  for (const ModelSpec& m : allModels()) {
    EXPECT_LT(m.id, MODEL_COUNT) << m.name;
    EXPECT_TRUE(ids.insert(m.id).second) << m.name;
    EXPECT_EQ(findModel(m.name), &m);
    EXPECT_EQ(&modelById(m.id), &m);
    EXPECT_EQ(m.delta, shared::modelIsDelta(m.id)) << m.name;
    EXPECT_FALSE(m.typical.empty()) << m.name;
    EXPECT_FALSE(m.hard.empty()) << m.name;
  }
  EXPECT_EQ(MODEL_LAMBERT, 0u);
}

// The defaults are the catalogue's typical set.
TEST(BrdfModelEval, DefaultsAreTheTypicalSet) {
  for (const ModelSpec& m : allModels()) {
    BrdfParams a = packParams(m, {}, m.name);
    BrdfParams b = packParams(m, typicalParams(m), m.name);
    for (int i = 0; i < 32; ++i)
      EXPECT_FLOAT_EQ(shared::brdfParam(a, i), shared::brdfParam(b, i)) << m.name << " float " << i;
  }
}

// Every parameter at the ends of its range (the others typical), and every choice: finite and
// non-negative everywhere, including normal incidence and grazing.
TEST(BrdfModelEval, ExtremeParametersStayFinite) {
  DirectionPairs dirs(21, 150);
  for (const ModelSpec& m : allModels()) {
    if (m.delta) continue;
    std::vector<NamedParams> variants;
    for (const ParamSpec& p : m.params) {
      std::vector<double> values;
      if (p.kind == ParamKind::Choice) {
        for (size_t c = 0; c < p.choices.size(); ++c) values.push_back(double(c));
      } else if (p.kind != ParamKind::Lobes) {
        values = {p.minExclusive ? p.minValue + 1e-3 * (p.maxValue - p.minValue) : p.minValue, p.maxValue};
      }
      for (double v : values) {
        NamedParams np = m.typical;
        for (auto& [n, val] : np)
          if (n == p.name) val = ParamValue::num(v);
        bool present = false;
        for (auto& [n, val] : np) present = present || n == p.name;
        if (!present) np.push_back({p.name, ParamValue::num(v)});
        variants.push_back(np);
      }
    }
    for (const NamedParams& np : variants) {
      BrdfParams params = packParams(m, np, m.name);
      int bad = 0;
      for (const auto& [wi, wo] : dirs.pairs) {
        vec3 f = shared::brdfEval(m.id, params, wi, wo);
        for (int c = 0; c < 3; ++c)
          if ((!std::isfinite(f[c]) || f[c] < 0.0f) && bad++ < 2) {
            std::string desc;
            for (const auto& [n, v] : np) desc += n + "=" + (v.kind == ParamValue::Kind::Number ? std::to_string(v.number) : v.text) + " ";
            ADD_FAILURE() << m.name << " " << desc << ": f = " << f[c] << " wi.z " << wi.z << " wo.z " << wo.z;
          }
      }
    }
  }
}

TEST(BrdfModelEval, FiniteAndNonNegative) {
  DirectionPairs dirs(1);
  for (const NamedSet& s : allSets()) {
    int bad = 0;
    for (const auto& [wi, wo] : dirs.pairs) {
      for (int swap = 0; swap < 2; ++swap) {
        vec3 f = swap ? eval(s, wo, wi) : eval(s, wi, wo);
        for (int c = 0; c < 3; ++c)
          if (!std::isfinite(f[c]) || f[c] < 0.0f) {
            if (bad++ < 3)
              ADD_FAILURE() << label(s) << ": f = " << f[c] << " at wi = (" << wi.x << ", " << wi.y << ", " << wi.z
                            << "), wo = (" << wo.x << ", " << wo.y << ", " << wo.z << ")";
          }
      }
    }
    // Below the surface: zero, unless the model transmits (ModelSpec::transmits; its own tests in
    // test_rough_dielectric.cpp): then positive across the surface.
    vec3 down(0.3f, 0.1f, -0.9486833f);
    if (s.model->transmits) {
      EXPECT_GT(shared::maxComponent(eval(s, down, vec3(0, 0, 1))), 0.0f) << label(s);
      EXPECT_GT(shared::maxComponent(eval(s, vec3(0, 0, 1), down)), 0.0f) << label(s);
      continue;
    }
    EXPECT_EQ(shared::maxComponent(eval(s, down, vec3(0, 0, 1))), 0.0f) << label(s);
    EXPECT_EQ(shared::maxComponent(eval(s, vec3(0, 0, 1), down)), 0.0f) << label(s);
  }
}

// f(u, v) = f(v, u) for every model except strauss. Tolerance: 2e-3 relative (float directions
// carry ~1e-7 of error, which a cos^n lobe with n = 20000 amplifies n-fold) plus 1e-6 absolute.
TEST(BrdfModelEval, Reciprocity) {
  DirectionPairs dirs(2);
  for (const NamedSet& s : allSets()) {
    if (s.model->name == "strauss") continue;
    int bad = 0;
    for (const auto& [wi, wo] : dirs.pairs) {
      vec3 a = eval(s, wi, wo), b = eval(s, wo, wi);
      for (int c = 0; c < 3; ++c) {
        double tol = 2e-3 * std::max(std::abs(a[c]), std::abs(b[c])) + 1e-6;
        if (std::abs(a[c] - b[c]) > tol && bad++ < 3)
          ADD_FAILURE() << label(s) << ": f(wi,wo) = " << a[c] << " f(wo,wi) = " << b[c] << " wi.z = " << wi.z
                        << " wo.z = " << wo.z;
      }
    }
  }
}

// Strauss is not reciprocal: make sure the test above would see it.
TEST(BrdfModelEval, StraussIsNotReciprocal) {
  const ModelSpec* m = findModel("strauss");
  ASSERT_NE(m, nullptr);
  BrdfParams p = packParams(*m, typicalParams(*m), "strauss");
  vec3 wi = dirFromAngles(1.2, 0.0), wo = dirFromAngles(1.0, M_PI);
  float a = shared::brdfEval(m->id, p, wi, wo).x, b = shared::brdfEval(m->id, p, wo, wi).x;
  EXPECT_GT(std::abs(a - b), 0.05f * std::max(a, b));
}

bool isotropicSet(const NamedSet& s) {
  const std::string& n = s.model->name;
  if (n == "poulin_fournier") return false;
  if (n == "ward") return shared::brdfParam(s.params, WARD_AX) == shared::brdfParam(s.params, WARD_AY);
  if (n == "ashikhmin_shirley")
    return shared::brdfParam(s.params, ASHIKHMIN_SHIRLEY_NU) == shared::brdfParam(s.params, ASHIKHMIN_SHIRLEY_NV);
  if (n == "schlick") return shared::brdfParam(s.params, SCHLICK_P) == 1.0f;
  if (n == "lafortune") {
    int count = int(shared::brdfParam(s.params, LAFORTUNE_LOBE_COUNT));
    for (int j = 0; j < count; ++j)
      if (shared::brdfParam(s.params, LAFORTUNE_LOBES + 4 * j) != shared::brdfParam(s.params, LAFORTUNE_LOBES + 4 * j + 1))
        return false;
  }
  return true;
}

vec3 rotateZ(vec3 w, double a) {
  double c = std::cos(a), s = std::sin(a);
  return vec3(float(c * w.x - s * w.y), float(s * w.x + c * w.y), w.z);
}

// Rotating both directions about the normal changes nothing for the isotropic models (same
// tolerance as reciprocity), and does change the anisotropic ones.
TEST(BrdfModelEval, Isotropy) {
  DirectionPairs dirs(3);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 2 * M_PI);
  for (const NamedSet& s : allSets()) {
    bool iso = isotropicSet(s);
    int bad = 0;
    double maxChange = 0;
    for (const auto& [wi, wo] : dirs.pairs) {
      double a = U(rng);
      vec3 f = eval(s, wi, wo), g = eval(s, rotateZ(wi, a), rotateZ(wo, a));
      for (int c = 0; c < 3; ++c) {
        double diff = std::abs(f[c] - g[c]), scale = std::max(std::abs(f[c]), std::abs(g[c]));
        maxChange = std::max(maxChange, diff / (scale + 1e-6));
        if (iso && diff > 2e-3 * scale + 1e-6 && bad++ < 3)
          ADD_FAILURE() << label(s) << ": rotated f = " << g[c] << " vs " << f[c];
      }
    }
    if (!iso) {
      EXPECT_GT(maxChange, 1e-2) << label(s) << " should be anisotropic";
    }
  }
}

// ---- Directional albedo -------------------------------------------------------------------------

const double kAngles[] = {0.0, 30.0, 60.0, 80.0, 89.0};

// Sets that the catalogue (or the model's design) declares energy conserving.
bool energyConserving(const NamedSet& s) {
  const std::string& n = s.model->name;
  if (n == "minnaert") return shared::brdfParam(s.params, MINNAERT_K) >= 1.0f;
  if (n == "schlick") return shared::brdfParam(s.params, SCHLICK_MULTIPLE) == 0.0f;
  if (n == "strauss") return s.set == "hard";
  if (n == "beard_maxwell") return false;
  if (n == "ward") return shared::brdfParam(s.params, WARD_NORMALIZATION) != float(WARD_NORM_DUER);
  return true;
}

// Runs fn(0 .. n-1) on all hardware threads (the albedo cases take 5 ms to a few s each).
template <class F>
void parallelFor(int n, const F& fn) {
  std::atomic<int> next{0};
  auto worker = [&]() {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  std::vector<std::thread> threads;
  unsigned count = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  for (unsigned t = 1; t < count; ++t) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
}

struct AlbedoCase {
  const NamedSet* set;
  double theta, phi;
  double a = 0, b = 0;  // ThetaOuter, PhiOuter
};

void runCases(std::vector<AlbedoCase>& cases) {
  parallelFor(static_cast<int>(cases.size()), [&](int i) {
    AlbedoCase& c = cases[i];
    c.a = directionalAlbedo(c.set->model->id, c.set->params, c.theta, c.phi, AlbedoMethod::ThetaOuter);
    c.b = directionalAlbedo(c.set->model->id, c.set->params, c.theta, c.phi, AlbedoMethod::PhiOuter);
  });
}

// Every set at theta = 0, 30, 60, 80, 89 (phi_i = 0); the anisotropic ones also at phi_i = 90
// degrees (theta = 60, 89; at theta = 0 the azimuth does not matter). Both quadratures must agree
// to 1e-4 relative; the energy-conserving sets must stay <= 1 + 1e-4. The values are printed
// ([albedo] lines: docs/models.md quotes them).
TEST(BrdfModelAlbedo, EnergyAndQuadratureAgreement) {
  std::vector<NamedSet> sets = allSets();
  std::vector<AlbedoCase> cases;
  for (const NamedSet& s : sets) {
    for (double th : kAngles) cases.push_back({&s, th, 0.0});
    if (!isotropicSet(s))
      for (double th : {60.0, 89.0}) cases.push_back({&s, th, 90.0});
  }
  runCases(cases);
  for (const AlbedoCase& c : cases) {
    const NamedSet& s = *c.set;
    EXPECT_TRUE(std::isfinite(c.a)) << label(s) << " theta " << c.theta;
    EXPECT_NEAR(c.a, c.b, 1e-4 * std::abs(c.a) + 1e-9)
        << label(s) << " theta " << c.theta << " phi " << c.phi << ": quadratures disagree";
    if (energyConserving(s)) {
      EXPECT_LE(c.a, 1.0 + 1e-4) << label(s) << " theta " << c.theta << " phi " << c.phi;
    }
    std::printf("[albedo] %-18s %-14s theta=%4.0f phi=%3.0f  a=%.6f  (other quadrature %.6f, rel. diff. %.1e)\n",
                s.model->name.c_str(), s.set.c_str(), c.theta, c.phi, c.a, c.b,
                std::abs(c.a - c.b) / std::max(std::abs(c.a), 1e-300));
  }
}

double albedoOf(const char* model, const NamedParams& values, double th) {
  const ModelSpec* m = findModel(model);
  EXPECT_NE(m, nullptr) << model;
  return directionalAlbedo(m->id, packParams(*m, values, model), th);
}

TEST(BrdfModelAlbedo, ClosedForms) {
  for (double th : kAngles) {
    EXPECT_NEAR(albedoOf("lambert", {{"rho", ParamValue::num(0.8)}}, th), 0.8, 1e-6);
    for (double k : {0.5, 0.8, 1.0, 1.7}) {
      const double expect = 0.9 * std::pow(std::cos(th * M_PI / 180), k - 1);
      EXPECT_NEAR(albedoOf("minnaert", {{"rho", ParamValue::num(0.9)}, {"k", ParamValue::num(k)}}, th), expect,
                  1e-4 * expect)
          << "k = " << k << " theta " << th;
    }
  }
  for (double n : {0.0, 1.0, 50.0, 10000.0}) {
    NamedParams p = {{"kd", ParamValue::num(0.3)}, {"ks", ParamValue::num(0.6)}, {"n", ParamValue::num(n)}};
    EXPECT_NEAR(albedoOf("phong", p, 0.0), 0.9, 1e-4) << "n = " << n;
    EXPECT_NEAR(albedoOf("lewis", p, 0.0), 0.9, 1e-4) << "n = " << n;
    EXPECT_NEAR(albedoOf("phong_specular", {{"ks", ParamValue::num(2.0)}, {"n", ParamValue::num(n)}}, 0.0),
                2.0 * 2 * M_PI / (n + 2), 1e-4 * 4 * M_PI / (n + 2))
        << "n = " << n;
  }
  for (double n : {0.0, 1.0, 7.0, 100.0, 20000.0}) {
    NamedParams p = {{"kd", ParamValue::num(0.3)}, {"ks", ParamValue::num(0.6)}, {"n", ParamValue::num(n)}};
    EXPECT_NEAR(albedoOf("blinn", p, 0.0), 0.9, 1e-4) << "n = " << n;
  }
  // coupled: total albedo = a_s + rd (1 - a_s) <= 1 by construction; a white rd = 1 with f0 = 0
  // must be close to 1 (the table interpolation error only).
  for (double m : {0.2, 0.02}) {
    NamedParams p = {{"rd", ParamValue::num(1.0)}, {"f0", ParamValue::num(0.5)}, {"m", ParamValue::num(m)}};
    for (double th : {0.0, 30.0, 60.0, 80.0})
      EXPECT_NEAR(albedoOf("coupled", p, th), 1.0, 5e-3) << "m = " << m << " theta " << th;
  }
}

// RGB: each channel is the formula with that channel's parameters; the luminance is what the
// albedo function integrates.
TEST(BrdfModelEval, ColourChannels) {
  const ModelSpec* m = findModel("phong");
  ParamValue kd;
  kd.kind = ParamValue::Kind::Array;
  kd.items = {ParamValue::num(0.1), ParamValue::num(0.4), ParamValue::num(0.2)};
  BrdfParams p = packParams(*m, {{"kd", kd}, {"ks", ParamValue::num(0.3)}}, "phong");
  double rgb[3];
  directionalAlbedoRgb(m->id, p, 0.0, 0.0, rgb);
  EXPECT_NEAR(rgb[0], 0.4, 1e-5);
  EXPECT_NEAR(rgb[1], 0.7, 1e-5);
  EXPECT_NEAR(rgb[2], 0.5, 1e-5);
  EXPECT_NEAR(directionalAlbedo(m->id, p, 0.0), 0.2126 * 0.4 + 0.7152 * 0.7 + 0.0722 * 0.5, 1e-5);
}

// glTF: against a direct double-precision transcription of the specification's appendix B.
TEST(BrdfModelEval, GltfMatchesSpecification) {
  const ModelSpec* m = findModel("gltf_pbr");
  DirectionPairs dirs(5, 200);
  for (double metallic : {0.0, 0.4, 1.0})
    for (double rough : {0.1, 0.5, 1.0}) {
      BrdfParams p = packParams(*m, {{"baseColor", ParamValue::num(0.7)}, {"metallic", ParamValue::num(metallic)},
                                     {"roughness", ParamValue::num(rough)}}, "gltf");
      for (const auto& [wi, wo] : dirs.pairs) {
        if (wi.z < 1e-3f || wo.z < 1e-3f) continue;
        double hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z, hl = std::sqrt(hx * hx + hy * hy + hz * hz);
        hx /= hl, hy /= hl, hz /= hl;
        double a = rough * rough, a2 = a * a, nl = wi.z, nv = wo.z, vh = wo.x * hx + wo.y * hy + wo.z * hz;
        double D = a2 / (M_PI * std::pow(hz * hz * (a2 - 1) + 1, 2));
        double V = 1 / ((nl + std::sqrt(a2 + (1 - a2) * nl * nl)) * (nv + std::sqrt(a2 + (1 - a2) * nv * nv)));
        double f0 = 0.04 + (0.7 - 0.04) * metallic, F = f0 + (1 - f0) * std::pow(1 - std::abs(vh), 5);
        double f = (1 - F) * 0.7 * (1 - metallic) / M_PI + F * D * V;
        EXPECT_NEAR(shared::brdfEval(m->id, p, wi, wo).x, f, 2e-3 * f + 1e-6);
      }
    }
}

// HTSG: the bounded series (at most HTSG_MAX_TERMS terms, strided for large g) against a plain
// double-precision sum of all terms, and the geometric-optics limit of the catalogue (2.15):
// for g >> 1 f_dd -> Fr Dbeck(h; 2 sigma / tau) S(ti) S(to) / (4 ci co).
TEST(BrdfModelEval, HtsgSeriesAndGeometricLimit) {
  const ModelSpec* m = findModel("htsg");
  BrdfParams p = packParams(*m, hardParams(*m), "htsg");
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<double> ratio;
  for (int i = 0; i < 1000; ++i) {
    double g = std::pow(10.0, -1.0 + 3.5 * U(rng)), c = g * 5.0 * U(rng) * U(rng);
    double brute = 0;
    for (int k = 1; k < 20000; ++k) brute += std::exp(k * std::log(g) - g - std::lgamma(k + 1.0) - std::log(double(k)) - c / k);
    if (brute > 1e-30) {
      EXPECT_NEAR(shared::htsgSeries(float(g), float(c)), brute, 1e-3 * brute) << "g " << g << " c " << c;
    }
    double ti = std::acos(0.2 + 0.8 * U(rng)), to = std::acos(0.2 + 0.8 * U(rng));
    vec3 wi = dirFromAngles(ti, 0.0), wo = dirFromAngles(to, 2 * M_PI * U(rng));
    vec3 h = shared::brdfHalf(wi, wo);
    float sigma = shared::htsgSigma(wi.z, wo.z, 4.0f, 0.8f);
    double ct = shared::fresnelComplex(shared::brdfHalfCos(wi, wo), 1.5f, 0.0f) *
                shared::beckmannD(h, 2.0f * sigma / 4.0f) * shared::htsgShadow(wi.z, 4.0f, 0.8f) *
                shared::htsgShadow(wo.z, 4.0f, 0.8f) / (4.0 * wi.z * wo.z);
    if (ct > 1e-3) ratio.push_back(shared::htsgEval(p, wi, wo).x / ct);
  }
  std::sort(ratio.begin(), ratio.end());
  ASSERT_GT(ratio.size(), 100u);
  EXPECT_NEAR(ratio[ratio.size() / 2], 1.0, 0.01);
  EXPECT_GT(ratio[ratio.size() / 50], 0.95);
  EXPECT_LT(ratio[ratio.size() * 49 / 50], 1.12);
  // The delta part: a smooth surface puts most energy into the spike; total <= 1.
  BrdfParams smooth = packParams(*m, m->variants[0].second, "htsg smooth");
  for (double th : {0.0, 30.0, 60.0, 80.0}) {
    double spike = shared::htsgSpecularReflectance(smooth, float(std::cos(th * M_PI / 180)));
    double dd = directionalAlbedo(m->id, smooth, th);
    EXPECT_LE(spike + dd, 1.0) << th;
    std::printf("[htsg smooth] theta=%4.0f  rho_sp=%.6f  a_dd=%.6f\n", th, spike, dd);
  }
  EXPECT_LT(shared::htsgSpecularReflectance(p, 1.0f), 1e-30f);
}

// Poulin-Fournier against a brute-force version of its definition: midpoint rule over the
// profile (arc and gap) with every point's visibility found by intersecting rays with the
// neighbouring cylinders (k = -3..3 periods), all in double precision.
double poulinFournierBrute(double kd, double ks, double n, double d, double h, vec3 wi, vec3 wo) {
  const double a = std::sqrt(1 - h * h), W = 2 * a + d, psiMax = std::acos(-h);
  auto visible = [&](double y, double z, vec3 w, bool onArc0) {
    for (int k = -3; k <= 3; ++k) {
      if (k == 0 && onArc0) continue;  // a point of cylinder 0: self-shadowing is max(0, nu.w)
      double cy = k * W, cz = h, py = y - cy, pz = z - cz;
      double uy = w.y, uz = w.z, uu = uy * uy + uz * uz;
      double b = py * uy + pz * uz, c = py * py + pz * pz - 1.0, disc = b * b - uu * c;
      if (disc > 0 && (-b + std::sqrt(disc)) / uu > 1e-12) return false;
    }
    return true;
  };
  auto floc = [&](double ny, double nz) {
    double ni = wi.y * ny + wi.z * nz, no = wo.y * ny + wo.z * nz;
    if (ni <= 0 || no <= 0) return 0.0;
    double ca = 2 * ni * no - (double(wi.x) * wo.x + double(wi.y) * wo.y + double(wi.z) * wo.z);
    return (kd / M_PI + ks * (n + 2) / (2 * M_PI) * (ca > 0 ? std::pow(ca, n) : 0.0)) * ni * no;
  };
  double sum = 0;
  const int NA = 200000, NF = 20000;
  for (int i = 0; i < NA; ++i) {
    double psi = -psiMax + (i + 0.5) * 2 * psiMax / NA;
    double y = std::sin(psi), z = h + std::cos(psi);
    double v = floc(std::sin(psi), std::cos(psi));
    if (v > 0 && visible(y, z, wi, true) && visible(y, z, wo, true)) sum += v * 2 * psiMax / NA;
  }
  for (int i = 0; i < NF && d > 0; ++i) {
    double y = a + (i + 0.5) * d / NF;
    double v = floc(0, 1);
    if (v > 0 && visible(y, 0, wi, false) && visible(y, 0, wo, false)) sum += v * d / NF;
  }
  return sum / (W * wi.z * wo.z);
}

TEST(BrdfModelEval, PoulinFournierMatchesBruteForce) {
  const ModelSpec* m = findModel("poulin_fournier");
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> U(0, 1);
  struct Case { double kd, ks, n, d, h; } cases[] = {{0.3, 0.6, 40, 0.5, 0}, {0.0, 1.0, 400, 0, 0}, {0.5, 0.5, 10, 1.0, -0.5},
                                                     {0.2, 0.7, 100, 0.3, -0.25}};
  for (const Case& c : cases) {
    BrdfParams p = packParams(*m, {N_("kd", c.kd), N_("ks", c.ks), N_("n", c.n), N_("d", c.d), N_("h", c.h)}, "pf");
    for (int i = 0; i < 12; ++i) {
      vec3 wi = dirFromAngles(std::acos(0.05 + 0.95 * U(rng)), 2 * M_PI * U(rng));
      vec3 wo = dirFromAngles(std::acos(0.05 + 0.95 * U(rng)), 2 * M_PI * U(rng));
      if (i % 3 == 0) wo = vec3(-wi.x, wo.y, wo.z * 0 + std::sqrt(std::max(0.0025f, 1 - wi.x * wi.x - wo.y * wo.y)));
      wo = shared::normalize(wo);
      double ref = poulinFournierBrute(c.kd, c.ks, c.n, c.d, c.h, wi, wo);
      double f = shared::brdfEval(m->id, p, wi, wo).x;
      EXPECT_NEAR(f, ref, 2e-3 * ref + 1e-5) << "n " << c.n << " d " << c.d << " h " << c.h << " wi (" << wi.x << ", "
                                             << wi.y << ", " << wi.z << ") wo (" << wo.x << ", " << wo.y << ", " << wo.z << ")";
    }
  }
}

// ---- Delta models -------------------------------------------------------------------------------

TEST(BrdfModelDelta, EvalIsZeroAndFlagged) {
  DirectionPairs dirs(4, 50);
  for (const NamedSet& s : allSets(true)) {
    if (!s.model->delta) continue;
    EXPECT_TRUE(shared::modelIsDelta(s.model->id));
    for (const auto& [wi, wo] : dirs.pairs) EXPECT_EQ(shared::maxComponent(eval(s, wi, wo)), 0.0f);
    EXPECT_EQ(directionalAlbedo(s.model->id, s.params, 30.0), 0.0);
  }
}

TEST(BrdfModelDelta, MirrorFresnel) {
  const ModelSpec* m = findModel("mirror");
  BrdfParams p = packParams(*m, hardParams(*m), "mirror");
  double n = 0.2, k = 3.0;
  EXPECT_NEAR(shared::mirrorReflectance(p, 1.0f).x, ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k), 1e-5);
  EXPECT_NEAR(shared::mirrorReflectance(p, 0.0f).x, 1.0, 1e-5);
  for (float c = 0.0f; c <= 1.0f; c += 0.01f) {
    float r = shared::mirrorReflectance(p, c).x;
    EXPECT_TRUE(r >= 0.0f && r <= 1.0f) << c;
  }
  // Against the complex-arithmetic definition of the catalogue (section 0).
  for (double c : {0.05, 0.3, 0.7, 0.99}) {
    std::complex<double> e(0.96, 6.69), ct = std::sqrt(1.0 - (1 - c * c) / (e * e));
    double rs = std::norm((c - e * ct) / (c + e * ct)), rp = std::norm((e * c - ct) / (e * c + ct));
    EXPECT_NEAR(shared::fresnelComplex(float(c), 0.96f, 6.69f), 0.5 * (rs + rp), 1e-5) << c;
  }
}

TEST(BrdfModelDelta, DielectricFresnelAndRefraction) {
  const float eta = 1.5f;
  EXPECT_NEAR(shared::dielectricReflectance(eta, vec3(0, 0, 1)), 0.04, 1e-6);
  EXPECT_NEAR(shared::dielectricReflectance(eta, vec3(0, 0, -1)), 0.04, 1e-6);
  for (double th = 0.0; th < 89.9; th += 7.3) {
    vec3 w = dirFromAngles(th * M_PI / 180, 0.4);
    vec3 t;
    ASSERT_TRUE(shared::dielectricRefract(eta, w, t));
    EXPECT_LT(t.z, 0.0f);
    EXPECT_NEAR(std::sqrt(t.x * t.x + t.y * t.y) * eta, std::sqrt(w.x * w.x + w.y * w.y), 1e-5);  // Snell
    EXPECT_NEAR(t.x * w.y - t.y * w.x, 0.0, 1e-6);  // same plane of incidence
    // Reciprocal: the refracted direction maps back, with the same reflectance.
    vec3 back;
    ASSERT_TRUE(shared::dielectricRefract(eta, t, back));
    EXPECT_NEAR(back.x, w.x, 1e-5);
    EXPECT_NEAR(back.z, w.z, 1e-5);
    EXPECT_NEAR(shared::dielectricReflectance(eta, w), shared::dielectricReflectance(eta, t), 1e-5);
  }
  // Total internal reflection from inside beyond the critical angle asin(1/eta).
  double crit = std::asin(1.0 / 2.42);
  vec3 inside = dirFromAngles(M_PI - (crit + 0.01), 0.0), t;
  EXPECT_FALSE(shared::dielectricRefract(2.42f, inside, t));
  EXPECT_EQ(shared::dielectricReflectance(2.42f, inside), 1.0f);
  EXPECT_NEAR(t.z, inside.z, 1e-6);
  vec3 justInside = dirFromAngles(M_PI - (crit - 0.01), 0.0);
  EXPECT_TRUE(shared::dielectricRefract(2.42f, justInside, t));
  EXPECT_LT(shared::dielectricReflectance(2.42f, justInside), 1.0f);
}

// ---- Parameter validation -----------------------------------------------------------------------

std::string packError(const char* model, const NamedParams& values) {
  try {
    packParams(*findModel(model), values, "scene.gltf: materials[3] \"Brass\"");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(BrdfModelParams, Errors) {
  std::string e = packError("ward", {{"roughness", ParamValue::num(0.1)}});
  EXPECT_NE(e.find("materials[3] \"Brass\""), std::string::npos) << e;
  EXPECT_NE(e.find("roughness"), std::string::npos) << e;
  EXPECT_NE(e.find("ax"), std::string::npos) << e;  // lists the known ones

  e = packError("ward", {{"ax", ParamValue::num(1.5)}});
  EXPECT_NE(e.find("\"ax\""), std::string::npos) << e;
  EXPECT_NE(e.find("[0.001, 1]"), std::string::npos) << e;

  e = packError("torrance_sparrow", {{"eta", ParamValue::num(0)}});
  EXPECT_NE(e.find("\"eta\""), std::string::npos) << e;
  EXPECT_NE(e.find("(0, 20]"), std::string::npos) << e;

  NamedParams hugeLobe = {{"lobes", arrayValue({arrayValue({ParamValue::num(-2), ParamValue::num(-2),
                                                            ParamValue::num(2), ParamValue::num(100)})})}};
  e = packError("lafortune", hugeLobe);
  EXPECT_NE(e.find("exceeds the allowed 1e6"), std::string::npos) << e;
  EXPECT_NE(e.find("Brass"), std::string::npos) << e;

  e = packError("ward", {{"normalization", ParamValue::str("walter")}});
  EXPECT_NE(e.find("one of ward92, duer, gmd"), std::string::npos) << e;

  e = packError("phong", {{"kd", ParamValue::num(-0.1)}});
  EXPECT_NE(e.find("\"kd\""), std::string::npos) << e;
  EXPECT_NE(e.find("[0, 1]"), std::string::npos) << e;

  e = packError("minnaert", {{"k", ParamValue::num(std::nan(""))}});
  EXPECT_NE(e.find("\"k\""), std::string::npos) << e;
  EXPECT_NE(e.find("[0.5, 2]"), std::string::npos) << e;

  e = packError("gltf_pbr", {{"roughness", ParamValue::num(2)}});
  EXPECT_NE(e.find("roughness"), std::string::npos) << e;

  e = packError("lafortune", {{"lobes", arrayValue({arrayValue({ParamValue::num(1), ParamValue::num(1)})})}});
  EXPECT_NE(e.find("lobes"), std::string::npos) << e;
  EXPECT_NE(e.find("[Cx, Cy, Cz, n]"), std::string::npos) << e;

  NamedParams bigExp = {{"lobes", arrayValue({arrayValue({ParamValue::num(-1), ParamValue::num(-1),
                                                          ParamValue::num(1), ParamValue::num(1e6)})})}};
  e = packError("lafortune", bigExp);
  EXPECT_NE(e.find("(0, 10000]"), std::string::npos) << e;

  e = packError("lambert", {{"rho", ParamValue::num(0.5)}, {"rho", ParamValue::num(0.5)}});
  EXPECT_NE(e.find("twice"), std::string::npos) << e;

  // Choice params accept the index as a number.
  EXPECT_EQ(packError("ward", {{"normalization", ParamValue::num(2)}}), "");
  EXPECT_NE(packError("ward", {{"normalization", ParamValue::num(3)}}), "");
  // Every model's hard set is valid.
  for (const ModelSpec& m : allModels()) EXPECT_NO_THROW(packParams(m, hardParams(m), m.name));
}

TEST(BrdfModelParams, LafortuneLobesPacked) {
  const ModelSpec* m = findModel("lafortune");
  NamedParams v = {{"lobes", arrayValue({arrayValue({ParamValue::num(-1), ParamValue::num(-0.5), ParamValue::num(0.9),
                                                     ParamValue::num(12)}),
                                         arrayValue({ParamValue::num(0.5), ParamValue::num(0.5), ParamValue::num(0.5),
                                                     ParamValue::num(3)})})}};
  BrdfParams p = packParams(*m, v, "lafortune");
  EXPECT_EQ(shared::brdfParam(p, LAFORTUNE_LOBE_COUNT), 2.0f);
  EXPECT_EQ(shared::brdfParam(p, LAFORTUNE_LOBES + 1), -0.5f);
  EXPECT_EQ(shared::brdfParam(p, LAFORTUNE_LOBES + 7), 3.0f);
  vec3 wi = dirFromAngles(0.5, 0.2), wo = dirFromAngles(0.7, 3.0);
  double d1 = -1 * wi.x * wo.x - 0.5 * wi.y * wo.y + 0.9 * wi.z * wo.z, d2 = 0.5 * (wi.x * wo.x + wi.y * wo.y + wi.z * wo.z);
  double expect = 0.3 / M_PI + (d1 > 0 ? std::pow(d1, 12) : 0) + (d2 > 0 ? std::pow(d2, 3) : 0);
  EXPECT_NEAR(shared::brdfEval(m->id, p, wi, wo).x, expect, 1e-5 * expect);
}

}  // namespace
}  // namespace nusselt
