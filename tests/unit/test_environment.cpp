// test_environment.cpp: the environment light on the CPU: the map convention, rotation, bilinear
// lookup, the 2-D distribution (normalisation, chi-square of the sampler against its pdf on a map
// with a sun), and reading maps (Radiance RGBE round trips and refusals, OpenEXR bad texels and
// chromaticities).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfTiledOutputFile.h>

#include "io/environment_map.h"
#include "io/image.h"
#include "render/environment.h"
#include "test_quadtree_chi2.h"
#include "util/error.h"

namespace nusselt {
namespace {

using namespace shared;

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("nusselt_env_" + std::to_string(::getpid()) + "_" + name)).string();
}

// A 2:1 map with a smooth sky and a sun: texels (sx, sy), (sx+1, sy) at `sun` x the sky's mean.
Environment sunMap(int w, int h, int sx, int sy, float sun) {
  Environment e;
  e.kind = EnvironmentKind::Map;
  e.width = w;
  e.height = h;
  e.rgb.resize(std::size_t(3) * w * h);
  double mean = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float t = float(y) / h;
      float* c = &e.rgb[3 * (std::size_t(y) * w + x)];
      c[0] = 0.2f + 0.6f * t;
      c[1] = 0.4f + 0.3f * t + 0.1f * std::sin(6.28f * x / w);
      c[2] = 1.0f - 0.7f * t;
      mean += (c[0] + c[1] + c[2]) / 3;
    }
  mean /= double(w) * h;
  for (int x : {sx, sx + 1})
    for (int c = 0; c < 3; ++c) e.rgb[3 * (std::size_t(sy) * w + x) + c] = float(sun * mean);
  return e;
}

// ---- Convention (issue 17): u = 0.5 + atan2(x, -z) / 2 pi, v = acos(y) / pi ----

TEST(EnvironmentConvention, AxesLandWhereTheIssueSays) {
  auto uv = [](vec3 d) { return envDirectionToUv(d); };
  EXPECT_NEAR(uv(vec3(0, 0, -1)).x, 0.5f, 1e-6f);   // the centre along -Z
  EXPECT_NEAR(uv(vec3(0, 0, -1)).y, 0.5f, 1e-6f);
  EXPECT_NEAR(uv(vec3(1, 0, 0)).x, 0.75f, 1e-6f);   // +X to the right of the centre
  EXPECT_NEAR(uv(vec3(-1, 0, 0)).x, 0.25f, 1e-6f);
  EXPECT_NEAR(uv(vec3(0, 0, 1)).x, 1.0f, 1e-6f);    // +Z on the seam
  EXPECT_NEAR(uv(vec3(0, 1, 0)).y, 0.0f, 1e-6f);    // +Y: the top row
  EXPECT_NEAR(uv(vec3(0, -1, 0)).y, 1.0f, 1e-6f);
}

TEST(EnvironmentConvention, UvDirectionRoundTripAndRotation) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> U(0.001f, 0.999f);
  const float a = 0.7f;
  const vec4 rot(std::cos(a), std::sin(a), 0, 0);
  for (int i = 0; i < 10000; ++i) {
    vec2 uv(U(rng), U(rng));
    float s;
    vec3 d = envUvToDirection(uv, s);
    EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
    vec2 back = envDirectionToUv(d);
    ASSERT_NEAR(back.x, uv.x, 2e-5f);
    ASSERT_NEAR(back.y, uv.y, 2e-5f);
    vec3 w = envMapToWorld(rot, d);
    vec3 m = envWorldToMap(rot, w);
    ASSERT_NEAR(glm::length(m - d), 0.0f, 1e-6f);
  }
  // Counter-clockwise seen from above (right-handed about +Y): 90 degrees takes the map's centre
  // (-Z) to -X and its +X to -Z.
  const vec4 quarter(0.0f, 1.0f, 0, 0);
  vec3 c = envMapToWorld(quarter, vec3(0, 0, -1));
  EXPECT_NEAR(c.x, -1.0f, 1e-6f);
  vec3 r = envMapToWorld(quarter, vec3(1, 0, 0));
  EXPECT_NEAR(r.z, -1.0f, 1e-6f);
}

TEST(EnvironmentLookup, TexelCentresExactSeamWrapsPolesClamp) {
  Environment e = sunMap(16, 8, 3, 2, 50.0f);
  EnvironmentData d = buildEnvironment(e);
  EnvHostView v = d.view();
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      vec3 got = envLookupUv(v, vec2((x + 0.5f) / 16, (y + 0.5f) / 8));
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], e.rgb[3 * (y * 16 + x) + c], 1e-5f * (1 + got[c]));
    }
  // u = 0 lies halfway between the last and the first texel of a row.
  vec3 seam = envLookupUv(v, vec2(0.0f, 4.5f / 8));
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(seam[c], 0.5f * (e.rgb[3 * (4 * 16 + 15) + c] + e.rgb[3 * (4 * 16) + c]), 1e-5f);
  // Above the first row's centres: the first row (clamped).
  vec3 top = envLookupUv(v, vec2(0.5f / 16, 0.0f));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(top[c], e.rgb[c], 1e-6f);
  // Scale multiplies.
  e.scale = 3.0f;
  EnvironmentData d3 = buildEnvironment(e);
  EXPECT_NEAR(envLookupUv(d3.view(), vec2(0.3f, 0.6f)).y, 3.0f * envLookupUv(v, vec2(0.3f, 0.6f)).y, 1e-5f);
}

// ---- Distribution ----

TEST(EnvironmentDistribution, CdfsAreNormalisedAndPositiveWhereTheLookupIs) {
  // A black map with one lit texel: the weight reaches its 3 x 3 neighbourhood (the bilinear
  // lookup's support), nothing else.
  Environment e;
  e.kind = EnvironmentKind::Map;
  e.width = 16;
  e.height = 8;
  e.rgb.assign(3 * 16 * 8, 0.0f);
  e.rgb[3 * (3 * 16 + 0) + 1] = 1.0f;  // row 3, column 0 (its neighbours wrap to column 15)
  EnvironmentData d = buildEnvironment(e);
  ASSERT_TRUE(d.emits());
  double total = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      double p = dist2dCellProbability(d.distribution.data(), 16, 8, x, y);
      total += p;
      const bool near = std::abs(y - 3) <= 1 && (x <= 1 || x == 15);
      EXPECT_EQ(p > 0, near) << "cell " << x << "," << y;
    }
  EXPECT_NEAR(total, 1.0, 1e-6);
  // A black map is no light.
  e.rgb.assign(3 * 16 * 8, 0.0f);
  EXPECT_FALSE(buildEnvironment(e).emits());
}

// The sampler against its own pdf: chi-square over 32 x 16 bins of the world's (u, v), a map of
// 64 x 32 texels with a sun of 10^4 x the sky's mean, rotated by 45 degrees (8 texel columns: the
// bins stay unions of texels, so the expected counts are exact sums of envPdf x solid angle over
// a sub-grid). 10^6 samples, fixed seed, significance 0.01.
TEST(EnvironmentDistribution, ChiSquareOfTheSamplerAgainstItsPdfWithASun) {
  Environment e = sunMap(64, 32, 40, 9, 1.0e4f);
  e.rotateDegrees = 45.0f;
  EnvironmentData d = buildEnvironment(e);
  EnvHostView v = d.view();
  const int bu = 32, bv = 16;
  // Expected: integral over each bin of envPdf(d(u, v)) dω with dω = 2 pi^2 sin(theta) du dv, by a
  // 4 x 4 midpoint rule per bin (= per map cell; the density is constant on a cell).
  std::vector<double> prob(bu * bv, 0.0);
  const int sub = 4;
  for (int j = 0; j < bv * sub; ++j)
    for (int i = 0; i < bu * sub; ++i) {
      vec2 uv((i + 0.5f) / (bu * sub), (j + 0.5f) / (bv * sub));
      float s;
      vec3 dir = envUvToDirection(uv, s);
      prob[(j / sub) * bu + i / sub] +=
          double(envPdf(v, dir)) * 2.0 * M_PI * M_PI * s / (double(bu * sub) * double(bv * sub));
    }
  double sumProb = 0;
  for (double p : prob) sumProb += p;
  EXPECT_NEAR(sumProb, 1.0, 1e-3);

  const int n = 1000000;
  std::vector<double> obs(bu * bv, 0.0);
  std::mt19937 rng(4242);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  int failed = 0;
  int pdfMismatch = 0;
  for (int k = 0; k < n; ++k) {
    vec2 u(std::min(U(rng), NUSSELT_ONE_MINUS_EPS), std::min(U(rng), NUSSELT_ONE_MINUS_EPS));
    float pdf;
    vec3 dir = envSample(v, u, pdf);
    if (!(pdf > 0)) {
      ++failed;
      continue;
    }
    // The pdf the sampler reports is the one envPdf evaluates (MIS needs them equal), except where
    // float rounding of the uv -> direction -> uv round trip (a few 1e-6) moves a sample across a
    // cell edge: a fraction of about 2 x 4e-6 x (64 + 32) = 8e-4 of the samples at most.
    if (std::fabs(double(envPdf(v, dir)) / pdf - 1.0) > 1e-3) ++pdfMismatch;
    vec2 uv = envDirectionToUv(dir);
    int i = std::min(int(uv.x * bu), bu - 1), j = std::min(int(uv.y * bv), bv - 1);
    obs[j * bu + i] += 1;
  }
  EXPECT_EQ(failed, 0);
  EXPECT_LT(pdfMismatch, 2e-3 * n) << "envSample's pdf and envPdf disagree too often";
  double chi2 = 0, pooledO = 0, pooledE = 0;
  int used = 0;
  for (int b = 0; b < bu * bv; ++b) {
    double ex = prob[b] * n;
    if (ex < 5) {
      pooledO += obs[b];
      pooledE += ex;
      continue;
    }
    chi2 += (obs[b] - ex) * (obs[b] - ex) / ex;
    ++used;
  }
  if (pooledE >= 5) {
    chi2 += (pooledO - pooledE) * (pooledO - pooledE) / pooledE;
    ++used;
  }
  const int dof = used - 1;
  const double p = qttest::gammaQ(0.5 * dof, 0.5 * chi2);
  EXPECT_GT(p, 0.01) << "chi2 " << chi2 << " with " << dof << " degrees of freedom";
  // The sun's texels hold most of the mass: their density is ~10^4 x 0.75^2 (the kernel's centre
  // weight) the sky's.
  float s0, s1;
  vec3 sunDir = envMapToWorld(v.e.rotation, envUvToDirection(vec2(40.5f / 64, 9.5f / 32), s0));
  vec3 skyDir = envMapToWorld(v.e.rotation, envUvToDirection(vec2(10.5f / 64, 9.5f / 32), s1));
  EXPECT_GT(envPdf(v, sunDir), 1000.0f * envPdf(v, skyDir));
  std::printf("[ env chi2 ] chi2 %.1f, %d dof, p = %.3f; pdf mismatches at cell edges: %d of %d\n", chi2, dof, p,
              pdfMismatch, n);
}

// ---- Radiance RGBE ----

TEST(RadianceHdr, FlatAndRunLengthEncodedRoundTrips) {
  const int w = 40, h = 20;
  std::vector<float> rgb(3 * w * h);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = (i / 3) % 7 == 0 ? 0.0f : std::exp(8.0f * U(rng) - 4.0f);
  for (int x = 0; x < 12; ++x)  // a run for the encoder
    for (int c = 0; c < 3; ++c) rgb[3 * x + c] = 2.0f;
  for (bool rle : {false, true}) {
    std::vector<std::uint8_t> bytes = encodeRadianceHdr(rgb, w, h, rle);
    RgbeImage img = decodeRadianceHdr(bytes.data(), bytes.size(), "test.hdr");
    ASSERT_EQ(img.width, w);
    ASSERT_EQ(img.height, h);
    for (std::size_t p = 0; p < std::size_t(w) * h; ++p) {
      float m = std::max(rgb[3 * p], std::max(rgb[3 * p + 1], rgb[3 * p + 2]));
      // RGBE keeps 8 mantissa bits relative to the largest channel (+ half a step on decoding).
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(img.rgb[3 * p + c], rgb[3 * p + c], m / 128.0f) << "rle " << rle << " texel " << p;
    }
  }
}

TEST(RadianceHdr, OldStyleRunsExposureAndRefusals) {
  auto decode = [](const std::string& s) {
    return decodeRadianceHdr(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), "x.hdr");
  };
  // Old-style run: one pixel then (1, 1, 1, 3) repeats it 3 times; EXPOSURE 2 halves values.
  std::string head = "#?RADIANCE\nEXPOSURE=2\n\n-Y 1 +X 4\n";
  std::string px = std::string("\x80\x40\x20\x81", 4) + std::string("\x01\x01\x01\x03", 4);
  RgbeImage img = decode(head + px);
  ASSERT_EQ(img.width, 4);
  for (int x = 0; x < 4; ++x) EXPECT_NEAR(img.rgb[3 * x], (128.5f / 256.0f) * 2.0f / 2.0f, 1e-6f);
  // Refusals name the file and the problem.
  auto refuses = [&](const std::string& s, const std::string& what) {
    try {
      decode(s);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("x.hdr"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refuses("P6\n", "no '#?' signature");
  refuses("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\x80\x80\x80\x80", "XYZE");
  refuses("#?RADIANCE\n\n+Y 1 +X 1\n\x80\x80\x80\x80", "-Y height +X width");
  refuses("#?RADIANCE\n\n-Y 2 +X 2\n\x80\x80\x80\x80", "truncated");
  refuses("#?RADIANCE\n\n-Y 100000 +X 200000\n", "larger than supported");
  refuses("#?RADIANCE\n\n-Y 0 +X 2\n", "empty");
  refuses("#?RADIANCE\n", "truncated");
}

// ---- OpenEXR maps ----

TEST(EnvironmentMapFile, ExrBadTexelsAreDroppedAndCountedAndShapeWarns) {
  Image img;
  img.width = 8;
  img.height = 3;  // not 2:1
  img.rgb.assign(3 * 8 * 3, 0.5f);
  img.rgb[0] = NAN;
  img.rgb[3 * 5 + 1] = -1.0f;
  img.rgb[3 * 7 + 2] = INFINITY;
  const std::string path = tempPath("bad.exr");
  writeExr(path, img);
  EnvironmentImage m = readEnvironmentMap(path);
  EXPECT_EQ(m.droppedTexels, 3u);
  EXPECT_EQ(m.rgb[0], 0.0f);
  EXPECT_EQ(m.rgb[3 * 5 + 1], 0.0f);
  EXPECT_EQ(m.rgb[3 * 1], 0.5f);
  ASSERT_EQ(m.warnings.size(), 2u);
  EXPECT_NE(m.warnings[0].find("3 texels"), std::string::npos) << m.warnings[0];
  EXPECT_NE(m.warnings[1].find("not 2:1"), std::string::npos) << m.warnings[1];
  std::remove(path.c_str());
  // Missing file and unknown format: errors naming the file.
  for (const std::string& bad : {tempPath("missing.exr"), tempPath("text.exr")}) {
    if (bad.find("text") != std::string::npos) std::ofstream(bad) << "hello";
    try {
      readEnvironmentMap(bad);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
    std::remove(bad.c_str());
  }
}

// A map in Rec. 2020 primaries (D65) becomes Rec. 709: the expected values are ITU-R BT.2087's
// published conversion matrix (4 decimals), independent of OpenEXR's computation.
TEST(EnvironmentMapFile, ExrChromaticitiesAreConvertedToRec709) {
  const std::string path = tempPath("rec2020.exr");
  const float in[3] = {0.2f, 0.5f, 0.3f};
  {
    Imf::Header header(2, 1);
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.channels().insert("G", Imf::Channel(Imf::FLOAT));
    header.channels().insert("B", Imf::Channel(Imf::FLOAT));
    Imf::addChromaticities(header, Imf::Chromaticities(Imath::V2f(0.708f, 0.292f), Imath::V2f(0.170f, 0.797f),
                                                       Imath::V2f(0.131f, 0.046f), Imath::V2f(0.3127f, 0.3290f)));
    float px[6] = {in[0], in[1], in[2], in[0], in[1], in[2]};
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px + 0), 12, 24));
    fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px + 1), 12, 24));
    fb.insert("B", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px + 2), 12, 24));
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  EnvironmentImage m = readEnvironmentMap(path);
  const double M[3][3] = {{1.6605, -0.5876, -0.0728}, {-0.1246, 1.1329, -0.0083}, {-0.0182, -0.1006, 1.1187}};
  for (int c = 0; c < 3; ++c) {
    double expected = M[c][0] * in[0] + M[c][1] * in[1] + M[c][2] * in[2];
    EXPECT_NEAR(m.rgb[c], expected, 1.5e-3) << "channel " << c;
  }
  std::remove(path.c_str());
}

// Tiled files and the lossy DWA compressions read like scanline ZIP files (the OpenEXR library
// decodes them): a 64 x 32 tiled map (16 x 16 tiles) with DWAB and with PIZ compression. PIZ is
// lossless for float data; DWAB quantises (its default level keeps smooth data within ~1 %).
TEST(EnvironmentMapFile, TiledDwaAndPizExrMapsRead) {
  const int w = 64, h = 32;
  std::vector<float> rgb(3 * w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) rgb[3 * (y * w + x) + c] = 0.5f + 0.3f * std::sin(0.1f * x + c) + 0.01f * y;
  for (Imf::Compression comp : {Imf::DWAB_COMPRESSION, Imf::PIZ_COMPRESSION}) {
    const std::string path = tempPath("tiled.exr");
    {
      Imf::Header header(w, h);
      header.compression() = comp;
      header.setTileDescription(Imf::TileDescription(16, 16, Imf::ONE_LEVEL));
      for (const char* n : {"R", "G", "B"}) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
      Imf::FrameBuffer fb;
      for (int c = 0; c < 3; ++c)
        fb.insert(c == 0 ? "R" : c == 1 ? "G" : "B",
                  Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + c), 12, 12 * std::size_t(w)));
      Imf::TiledOutputFile out(path.c_str(), header);
      out.setFrameBuffer(fb);
      out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
    }
    EnvironmentImage m = readEnvironmentMap(path);
    ASSERT_EQ(m.width, w);
    ASSERT_EQ(m.height, h);
    double worst = 0;
    for (std::size_t i = 0; i < rgb.size(); ++i) worst = std::max(worst, double(std::fabs(m.rgb[i] - rgb[i]) / rgb[i]));
    std::printf("[ env exr ] tiled, compression %d: worst relative difference %.3g\n", int(comp), worst);
    EXPECT_LT(worst, comp == Imf::PIZ_COMPRESSION ? 1e-7 : 0.02) << "compression " << int(comp);
    EXPECT_TRUE(m.warnings.empty());
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace nusselt
