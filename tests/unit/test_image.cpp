// test_image.cpp: EXR/PNG writing and reading (io/image.h) and the progress display
// (util/progress.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <csignal>
#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/image.h"
#include "util/error.h"
#include "util/progress.h"

// A PNG decoder, to check what writePng encoded. Static so it cannot clash with a copy compiled
// into the library (tinygltf can bring one).
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace nusselt {
namespace {

// A fresh directory per test, removed (with its contents; tests create no subdirectories) after.
class TempDir {
 public:
  TempDir() {
    std::string pattern = ::testing::TempDir() + "nusselt_image_XXXXXX";
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    if (!::mkdtemp(buf.data())) std::abort();
    path_ = buf.data();
  }
  ~TempDir() {
    ::chmod(path_.c_str(), 0755);
    for (const std::string& name : entries()) ::unlink((path_ + "/" + name).c_str());
    ::rmdir(path_.c_str());
  }
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // Names in the directory (including hidden ones such as temporary files), sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    if (DIR* d = ::opendir(path_.c_str())) {
      while (dirent* e = ::readdir(d)) {
        std::string n = e->d_name;
        if (n != "." && n != "..") names.push_back(n);
      }
      ::closedir(d);
    }
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  std::string path_;
};

std::vector<unsigned char> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// A deterministic, poorly compressible image (so files are reasonably large).
Image noiseImage(int width, int height, uint32_t seed, bool withVariance) {
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(3) * width * height);
  uint32_t state = seed * 2654435761u + 1;
  auto next = [&] {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return float(state) / 4294967296.0f * 10.0f;
  };
  for (float& v : image.rgb) v = next();
  if (withVariance) {
    image.variance.resize(image.rgb.size());
    for (float& v : image.variance) v = next() * 1e-3f;
  }
  return image;
}

bool bitEqual(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

template <class T>
std::vector<std::pair<std::string, T>> sorted(std::vector<std::pair<std::string, T>> v) {
  std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  return v;
}

// Runs `f` expecting nusselt::Error; returns its message ("" and a test failure otherwise).
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected nusselt::Error, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected nusselt::Error, nothing was thrown";
  return "";
}

TEST(ImageExr, RoundTripIsBitExactWithVarianceAndAttributes) {
  TempDir dir;
  Image image = noiseImage(7, 5, 1, true);
  // Values a careless conversion would change: -0, a denormal, huge, tiny, inf, NaN with payload.
  image.rgb[0] = -0.0f;
  image.rgb[1] = std::numeric_limits<float>::denorm_min();
  image.rgb[2] = 3.0e38f;
  image.rgb[3] = 1e-30f;
  image.rgb[4] = std::numeric_limits<float>::infinity();
  uint32_t nanBits = 0x7fc01234u;
  std::memcpy(&image.rgb[5], &nanBits, 4);

  ImageMetadata meta;
  meta.strings = {{"nusselt/scene", "scenes/cornell-box.glb"},
                  {"nusselt/version", "0.1.0"},
                  {"nusselt/empty", ""},
                  {"a name with spaces & a very long tail exceeding 31 characters", "ünïcödé"}};
  meta.ints = {{"nusselt/spp", 1024}, {"nusselt/negative", -7},
               {"nusselt/int32max", std::numeric_limits<int>::max()},
               {"nusselt/int32min", std::numeric_limits<int>::min()}};
  meta.doubles = {{"nusselt/seconds", 12.345678901234567}, {"nusselt/tiny", 1e-300},
                  {"nusselt/huge", -1.5e300}};

  const std::string path = dir.file("out.exr");
  writeExr(path, image, meta);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.exr"});

  ImageMetadata back;
  Image read = readExr(path, &back);
  EXPECT_EQ(read.width, 7);
  EXPECT_EQ(read.height, 5);
  EXPECT_TRUE(bitEqual(read.rgb, image.rgb));
  EXPECT_TRUE(bitEqual(read.variance, image.variance));
  EXPECT_EQ(sorted(back.strings), sorted(meta.strings));
  EXPECT_EQ(sorted(back.ints), sorted(meta.ints));
  EXPECT_EQ(sorted(back.doubles), sorted(meta.doubles));  // exact: doubles are stored as doubles

  EXPECT_EQ(findInt(back, "nusselt/spp"), 1024);
  EXPECT_EQ(findString(back, "nusselt/version"), "0.1.0");
  EXPECT_EQ(findDouble(back, "nusselt/tiny"), 1e-300);
  EXPECT_EQ(findInt(back, "nusselt/missing"), std::nullopt);

  // Without the metadata pointer it still reads.
  EXPECT_TRUE(bitEqual(readExr(path).rgb, image.rgb));
}

TEST(ImageExr, Int64OutsideInt32IsStoredAsExactDecimalString) {
  TempDir dir;
  ImageMetadata meta;
  const int64_t big = (int64_t(1) << 53) + 1;  // not representable as a double
  meta.ints = {{"nusselt/seed", big}, {"nusselt/min", std::numeric_limits<int64_t>::min()}};
  writeExr(dir.file("a.exr"), noiseImage(2, 2, 3, false), meta);
  ImageMetadata back;
  readExr(dir.file("a.exr"), &back);
  EXPECT_TRUE(back.ints.empty());
  EXPECT_EQ(findString(back, "nusselt/seed"), std::to_string(big));
  EXPECT_EQ(findInt(back, "nusselt/seed"), big);
  EXPECT_EQ(findInt(back, "nusselt/min"), std::numeric_limits<int64_t>::min());
}

TEST(ImageExr, WithoutVarianceHasNoVarianceChannels) {
  TempDir dir;
  Image image = noiseImage(16, 3, 2, false);
  writeExr(dir.file("a.exr"), image, {});
  Image read = readExr(dir.file("a.exr"));
  EXPECT_TRUE(bitEqual(read.rgb, image.rgb));
  EXPECT_TRUE(read.variance.empty());
}

TEST(ImageExr, WritingIntoMissingDirectoryThrowsAndLeavesNothing) {
  TempDir dir;
  const std::string path = dir.file("missing/out.exr");
  std::string message = errorOf([&] { writeExr(path, noiseImage(4, 4, 1, false), {}); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find(std::strerror(ENOENT)), std::string::npos) << message;
  EXPECT_TRUE(dir.entries().empty());

  message = errorOf([&] { writePng(path, noiseImage(4, 4, 1, false)); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(ImageExr, OverwriteReplacesTheFile) {
  TempDir dir;
  const std::string path = dir.file("out.exr");
  Image first = noiseImage(8, 8, 1, false), second = noiseImage(5, 3, 2, true);
  writeExr(path, first, {});
  writeExr(path, second, {});
  Image read = readExr(path);
  EXPECT_EQ(read.width, 5);
  EXPECT_TRUE(bitEqual(read.rgb, second.rgb));
  EXPECT_TRUE(bitEqual(read.variance, second.variance));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.exr"});
}

TEST(ImageExr, InvalidImageOrMetadataLeavesOldFileIntact) {
  TempDir dir;
  const std::string path = dir.file("out.exr");
  writeExr(path, noiseImage(8, 8, 1, false), {});
  const auto before = readBytes(path);

  Image bad = noiseImage(8, 8, 2, false);
  bad.rgb.pop_back();
  std::string message = errorOf([&] { writeExr(path, bad, {}); });
  EXPECT_NE(message.find(path), std::string::npos) << message;

  Image badVariance = noiseImage(8, 8, 2, true);
  badVariance.variance.resize(3);
  errorOf([&] { writeExr(path, badVariance, {}); });
  errorOf([&] { writeExr(path, Image{}, {}); });
  errorOf([&] { writePng(dir.file("out.png"), bad); });

  ImageMetadata reserved;
  reserved.strings = {{"compression", "none"}};
  message = errorOf([&] { writeExr(path, noiseImage(8, 8, 2, false), reserved); });
  EXPECT_NE(message.find("compression"), std::string::npos) << message;
  ImageMetadata duplicate;
  duplicate.strings = {{"x", "1"}};
  duplicate.ints = {{"x", 1}};
  errorOf([&] { writeExr(path, noiseImage(8, 8, 2, false), duplicate); });
  ImageMetadata unnamed;
  unnamed.doubles = {{"", 1.0}};
  errorOf([&] { writeExr(path, noiseImage(8, 8, 2, false), unnamed); });

  EXPECT_EQ(readBytes(path), before);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.exr"});
}

// Makes write() fail part-way through the file (as a full disk would) with RLIMIT_FSIZE, which
// works even as root, unlike a read-only directory. SIGXFSZ is ignored so that write() returns
// EFBIG instead of the signal killing the test. Both are restored afterwards.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    oldHandler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, oldHandler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*oldHandler_)(int) = nullptr;
  bool ok_ = false;
};

TEST(ImageExr, WriteErrorPartWayLeavesOldFileIntactAndNoTempFile) {
  TempDir dir;
  const std::string exr = dir.file("out.exr"), png = dir.file("out.png");
  writeExr(exr, noiseImage(4, 4, 1, false), {});
  writePng(png, noiseImage(4, 4, 1, false));
  const auto exrBefore = readBytes(exr), pngBefore = readBytes(png);
  ASSERT_LT(exrBefore.size(), 4096u);

  Image big = noiseImage(128, 128, 7, true);  // ~400 kB of noise: cannot compress below 4 kB
  std::string exrMessage, pngMessage;
  {
    FileSizeLimit limit(4096);
    if (!limit.ok()) GTEST_SKIP() << "cannot set RLIMIT_FSIZE";
    exrMessage = errorOf([&] { writeExr(exr, big, {}); });
    pngMessage = errorOf([&] { writePng(png, big); });
  }
  EXPECT_NE(exrMessage.find(exr), std::string::npos) << exrMessage;
  EXPECT_NE(exrMessage.find(std::strerror(EFBIG)), std::string::npos) << exrMessage;
  EXPECT_NE(pngMessage.find(png), std::string::npos) << pngMessage;
  EXPECT_NE(pngMessage.find(std::strerror(EFBIG)), std::string::npos) << pngMessage;
  EXPECT_EQ(readBytes(exr), exrBefore);
  EXPECT_EQ(readBytes(png), pngBefore);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.exr", "out.png"}));
}

TEST(ImageExr, ReadingATruncatedFileThrowsNamingTheFile) {
  TempDir dir;
  const std::string path = dir.file("out.exr");
  writeExr(path, noiseImage(64, 64, 1, true), {});
  const auto bytes = readBytes(path);
  ASSERT_GT(bytes.size(), 2000u);

  for (size_t keep : {size_t(0), size_t(3), size_t(40), size_t(300), bytes.size() / 2,
                      bytes.size() - 1}) {
    const std::string cut = dir.file("cut.exr");
    writeBytes(cut, std::vector<unsigned char>(bytes.begin(), bytes.begin() + long(keep)));
    std::string message = errorOf([&] { readExr(cut); });
    EXPECT_NE(message.find(cut), std::string::npos) << "kept " << keep << ": " << message;
  }

  // Not an EXR at all; missing; a directory.
  writeBytes(dir.file("text.exr"), {'h', 'e', 'l', 'l', 'o', '\n'});
  EXPECT_NE(errorOf([&] { readExr(dir.file("text.exr")); }).find("text.exr"), std::string::npos);
  std::string message = errorOf([&] { readExr(dir.file("nope.exr")); });
  EXPECT_NE(message.find("nope.exr"), std::string::npos) << message;
  EXPECT_NE(message.find(std::strerror(ENOENT)), std::string::npos) << message;
  EXPECT_NE(errorOf([&] { readExr(dir.path()); }).find(dir.path()), std::string::npos);
}

TEST(ImagePng, SrgbTransferFunction) {
  EXPECT_EQ(toSrgb8(0.0f), 0);
  // The linear segment ends at 0.0031308 -> 0.0404500, i.e. 10.31 of 255.
  EXPECT_EQ(toSrgb8(0.0031308f), 10);
  EXPECT_EQ(toSrgb8(1.0f), 255);
  EXPECT_EQ(toSrgb8(0.001f), 3);     // 12.92 * 0.001 * 255 = 3.29
  EXPECT_EQ(toSrgb8(0.5f), 188);     // 1.055 * 0.5^(1/2.4) - 0.055 = 0.73536 -> 187.5
  EXPECT_EQ(toSrgb8(0.18f), 118);    // mid grey: 0.46135 -> 117.6
  EXPECT_EQ(toSrgb8(-1.0f), 0);
  EXPECT_EQ(toSrgb8(7.0f), 255);
  EXPECT_EQ(toSrgb8(std::numeric_limits<float>::infinity()), 255);
  EXPECT_EQ(toSrgb8(std::nanf("")), 0);
  // Monotonic over [0, 1].
  int previous = 0;
  for (int i = 0; i <= 10000; ++i) {
    int v = toSrgb8(float(i) / 10000.0f);
    EXPECT_GE(v, previous);
    previous = v;
  }
}

TEST(ImagePng, WritesTonemappedPng) {
  TempDir dir;
  Image image;
  image.width = 3;
  image.height = 2;
  // Top row: black, 0.5 grey, overexposed red; bottom row: 0.25, 0.0031308, blue.
  image.rgb = {0, 0, 0, 0.5f, 0.5f, 0.5f, 4, 0, 0, 0.25f, 0.25f, 0.25f,
               0.0031308f, 0.0031308f, 0.0031308f, 0, 0, 1};
  const std::string path = dir.file("out.png");
  writePng(path, image);
  auto bytes = readBytes(path);
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(std::memcmp(bytes.data(), signature, 8), 0);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.png"});

  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
  std::vector<int> got(pixels, pixels + 18);
  stbi_image_free(pixels);
  EXPECT_EQ(got, (std::vector<int>{0, 0, 0, 188, 188, 188, 255, 0, 0, 137, 137, 137, 10, 10, 10,
                                   0, 0, 255}));

  // +1 stop doubles the linear values: 0.25 -> 0.5 -> 188.
  writePng(path, image, 1.0f);
  bytes = readBytes(path);
  pixels = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(pixels[9], 188);
  EXPECT_EQ(pixels[3], 255);
  stbi_image_free(pixels);
}

// A 2 x 1 image and a reference whose comparison the tests below work out by hand.
static std::pair<Image, Image> twoPixelImages() {
  Image a, ref;
  a.width = ref.width = 2;
  a.height = ref.height = 1;
  a.rgb = {1, 2, 3, 0, 0, 0};
  ref.rgb = {1, 1, 1, 0, 0, 1};
  return {a, ref};
}

TEST(ImageCompare, KnownInputs) {
  Image a, ref;
  std::tie(a, ref) = twoPixelImages();
  ImageDifference d = compareImages(a, ref);
  EXPECT_DOUBLE_EQ(d.mse, 1.0);                      // (0 + 1 + 4 + 0 + 0 + 1) / 6
  EXPECT_DOUBLE_EQ(d.relMse, (1 + 4 + 1) / 1.01 / 6);  // every nonzero diff has ref^2 = 1
  EXPECT_DOUBLE_EQ(d.meanA, 1.0);
  EXPECT_DOUBLE_EQ(d.meanB, 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(d.maxAbs, 2.0);

  // Against itself: all zero.
  d = compareImages(ref, ref);
  EXPECT_EQ(d.mse, 0.0);
  EXPECT_EQ(d.relMse, 0.0);
  EXPECT_EQ(d.maxAbs, 0.0);

  // The 0.01 keeps relMse finite where the reference is black.
  Image black = ref;
  black.rgb.assign(6, 0.0f);
  Image one = ref;
  one.rgb.assign(6, 0.1f);
  EXPECT_DOUBLE_EQ(compareImages(one, black).relMse, double(0.1f) * double(0.1f) / 0.01);

  // A NaN shows up in maxAbs (and the means) instead of being silently skipped.
  Image nan = a;
  nan.rgb[4] = std::nanf("");
  EXPECT_TRUE(std::isnan(compareImages(nan, ref).maxAbs));

  // The error map: per pixel the root of its relMse, clamped to 1; NaN is white.
  Image near = ref;
  near.rgb = {1.1f, 1.0f, 1.0f, 0.0f, 0.0f, 1.0f};
  Image m = errorMap(near, ref);
  ASSERT_EQ(m.width, 2);
  ASSERT_EQ(m.rgb.size(), 6u);
  EXPECT_NEAR(m.rgb[0], std::sqrt(double(0.1f) * double(0.1f) / 1.01 / 3.0), 1e-7);
  EXPECT_EQ(m.rgb[1], m.rgb[0]);
  EXPECT_EQ(m.rgb[3], 0.0f);
  EXPECT_EQ(errorMap(a, ref).rgb[0], 1.0f);  // (1 + 4) / 1.01 / 3 > 1
  EXPECT_EQ(errorMap(nan, ref).rgb[3], 1.0f);

  Image other = ref;
  other.width = 1;
  other.height = 2;
  EXPECT_NE(errorOf([&] { compareImages(a, other); }).find("2x1"), std::string::npos);
  Image broken = ref;
  broken.rgb.pop_back();
  errorOf([&] { compareImages(a, broken); });
}

// The reference's own noise (`nusselt diff` with a reference rendered with --variance): its share
// of relMse, and the crop keeping the variance channels.
TEST(ImageCompare, ReferenceVarianceGivesItsOwnShareOfRelMse) {
  Image a, ref;
  std::tie(a, ref) = twoPixelImages();
  EXPECT_EQ(compareImages(a, ref).referenceRelMse, -1.0);  // no variance channels
  ref.variance = {0.5f, 0, 0, 0.25f, 0, 0};
  EXPECT_DOUBLE_EQ(compareImages(a, ref).referenceRelMse, (0.5 / 1.01 + 0.25 / 0.01) / 6);
  EXPECT_EQ(compareImages(ref, a).referenceRelMse, -1.0);  // only the reference's variance counts
  Image right = cropImage(ref, 0.5, 0.0, 1.0, 1.0);
  ASSERT_EQ(right.variance.size(), 3u);
  EXPECT_EQ(right.variance[0], 0.25f);
}

// relMse - referenceRelMse estimates the image's relMSE against the truth. Simulated: per value a
// true mean m (0.02 .. 2.02), an image x = m + N(0, (0.1 m)^2) and an independent reference
// r = m + N(0, (0.02 m)^2) carrying var = (0.02 m)^2; the image's true relMSE is
// T = mean of (0.1 m)^2 / (m^2 + 0.01). The estimate must be within 4 standard errors of its
// per-value terms (two-sided, about 6e-5) plus the bias of the noisy denominator, whose leading
// term is below 3 var / m^2 = 0.0012 of T (0.002 T allowed); relMse alone is off by the
// reference's noise, about 4 % of T, far outside the same bound.
TEST(ImageCompare, RelMseLessTheReferenceNoiseIsUnbiased) {
  const int pixels = 100000;
  Image x, r;
  x.width = r.width = pixels;
  x.height = r.height = 1;
  std::mt19937 rng(16);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> m(std::size_t(3) * pixels);
  double truth = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    m[i] = 0.02 + 2.0 * std::fmod(double(i) * 0.6180339887, 1.0);
    const double sa = 0.1 * m[i], sb = 0.02 * m[i];
    x.rgb.push_back(float(m[i] + sa * normal(rng)));
    r.rgb.push_back(float(m[i] + sb * normal(rng)));
    r.variance.push_back(float(sb * sb));
    truth += sa * sa / (m[i] * m[i] + 0.01);
  }
  const double n = double(m.size());
  truth /= n;
  ImageDifference d = compareImages(x, r);
  ASSERT_GT(d.referenceRelMse, 0.0);
  const double estimate = d.relMse - d.referenceRelMse;
  double sum = 0, sumSq = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double rr = r.rgb[i], diff = double(x.rgb[i]) - rr;
    const double t = (diff * diff - double(r.variance[i])) / (rr * rr + 0.01);
    sum += t;
    sumSq += t * t;
  }
  const double se = std::sqrt(std::max(0.0, sumSq / n - (sum / n) * (sum / n)) / n);
  const double bound = 4.0 * se + 0.002 * truth;
  EXPECT_LT(std::abs(estimate - truth), bound) << "truth " << truth << ", estimate " << estimate << ", se " << se;
  EXPECT_GT(std::abs(d.relMse - truth), bound) << "relMse " << d.relMse << ": the reference's noise should show";
}

TEST(ImageCompare, RegionCropsTheTouchedPixels) {
  // A 4 x 2 image whose pixel (x, y) holds x + 10 y in every channel.
  Image im;
  im.width = 4;
  im.height = 2;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) im.rgb.push_back(float(x + 10 * y));
  auto firstColumnRow = [](const Image& c) { return std::make_pair(c.rgb.front(), c.rgb.back()); };
  // The right half of the lower row: pixels (2, 1) and (3, 1).
  Image c = cropImage(im, 0.5, 0.5, 1.0, 1.0);
  EXPECT_EQ(c.width, 2);
  EXPECT_EQ(c.height, 1);
  EXPECT_EQ(firstColumnRow(c), std::make_pair(12.0f, 13.0f));
  // Fractions between pixel edges take every pixel they touch: x in [0.3, 0.55) -> pixels 1 and 2.
  c = cropImage(im, 0.3, 0.0, 0.55, 0.2);
  EXPECT_EQ(c.width, 2);
  EXPECT_EQ(c.height, 1);
  EXPECT_EQ(firstColumnRow(c), std::make_pair(1.0f, 2.0f));
  // The whole image is itself.
  EXPECT_EQ(cropImage(im, 0, 0, 1, 1).rgb, im.rgb);
  // Out of range, reversed or NaN fractions name the option.
  EXPECT_NE(errorOf([&] { cropImage(im, 0.5, 0, 0.5, 1, "--region"); }).find("--region"), std::string::npos);
  errorOf([&] { cropImage(im, -0.1, 0, 0.5, 1); });
  errorOf([&] { cropImage(im, 0, 0, 1.5, 1); });
  errorOf([&] { cropImage(im, 0, std::nan(""), 1, 1); });
  Image broken = im;
  broken.rgb.pop_back();
  errorOf([&] { cropImage(broken, 0, 0, 1, 1); });
}

TEST(Progress, FormatDuration) {
  EXPECT_EQ(formatDuration(0), "0:00");
  EXPECT_EQ(formatDuration(4.2), "0:04");
  EXPECT_EQ(formatDuration(59.7), "1:00");
  EXPECT_EQ(formatDuration(754), "12:34");
  EXPECT_EQ(formatDuration(3600 + 62), "1:01:02");
  EXPECT_EQ(formatDuration(-1), "--:--");
  EXPECT_EQ(formatDuration(std::numeric_limits<double>::infinity()), "--:--");
  EXPECT_EQ(formatDuration(std::nan("")), "--:--");
}

TEST(Progress, Lines) {
  Progress p("render", 100, 250000, false, true);
  EXPECT_EQ(p.barLine(45, 3.0),
            "render [#########...........] 45/100 spp  15.0 spp/s  3.8 Msamples/s  ETA 0:04");
  EXPECT_EQ(p.barLine(0, 0.0), "render [....................] 0/100 spp  ETA --:--");
  EXPECT_EQ(p.summaryLine(100, 3.2, ""), "render: 100 spp in 3.2 s (31.2 spp/s, 7.8 Msamples/s)");
  EXPECT_EQ(p.summaryLine(45, 90.0, "(interrupted)"),
            "render: 45 of 100 spp in 1:30 (0.50 spp/s, 0.12 Msamples/s) (interrupted)");
  Progress noPixels("render", 10, 0, false, true);
  EXPECT_EQ(noPixels.summaryLine(10, 2.0, ""), "render: 10 spp in 2.0 s (5.0 spp/s)");
}

TEST(Progress, TerminalDrawsBarAndSummary) {
  ::testing::internal::CaptureStderr();
  {
    Progress p("render", 4, 100, true, false);
    p.update(1);
    p.update(2);  // within 100 ms of the first: not drawn
    p.update(4);  // the last pass: always drawn
    p.finish("wrote out.exr");
  }
  std::string out = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(out.find("\rrender [#####...............] 1/4 spp"), std::string::npos) << out;
  EXPECT_EQ(out.find("2/4 spp"), std::string::npos) << out;
  EXPECT_NE(out.find("] 4/4 spp"), std::string::npos) << out;
  EXPECT_NE(out.find("\r\x1b[Krender: 4 spp in "), std::string::npos) << out;
  EXPECT_EQ(out.substr(out.size() - 15), " wrote out.exr\n") << out;
}

TEST(Progress, NonTerminalPrintsOnlySummaryAndQuietNothing) {
  ::testing::internal::CaptureStderr();
  {
    Progress p("render", 4, 100, false, false);
    p.update(4);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    ::testing::internal::CaptureStderr();
    p.finish();
    p.finish();  // idempotent
  }
  std::string out = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(out.rfind("render: 4 spp in ", 0), 0u) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;

  ::testing::internal::CaptureStderr();
  {
    Progress p("render", 4, 100, true, true);
    p.update(2);
    p.finish();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(Progress, UnfinishedBarEndsItsLine) {
  ::testing::internal::CaptureStderr();
  {
    Progress p("render", 4, 100, true, false);
    p.update(1);
  }
  std::string out = ::testing::internal::GetCapturedStderr();
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back(), '\n');
}

}  // namespace
}  // namespace nusselt
