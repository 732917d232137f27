// image.cpp: OpenEXR and PNG output, EXR input, image comparison. See image.h.
#include "io/image.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <set>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Iex.h>
#include <ImfChannelList.h>
#include <array>
#include <type_traits>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

// stb_image_write: the implementation lives in this translation unit only. STATIC keeps its
// symbols local, so it cannot clash with another copy (tinygltf can compile one in too);
// NO_STDIO because we write through our own checked temp-file path, never through fopen.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include "util/error.h"

namespace nusselt {
namespace {

// The optional three-channel groups of an Image, by channel-name prefix.
template <class ImageT>
auto optionalGroups(ImageT& image) {
  using Vec = std::conditional_t<std::is_const_v<ImageT>, const std::vector<float>, std::vector<float>>;
  return std::array<std::pair<const char*, Vec*>, 3>{
      {{"var", &image.variance}, {"sum", &image.sum}, {"sumSq", &image.sumSq}}};
}


Error writeError(const std::string& path, const std::string& reason) {
  return Error("cannot write '" + path + "': " + reason);
}

Error readError(const std::string& path, const std::string& reason) {
  return Error("cannot read EXR image '" + path + "': " + reason);
}

// Checks that the image's buffers match its dimensions and that the dimensions are within what
// readExr accepts. Called before any file is created, so a bad image never touches the disk.
void checkImage(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0)
    throw writeError(path, "image is empty (" + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + ")");
  if (image.width > kMaxImageSide || image.height > kMaxImageSide ||
      int64_t(image.width) * image.height > kMaxImagePixels)
    throw writeError(path, "image " + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + " is larger than supported");
  size_t expected = size_t(3) * size_t(image.width) * size_t(image.height);
  if (image.rgb.size() != expected)
    throw writeError(path, "image is " + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + " but has " +
                               std::to_string(image.rgb.size()) + " RGB values (expected " +
                               std::to_string(expected) + ")");
  for (auto& [prefix, values] : optionalGroups(image))
    if (!values->empty() && values->size() != expected)
      throw writeError(path, "image has " + std::to_string(values->size()) + " " + prefix +
                                 " values (expected 0 or " + std::to_string(expected) + ")");
}

// Writes all n bytes, retrying on EINTR and short writes. Returns 0 or an errno value.
int writeAll(int fd, const char* data, size_t n) {
  while (n > 0) {
    ssize_t w = ::write(fd, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (w == 0) return EIO;  // cannot happen for regular files; don't loop forever
    data += w;
    n -= size_t(w);
  }
  return 0;
}

// A temporary file next to the destination, removed on destruction unless commit() succeeded.
// Being in the same directory matters: rename() is only atomic within one filesystem.
class TempFile {
 public:
  explicit TempFile(const std::string& path) : path_(path) {
    size_t slash = path.find_last_of('/');
    std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
    if (base.empty() || base == "." || base == "..") throw writeError(path, "not a file name");
    dir_ = dir;
    // pid + a per-process counter: concurrent writers (other processes, or other threads of
    // ours) never share a temporary file. O_EXCL so we never write through someone's file or
    // symlink; on a stale leftover of a dead process with our pid, try the next counter.
    static std::atomic<unsigned> counter{0};
    for (int attempt = 0; attempt < 100; ++attempt) {
      tmp_ = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + "." +
             base + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
      fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd_ >= 0 || errno != EEXIST) break;
    }
    if (fd_ < 0)
      throw writeError(path, "cannot create a temporary file in '" + dir + "': " +
                                 std::strerror(errno));
  }

  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(tmp_.c_str());
  }

  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  int fd() const { return fd_; }
  const std::string& tmpPath() const { return tmp_; }

  void write(const void* data, size_t n) {
    if (int err = writeAll(fd_, static_cast<const char*>(data), n)) fail(err);
  }

  // fsync before rename: otherwise a crash shortly after could leave the new name pointing at
  // an empty file (the rename reaching the disk before the data does) on some filesystems.
  void commit() {
    if (::fsync(fd_) != 0) fail(errno);
    int fd = fd_;
    fd_ = -1;
    // close() can report deferred write errors (NFS, quota); a file we could not close is not
    // known to be complete.
    if (::close(fd) != 0) fail(errno);
    if (::rename(tmp_.c_str(), path_.c_str()) != 0) fail(errno);
    committed_ = true;
    // Make the rename itself durable. Best effort: the image is complete and in place either
    // way, and some filesystems refuse fsync on directories.
    int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      (void)::fsync(dfd);
      ::close(dfd);
    }
  }

  [[noreturn]] void fail(int err) { throw writeError(path_, std::strerror(err)); }

 private:
  std::string path_, dir_, tmp_;
  int fd_ = -1;
  bool committed_ = false;
};

// An Imf::OStream over a file descriptor that checks every write. The error is also kept in the
// stream because OpenEXR's OutputFile destructor writes the line offset table and swallows any
// exception while doing so; we check error() after the OutputFile is gone.
class FdOStream : public Imf::OStream {
 public:
  FdOStream(const std::string& name, int fd) : Imf::OStream(name.c_str()), fd_(fd) {
    buffer_.reserve(kBufferSize);
  }

  void write(const char c[], int n) override {
    if (error_) throwError();
    if (n < 0) throw Iex::ArgExc("negative write size");
    if (buffer_.size() + size_t(n) > kBufferSize) flush();
    // OpenEXR writes headers a few bytes at a time; buffering avoids a syscall per field.
    if (size_t(n) >= kBufferSize) {
      if (int err = writeAll(fd_, c, size_t(n))) setError(err);
    } else {
      buffer_.insert(buffer_.end(), c, c + n);
    }
    position_ += uint64_t(n);
  }

  uint64_t tellp() override { return position_; }

  void seekp(uint64_t pos) override {
    flush();
    if (::lseek(fd_, off_t(pos), SEEK_SET) < 0) setError(errno);
    position_ = pos;
  }

  void flush() {
    if (error_) throwError();
    if (buffer_.empty()) return;
    int err = writeAll(fd_, buffer_.data(), buffer_.size());
    buffer_.clear();
    if (err) setError(err);
  }

  int error() const { return error_; }

 private:
  static constexpr size_t kBufferSize = 1 << 16;

  [[noreturn]] void setError(int err) {
    error_ = err;
    throwError();
  }
  [[noreturn]] void throwError() { throw Iex::IoExc(std::strerror(error_)); }

  int fd_;
  std::vector<char> buffer_;
  uint64_t position_ = 0;
  int error_ = 0;
};

// The attributes every EXR header carries; user metadata may not use these names, and readExr
// does not report them as metadata.
bool isRequiredAttribute(const std::string& name) {
  static const std::set<std::string> kRequired = {
      "channels",         "compression",        "dataWindow",       "displayWindow",
      "lineOrder",        "pixelAspectRatio",   "screenWindowCenter", "screenWindowWidth",
      "tiles",            "type",               "name",             "version",
      "chunkCount"};
  return kRequired.count(name) != 0;
}

Imf::Header makeHeader(const std::string& path, const Image& image, const ImageMetadata& meta) {
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.lineOrder() = Imf::INCREASING_Y;
  Imf::ChannelList& channels = header.channels();
  for (const char* name : {"R", "G", "B"}) channels.insert(name, Imf::Channel(Imf::FLOAT));
  for (auto& [prefix, values] : optionalGroups(image))
    if (!values->empty())
      for (const char* c : {".R", ".G", ".B"}) channels.insert(std::string(prefix) + c, Imf::Channel(Imf::FLOAT));

  std::set<std::string> seen;
  auto checkName = [&](const std::string& name) {
    if (name.empty()) throw writeError(path, "metadata attribute with an empty name");
    if (name.size() > 255)
      throw writeError(path, "metadata attribute name '" + name.substr(0, 40) +
                                 "...' is longer than 255 bytes");
    if (isRequiredAttribute(name))
      throw writeError(path, "metadata attribute name '" + name + "' is reserved by OpenEXR");
    if (!seen.insert(name).second)
      throw writeError(path, "metadata attribute '" + name + "' given twice");
  };
  for (const auto& [name, value] : meta.strings) {
    checkName(name);
    header.insert(name, Imf::StringAttribute(value));
  }
  for (const auto& [name, value] : meta.ints) {
    checkName(name);
    if (value >= std::numeric_limits<int>::min() && value <= std::numeric_limits<int>::max())
      header.insert(name, Imf::IntAttribute(int(value)));
    else  // exact decimal digits; see image.h
      header.insert(name, Imf::StringAttribute(std::to_string(value)));
  }
  for (const auto& [name, value] : meta.doubles) {
    checkName(name);
    header.insert(name, Imf::DoubleAttribute(value));
  }
  return header;
}

// A slice of interleaved 3-float pixels starting at `base` (which points at the channel's first
// value), for the data window `window`.
Imf::Slice interleavedSlice(const float* base, const Imath::Box2i& window, int width) {
  return Imf::Slice::Make(Imf::FLOAT, base, window, 3 * sizeof(float),
                          size_t(3) * sizeof(float) * size_t(width));
}

}  // namespace

std::optional<std::string> findString(const ImageMetadata& meta, const std::string& name) {
  for (const auto& [key, value] : meta.strings)
    if (key == name) return value;
  return std::nullopt;
}

std::optional<int64_t> findInt(const ImageMetadata& meta, const std::string& name) {
  for (const auto& [key, value] : meta.ints)
    if (key == name) return value;
  // Values outside the int32 range are stored as decimal strings (see image.h).
  if (auto text = findString(meta, name)) {
    if (text->empty()) return std::nullopt;
    errno = 0;
    char* end = nullptr;
    long long v = std::strtoll(text->c_str(), &end, 10);
    if (errno == 0 && end == text->c_str() + text->size()) return int64_t(v);
  }
  return std::nullopt;
}

std::optional<double> findDouble(const ImageMetadata& meta, const std::string& name) {
  for (const auto& [key, value] : meta.doubles)
    if (key == name) return value;
  return std::nullopt;
}

void writeExr(const std::string& path, const Image& image, const ImageMetadata& meta) {
  checkImage(path, image);
  Imf::Header header;
  try {
    header = makeHeader(path, image, meta);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw writeError(path, e.what());
  }

  TempFile tmp(path);
  FdOStream stream(tmp.tmpPath(), tmp.fd());
  try {
    {
      // The FrameBuffer only reads from our buffers (OpenEXR's API takes char*, hence the casts).
      Imf::FrameBuffer frame;
      const Imath::Box2i window = header.dataWindow();
      const float* rgb = image.rgb.data();
      frame.insert("R", interleavedSlice(rgb + 0, window, image.width));
      frame.insert("G", interleavedSlice(rgb + 1, window, image.width));
      frame.insert("B", interleavedSlice(rgb + 2, window, image.width));
      for (auto& [prefix, values] : optionalGroups(image))
        if (!values->empty()) {
          const float* v = values->data();
          frame.insert(std::string(prefix) + ".R", interleavedSlice(v + 0, window, image.width));
          frame.insert(std::string(prefix) + ".G", interleavedSlice(v + 1, window, image.width));
          frame.insert(std::string(prefix) + ".B", interleavedSlice(v + 2, window, image.width));
        }
      Imf::OutputFile file(stream, header);
      file.setFrameBuffer(frame);
      file.writePixels(image.height);
      // ~OutputFile writes the line offset table (errors recorded in the stream, see FdOStream).
    }
    stream.flush();
  } catch (const std::exception& e) {
    // Prefer the OS error (e.g. "No space left on device") over OpenEXR's wrapping of it.
    throw writeError(path, stream.error() ? std::strerror(stream.error()) : e.what());
  }
  if (stream.error()) throw writeError(path, std::strerror(stream.error()));
  tmp.commit();
}

Image readExr(const std::string& path, ImageMetadata* meta) {
  // Open it ourselves first: OpenEXR's message for a missing file is less direct than strerror.
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw readError(path, std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw readError(path, "is a directory");
  if (::access(path.c_str(), R_OK) != 0) throw readError(path, std::strerror(errno));

  Image image;
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    int64_t width = int64_t(window.max.x) - window.min.x + 1;
    int64_t height = int64_t(window.max.y) - window.min.y + 1;
    if (width <= 0 || height <= 0) throw readError(path, "empty data window");
    if (width > kMaxImageSide || height > kMaxImageSide || width * height > kMaxImagePixels)
      throw readError(path, "image " + std::to_string(width) + "x" + std::to_string(height) +
                                " is larger than supported (at most " +
                                std::to_string(kMaxImageSide) + " per side and " +
                                std::to_string(kMaxImagePixels) + " pixels)");

    const Imf::ChannelList& channels = header.channels();
    auto usable = [&](const char* name) {
      const Imf::Channel* c = channels.findChannel(name);
      if (c && (c->xSampling != 1 || c->ySampling != 1))
        throw readError(path, std::string("channel ") + name + " is subsampled");
      return c != nullptr;
    };
    for (const char* name : {"R", "G", "B"})
      if (!usable(name)) throw readError(path, std::string("no ") + name + " channel");
    auto hasGroup = [&](const std::string& prefix) {
      return usable((prefix + ".R").c_str()) && usable((prefix + ".G").c_str()) && usable((prefix + ".B").c_str());
    };

    // A file cut short (crash, full disk of whoever wrote it) would otherwise read as an image
    // with missing rows silently zeroed, or fail later with a less clear message.
    if (!file.isComplete()) throw readError(path, "file is truncated or incomplete");

    image.width = int(width);
    image.height = int(height);
    image.rgb.assign(size_t(3) * size_t(width) * size_t(height), 0.0f);
    for (auto& [prefix, values] : optionalGroups(image))
      if (hasGroup(prefix)) values->assign(image.rgb.size(), 0.0f);

    Imf::FrameBuffer frame;
    float* rgb = image.rgb.data();
    frame.insert("R", interleavedSlice(rgb + 0, window, image.width));
    frame.insert("G", interleavedSlice(rgb + 1, window, image.width));
    frame.insert("B", interleavedSlice(rgb + 2, window, image.width));
    for (auto& [prefix, values] : optionalGroups(image))
      if (!values->empty()) {
        float* v = values->data();
        frame.insert(std::string(prefix) + ".R", interleavedSlice(v + 0, window, image.width));
        frame.insert(std::string(prefix) + ".G", interleavedSlice(v + 1, window, image.width));
        frame.insert(std::string(prefix) + ".B", interleavedSlice(v + 2, window, image.width));
      }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);

    if (meta) {
      *meta = ImageMetadata{};
      for (auto it = header.begin(); it != header.end(); ++it) {
        std::string name = it.name();
        if (isRequiredAttribute(name)) continue;
        const Imf::Attribute& a = it.attribute();
        if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
          meta->strings.emplace_back(name, s->value());
        else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
          meta->ints.emplace_back(name, int64_t(i->value()));
        else if (auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a))
          meta->doubles.emplace_back(name, d->value());
        else if (auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a))
          meta->doubles.emplace_back(name, double(f->value()));
        // Other types (vectors, matrices, chromaticities, ...) have no place in ImageMetadata.
      }
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw readError(path, e.what());
  }
  return image;
}

uint8_t toSrgb8(float linear) {
  // !(x > 0) also catches NaN, which would otherwise turn into an arbitrary code value.
  if (!(linear > 0.0f)) return 0;
  if (linear >= 1.0f) return 255;
  double l = linear;
  double encoded = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
  return uint8_t(std::clamp(encoded * 255.0 + 0.5, 0.0, 255.0));
}

void writePng(const std::string& path, const Image& image, float exposureStops) {
  checkImage(path, image);
  const float scale = std::exp2(exposureStops);
  std::vector<uint8_t> pixels(image.rgb.size());
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = toSrgb8(image.rgb[i] * scale);

  // Encode into memory: stb's write callback cannot report errors, so the file writing happens
  // afterwards, checked, through TempFile.
  std::vector<uint8_t> png;
  auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<uint8_t>*>(context);
    const auto* bytes = static_cast<const uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, pixels.data(),
                              image.width * 3))
    throw writeError(path, "PNG encoding failed (out of memory?)");

  TempFile tmp(path);
  tmp.write(png.data(), png.size());
  tmp.commit();
}

Image errorMap(const Image& a, const Image& reference) {
  compareImages(a, reference);  // its size checks
  Image map;
  map.width = a.width;
  map.height = a.height;
  map.rgb.resize(a.rgb.size());
  for (size_t p = 0; p + 2 < a.rgb.size(); p += 3) {
    double rel = 0;
    for (size_t c = 0; c < 3; ++c) {
      const double diff = double(a.rgb[p + c]) - double(reference.rgb[p + c]);
      rel += diff * diff / (double(reference.rgb[p + c]) * reference.rgb[p + c] + 0.01);
    }
    const double e = std::sqrt(rel / 3.0);
    const float v = std::isnan(e) ? 1.0f : static_cast<float>(std::min(e, 1.0));
    map.rgb[p] = map.rgb[p + 1] = map.rgb[p + 2] = v;
  }
  return map;
}

ImageDifference compareImages(const Image& a, const Image& reference) {
  auto checkSize = [](const Image& image, const char* which) {
    size_t expected = size_t(3) * size_t(std::max(image.width, 0)) *
                      size_t(std::max(image.height, 0));
    if (image.width < 0 || image.height < 0 || image.rgb.size() != expected)
      throw Error(std::string("compareImages: ") + which + " image is " +
                  std::to_string(image.width) + "x" + std::to_string(image.height) + " but has " +
                  std::to_string(image.rgb.size()) + " RGB values");
  };
  checkSize(a, "first");
  checkSize(reference, "reference");
  if (a.width != reference.width || a.height != reference.height)
    throw Error("compareImages: image is " + std::to_string(a.width) + "x" +
                std::to_string(a.height) + " but the reference is " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height));

  ImageDifference d;
  const size_t n = a.rgb.size();
  if (n == 0) return d;
  // Accumulate in double: a 4K image has 25M values, far past float's exact-sum range.
  double relSum = 0, sqSum = 0, sumA = 0, sumB = 0, maxAbs = 0, refSum = 0;
  bool nan = false;
  const bool refVariance = reference.variance.size() == n;
  for (size_t i = 0; i < n; ++i) {
    double x = a.rgb[i], r = reference.rgb[i];
    double diff = x - r;
    relSum += diff * diff / (r * r + 0.01);
    if (refVariance) refSum += double(reference.variance[i]) / (r * r + 0.01);
    sqSum += diff * diff;
    sumA += x;
    sumB += r;
    if (std::isnan(diff)) nan = true;
    else maxAbs = std::max(maxAbs, std::abs(diff));
  }
  d.relMse = relSum / double(n);
  d.mse = sqSum / double(n);
  d.meanA = sumA / double(n);
  d.meanB = sumB / double(n);
  d.maxAbs = nan ? std::numeric_limits<double>::quiet_NaN() : maxAbs;
  if (refVariance) d.referenceRelMse = refSum / double(n);
  return d;
}

Image cropImage(const Image& image, double x0, double y0, double x1, double y1, const std::string& what) {
  auto fraction = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 1.0; };
  if (!fraction(x0) || !fraction(y0) || !fraction(x1) || !fraction(y1) || !(x0 < x1) || !(y0 < y1))
    throw Error(what + ": expected fractions 0 <= x0 < x1 <= 1 and 0 <= y0 < y1 <= 1 of the image, got " +
                std::to_string(x0) + "," + std::to_string(y0) + "," + std::to_string(x1) + "," + std::to_string(y1));
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() != std::size_t(3) * image.width * image.height)
    throw Error(what + ": the image is empty or its size does not match its pixels");
  // Every pixel the fractions touch: floor(x0 w) < ceil(x1 w) <= w when x0 < x1 <= 1.
  int px0 = int(std::floor(x0 * image.width)), px1 = int(std::ceil(x1 * image.width));
  int py0 = int(std::floor(y0 * image.height)), py1 = int(std::ceil(y1 * image.height));
  Image out;
  out.width = px1 - px0;
  out.height = py1 - py0;
  out.rgb.reserve(std::size_t(3) * out.width * out.height);
  const bool variance = image.variance.size() == image.rgb.size();  // kept: diff --region uses it
  for (int y = py0; y < py1; ++y)
    for (int x = px0; x < px1; ++x)
      for (int c = 0; c < 3; ++c) {
        const std::size_t i = (std::size_t(y) * image.width + x) * 3 + c;
        out.rgb.push_back(image.rgb[i]);
        if (variance) out.variance.push_back(image.variance[i]);
      }
  return out;
}

}  // namespace nusselt
