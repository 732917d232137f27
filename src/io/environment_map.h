// environment_map.h: reading equirectangular environment maps: OpenEXR (through the OpenEXR
// library: scanline or tiled, any compression it supports, a `chromaticities` attribute
// converted to Rec. 709 primaries) and Radiance RGBE (.hdr, our own reader: flat, run-length
// encoded and old-style RLE scanlines). The format is told by the file's first bytes, not its
// name. docs/environment.md describes both and what is refused.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace nusselt {

struct EnvironmentImage {
  int width = 0, height = 0;
  std::vector<float> rgb;               // 3 * width * height, linear Rec. 709, top row first
  std::uint64_t droppedTexels = 0;      // texels with a NaN, infinite or negative channel, set to 0
  std::vector<std::string> warnings;    // one line each, naming the file (not 2:1, dropped texels, ...)
};

// Reads the map at `path`. Throws nusselt::Error naming the file and the reason when it is
// missing, unreadable, truncated, of an unknown format, larger than kMaxImageSide per side or
// kMaxImagePixels in all (io/image.h), or malformed. Bad texels and a width that is not twice the
// height are warnings, not errors.
EnvironmentImage readEnvironmentMap(const std::string& path);

// Decodes a Radiance RGBE (.hdr) file held in memory; `name` is used in messages. For tests and
// the fuzzer; readEnvironmentMap calls it for .hdr files.
EnvironmentImage decodeRadianceHdr(const std::uint8_t* data, std::size_t size, const std::string& name);

// Encodes rgb (3 * width * height floats, top row first) as a flat (uncompressed) or run-length
// encoded Radiance RGBE file in memory. For generated test maps and tools; not a general writer.
std::vector<std::uint8_t> encodeRadianceHdr(const std::vector<float>& rgb, int width, int height, bool rle);

}  // namespace nusselt
