// environment_map.cpp: OpenEXR and Radiance RGBE environment maps. See environment_map.h.
//
// Radiance RGBE files are decoded by io/radiance_hdr.cpp.
#include "io/environment_map.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

#include <ImfChromaticities.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStandardAttributes.h>

#include "io/image.h"
#include "io/radiance_hdr.h"
#include "util/error.h"

namespace nusselt {
namespace {

Error mapError(const std::string& path, const std::string& reason) {
  return Error("environment map '" + path + "': " + reason);
}

// Sets texels with a NaN, infinite or negative channel to 0 and counts them; warns about the
// count and about a map that is not 2:1.
void checkTexels(EnvironmentImage& img, const std::string& path) {
  const std::size_t n = std::size_t(img.width) * img.height;
  for (std::size_t i = 0; i < n; ++i) {
    float* t = &img.rgb[3 * i];
    bool bad = false;
    for (int c = 0; c < 3; ++c) bad = bad || !std::isfinite(t[c]) || t[c] < 0.0f;
    if (bad) {
      t[0] = t[1] = t[2] = 0.0f;
      ++img.droppedTexels;
    }
  }
  if (img.droppedTexels)
    img.warnings.push_back("environment map '" + path + "': " + std::to_string(img.droppedTexels) +
                           " texels with a NaN, infinite or negative value were set to 0");
  if (img.width != 2 * img.height)
    img.warnings.push_back("environment map '" + path + "' is " + std::to_string(img.width) + "x" +
                           std::to_string(img.height) + ", not 2:1: an equirectangular map spans 360 x 180 degrees, "
                           "so it is stretched to fit");
}

// ---- OpenEXR ----

EnvironmentImage readExrMap(const std::string& path) {
  Image image = readExr(path);  // size caps, completeness, R/G/B channels; errors name the file
  EnvironmentImage out;
  out.width = image.width;
  out.height = image.height;
  out.rgb = std::move(image.rgb);
  checkTexels(out, path);  // bad input texels first: the conversion below must not spread them
  // chromaticities: convert the file's RGB to Rec. 709 through XYZ (no chromatic adaptation: the
  // attribute's white point is kept, as Mitsuba 3 and OpenEXR's own RGBtoXYZ do). Colours outside
  // the Rec. 709 gamut get negative channels, which are clipped to 0 and counted.
  try {
    Imf::InputFile file(path.c_str());
    if (Imf::hasChromaticities(file.header())) {
      const Imf::Chromaticities fileChroma = Imf::chromaticities(file.header());
      const Imf::Chromaticities rec709;  // OpenEXR's default: Rec. 709 primaries, D65
      const Imath::M44f m = Imf::RGBtoXYZ(fileChroma, 1.0f) * Imf::XYZtoRGB(rec709, 1.0f);
      bool identity = true;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) identity = identity && std::fabs(m[i][j] - (i == j ? 1.0f : 0.0f)) < 1e-5f;
      if (!identity) {
        std::uint64_t clipped = 0;
        for (std::size_t k = 0; k + 2 < out.rgb.size(); k += 3) {
          const float r = out.rgb[k], g = out.rgb[k + 1], b = out.rgb[k + 2];
          bool clip = false;
          // Imath matrices multiply row vectors: out = (r, g, b) M.
          for (int c = 0; c < 3; ++c) {
            float v = r * m[0][c] + g * m[1][c] + b * m[2][c];
            if (!(v >= 0.0f)) {
              clip = true;
              v = 0.0f;
            }
            out.rgb[k + c] = v;
          }
          clipped += clip ? 1 : 0;
        }
        if (clipped)
          out.warnings.push_back("environment map '" + path + "': " + std::to_string(clipped) + " texels lie outside "
                                 "the Rec. 709 gamut; their negative channels were set to 0");
      }
    }
  } catch (const std::exception& e) {
    throw mapError(path, e.what());
  }
  return out;
}

}  // namespace

EnvironmentImage readEnvironmentMap(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw mapError(path, std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw mapError(path, "is a directory");
  if (!S_ISREG(st.st_mode)) throw mapError(path, "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw mapError(path, std::strerror(errno));
  char magic[4] = {0, 0, 0, 0};
  in.read(magic, 4);
  const std::size_t got = std::size_t(in.gcount());
  EnvironmentImage img;
  if (got == 4 && std::uint8_t(magic[0]) == 0x76 && std::uint8_t(magic[1]) == 0x2f && std::uint8_t(magic[2]) == 0x31 &&
      std::uint8_t(magic[3]) == 0x01) {
    img = readExrMap(path);
  } else if (got >= 2 && magic[0] == '#' && magic[1] == '?') {
    // At most 4 bytes per texel plus a header: refuse absurd sizes before reading.
    const std::uint64_t cap = 4ull * std::uint64_t(kMaxImagePixels) + (1u << 20);
    if (std::uint64_t(st.st_size) > cap) throw mapError(path, "file is larger than any supported map");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size()));
    if (std::size_t(in.gcount()) != bytes.size()) throw mapError(path, "read error");
    RgbeImage rgbe = decodeRadianceHdr(bytes.data(), bytes.size(), path);
    img.width = rgbe.width;
    img.height = rgbe.height;
    img.rgb = std::move(rgbe.rgb);
    checkTexels(img, path);
  } else {
    throw mapError(path, "unknown format (an equirectangular map must be OpenEXR or Radiance RGBE .hdr)");
  }
  return img;
}

}  // namespace nusselt
