// radiance_hdr.cpp: Radiance RGBE (.hdr) decoding and a small encoder. See radiance_hdr.h.
//
// The reader is ours (about 150 lines) rather than stb_image's: Debian's stb 2.27 carries
// reported heap overflows in its decoders (the reason src/io/image_decode.cpp does not use it
// either), and no other Debian package reads .hdr without pulling in a whole imaging library
// (OpenImageIO, ImageMagick). Every read below is bounds-checked against the buffer; the fuzzer
// tests/fuzz/fuzz_hdr.cpp drives it.
#include "io/radiance_hdr.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "util/error.h"

namespace nusselt {
namespace {

Error mapError(const std::string& path, const std::string& reason) {
  return Error("environment map '" + path + "': " + reason);
}

void checkSize(const std::string& path, std::int64_t w, std::int64_t h, std::int64_t maxTexels) {
  if (w <= 0 || h <= 0) throw mapError(path, "empty image");
  if (w > kHdrMaxSide || h > kHdrMaxSide || w * h > maxTexels)
    throw mapError(path, "image " + std::to_string(w) + "x" + std::to_string(h) + " is larger than supported (at most " +
                             std::to_string(kHdrMaxSide) + " per side and " + std::to_string(maxTexels) + " texels)");
}

struct Reader {
  const std::uint8_t* p;
  std::size_t size;
  std::size_t pos = 0;
  const std::string& name;

  bool done() const { return pos >= size; }
  std::uint8_t byte() {
    if (pos >= size) throw mapError(name, "file is truncated (pixel data ends early)");
    return p[pos++];
  }
  // A header line without its '\n' (at most 4096 bytes: no real header line is longer).
  std::string line() {
    std::string s;
    while (true) {
      if (pos >= size) throw mapError(name, "file is truncated (in the header)");
      char c = char(p[pos++]);
      if (c == '\n') return s;
      if (s.size() >= 4096) throw mapError(name, "header line longer than 4096 bytes: not a Radiance file");
      s.push_back(c);
    }
  }
};

// Radiance's colr_color(): (mantissa + 0.5) 2^(e - 136); e = 0 is black.
inline void rgbeToFloat(const std::uint8_t* c, float* out) {
  if (c[3] == 0) {
    out[0] = out[1] = out[2] = 0.0f;
    return;
  }
  const float f = std::ldexp(1.0f, int(c[3]) - (128 + 8));
  for (int k = 0; k < 3; ++k) out[k] = (float(c[k]) + 0.5f) * f;
}

}  // namespace

RgbeImage decodeRadianceHdr(const std::uint8_t* data, std::size_t size, const std::string& name,
                            std::int64_t maxTexels) {
  Reader r{data, size, 0, name};
  // ---- Header: "#?RADIANCE" (or any "#?" program name), variables, an empty line ----
  std::string magic = r.line();
  if (magic.size() < 2 || magic[0] != '#' || magic[1] != '?')
    throw mapError(name, "not a Radiance RGBE file (no '#?' signature)");
  double exposure = 1.0;
  for (int lines = 0;; ++lines) {
    if (lines > 1000) throw mapError(name, "header has more than 1000 lines");
    std::string l = r.line();
    if (l.empty()) break;
    if (l.rfind("FORMAT=", 0) == 0) {
      std::string f = l.substr(7);
      while (!f.empty() && (f.back() == ' ' || f.back() == '\r')) f.pop_back();
      if (f != "32-bit_rle_rgbe")
        throw mapError(name, "FORMAT=" + f + " is not supported (only 32-bit_rle_rgbe; XYZE maps are not read)");
    } else if (l.rfind("EXPOSURE=", 0) == 0) {
      // Pixel values are the original radiance times every EXPOSURE in the header: undo it.
      char* end = nullptr;
      double e = std::strtod(l.c_str() + 9, &end);
      if (!(e > 0) || !std::isfinite(e)) throw mapError(name, "EXPOSURE=" + l.substr(9) + " is not a positive number");
      exposure *= e;
    }
  }
  // ---- Resolution: "-Y height +X width" (top row first, left to right: the usual orientation) ----
  std::string res = r.line();
  char ys[3] = {0}, xs[3] = {0};
  long h = 0, w = 0;
  int consumed = 0;
  if (std::sscanf(res.c_str(), "%2s %ld %2s %ld%n", ys, &h, xs, &w, &consumed) != 4 || std::strcmp(ys, "-Y") != 0 ||
      std::strcmp(xs, "+X") != 0)
    throw mapError(name, "resolution line '" + res.substr(0, 60) + "' is not of the form '-Y height +X width' (other "
                         "orientations are not supported)");
  checkSize(name, w, h, maxTexels);
  RgbeImage img;
  img.width = int(w);
  img.height = int(h);
  // Rows are added as they are decoded: a header that claims a huge image in a short file fails
  // at its first missing byte, not after allocating the whole image.
  std::vector<std::uint8_t> scan(std::size_t(4) * w);

  for (long y = 0; y < h; ++y) {
    // New-style run-length encoding: 2, 2, width (big-endian, < 32768), then each of the four
    // components of the scanline as runs (count > 128: count - 128 copies of one byte) and
    // literals (count <= 128 bytes).
    bool rle = false;
    if (w >= 8 && w < 32768 && r.pos + 4 <= r.size && r.p[r.pos] == 2 && r.p[r.pos + 1] == 2 &&
        (r.p[r.pos + 2] & 0x80) == 0) {
      rle = true;
      const long sw = (long(r.p[r.pos + 2]) << 8) | r.p[r.pos + 3];
      if (sw != w) throw mapError(name, "scanline " + std::to_string(y) + " has width " + std::to_string(sw) +
                                            ", the header says " + std::to_string(w));
      r.pos += 4;
      for (int c = 0; c < 4; ++c) {
        long x = 0;
        while (x < w) {
          unsigned count = r.byte();
          if (count > 128) {
            count -= 128;
            if (x + long(count) > w) throw mapError(name, "run overflows scanline " + std::to_string(y));
            std::uint8_t v = r.byte();
            for (unsigned k = 0; k < count; ++k) scan[4 * (x++) + c] = v;
          } else {
            if (count == 0 || x + long(count) > w)
              throw mapError(name, "bad literal count in scanline " + std::to_string(y));
            for (unsigned k = 0; k < count; ++k) scan[4 * (x++) + c] = r.byte();
          }
        }
      }
    }
    if (!rle) {
      // Flat RGBE pixels, with old-style runs: (1, 1, 1, n) repeats the previous pixel n << shift
      // times (consecutive run markers shift by 8 more bits).
      long x = 0;
      int shift = 0;
      while (x < w) {
        std::uint8_t c[4] = {r.byte(), r.byte(), r.byte(), r.byte()};
        if (c[0] == 1 && c[1] == 1 && c[2] == 1) {
          if (x == 0) throw mapError(name, "old-style run at the start of scanline " + std::to_string(y));
          if (shift > 16) throw mapError(name, "old-style run too long in scanline " + std::to_string(y));
          const long count = long(c[3]) << shift;
          if (x + count > w) throw mapError(name, "run overflows scanline " + std::to_string(y));
          for (long k = 0; k < count; ++k, ++x) std::memcpy(&scan[4 * x], &scan[4 * (x - 1)], 4);
          shift += 8;
        } else {
          std::memcpy(&scan[4 * x], c, 4);
          ++x;
          shift = 0;
        }
      }
    }
    img.rgb.resize(std::size_t(3) * w * (y + 1));
    float* row = &img.rgb[std::size_t(3) * w * y];
    for (long x = 0; x < w; ++x) {
      rgbeToFloat(&scan[4 * x], row + 3 * x);
      if (exposure != 1.0)
        for (int k = 0; k < 3; ++k) {
          // In double: a tiny EXPOSURE can make 1 / exposure overflow a float, and 0 x inf would be
          // NaN. A value beyond the float range is +Inf (the environment reader drops and counts
          // such texels); black stays 0.
          const double v = double(row[3 * x + k]) / exposure;
          row[3 * x + k] = v > double(std::numeric_limits<float>::max()) ? std::numeric_limits<float>::infinity()
                                                                         : float(v);
        }
    }
  }
  return img;
}

std::vector<std::uint8_t> encodeRadianceHdr(const std::vector<float>& rgb, int width, int height, bool rle) {
  std::string head = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(height) + " +X " +
                     std::to_string(width) + "\n";
  std::vector<std::uint8_t> out(head.begin(), head.end());
  std::vector<std::uint8_t> scan(std::size_t(4) * width);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float* c = &rgb[3 * (std::size_t(y) * width + x)];
      float m = std::max(c[0], std::max(c[1], c[2]));
      std::uint8_t* e = &scan[4 * x];
      if (!(m > 1e-32f)) {
        e[0] = e[1] = e[2] = e[3] = 0;
      } else {
        int ex;
        float f = std::frexp(m, &ex) * 256.0f / m;  // m = f' 2^ex, f' in [0.5, 1)
        for (int k = 0; k < 3; ++k) e[k] = std::uint8_t(std::min(255.0f, std::max(0.0f, c[k] * f)));
        e[3] = std::uint8_t(ex + 128);
      }
    }
    if (rle && width >= 8 && width < 32768) {
      out.insert(out.end(), {2, 2, std::uint8_t(width >> 8), std::uint8_t(width & 255)});
      for (int c = 0; c < 4; ++c) {
        int x = 0;
        while (x < width) {
          int run = 1;
          while (x + run < width && run < 127 && scan[4 * (x + run) + c] == scan[4 * x + c]) ++run;
          if (run >= 3) {
            out.push_back(std::uint8_t(128 + run));
            out.push_back(scan[4 * x + c]);
            x += run;
          } else {
            int n = 0;
            std::vector<std::uint8_t> lit;
            while (x + n < width && n < 128) {
              if (x + n + 2 < width && scan[4 * (x + n) + c] == scan[4 * (x + n + 1) + c] &&
                  scan[4 * (x + n) + c] == scan[4 * (x + n + 2) + c])
                break;
              lit.push_back(scan[4 * (x + n) + c]);
              ++n;
            }
            out.push_back(std::uint8_t(n));
            out.insert(out.end(), lit.begin(), lit.end());
            x += n;
          }
        }
      }
    } else {
      out.insert(out.end(), scan.begin(), scan.end());
    }
  }
  return out;
}

}  // namespace nusselt
