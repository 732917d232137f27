// environment_map.h: reading equirectangular environment maps: OpenEXR (through the OpenEXR
// library: scanline or tiled, any compression it supports, a `chromaticities` attribute
// converted to Rec. 709 primaries) and Radiance RGBE (.hdr, our own reader: flat, run-length
// encoded and old-style RLE scanlines). The format is told by the file's first bytes, not its
// name. docs/environment.md describes both and what is refused.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/radiance_hdr.h"

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


}  // namespace nusselt
