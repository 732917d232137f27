// radiance_hdr.h: Radiance RGBE (.hdr) images: a careful decoder (flat, run-length encoded and
// old-style-run scanlines, EXPOSURE honoured, XYZE and unusual orientations refused) and a small
// encoder for generated test maps. No OpenEXR or Vulkan: the fuzzer links it alone.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace nusselt {

// The size caps (the same as io/image.h's kMaxImageSide and kMaxImagePixels).
constexpr std::int64_t kHdrMaxSide = 65536;
constexpr std::int64_t kHdrMaxTexels = std::int64_t(1) << 28;

struct RgbeImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 * width * height, top row first
};

// Decodes a Radiance RGBE file held in memory; `name` is used in messages. Throws nusselt::Error
// naming it and the problem (no signature, unsupported FORMAT or orientation, more than
// kHdrMaxSide per side or maxTexels in all, truncated, runs that overflow a scanline, ...).
// Memory grows with the rows actually decoded.
RgbeImage decodeRadianceHdr(const std::uint8_t* data, std::size_t size, const std::string& name,
                            std::int64_t maxTexels = kHdrMaxTexels);

// Encodes rgb (3 * width * height floats, top row first) as a flat (uncompressed) or run-length
// encoded Radiance RGBE file in memory. For generated test maps and tools; not a general writer.
std::vector<std::uint8_t> encodeRadianceHdr(const std::vector<float>& rgb, int width, int height, bool rle);

}  // namespace nusselt
