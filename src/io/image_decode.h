// image_decode.h: PNG and JPEG decoding of untrusted bytes (glTF textures) into 8-bit RGBA,
// through libpng and libjpeg-turbo (TurboJPEG API): maintained decoders, fuzzed by
// tests/fuzz/fuzz_image.cpp. Not stb_image (Debian 12's stb 2.27 has reported heap overflows).
//
// The bytes are identified by their signature, not by a file name or a media type. Colour
// information of the file (PNG gAMA, sRGB, iCCP, cHRM; JPEG ICC or EXIF) is ignored, as glTF 2.0
// requires: the code values are returned as they are stored, and the user of the texture decides
// whether they are sRGB-encoded colours or linear data.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace nusselt {

struct ImageLimits {
  // Width x height above this is refused before any pixel is decoded (2^26: 8192 x 8192, a
  // 256 MiB RGBA buffer).
  std::uint64_t maxPixels = std::uint64_t(1) << 26;
  // Encoded input above this is refused without being parsed.
  std::uint64_t maxBytes = std::uint64_t(1) << 28;
};

enum class ImageFormat { Png, Jpeg };

// 8-bit RGBA, row-major, top row first (the first row of the file), 4 * width * height bytes.
struct DecodedImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  ImageFormat format = ImageFormat::Png;
  int sourceChannels = 0;  // 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA (palette: 3, or 4 with tRNS)
  int sourceBits = 8;      // bits per channel in the file: 1, 2, 4, 8 or 16 (PNG), 8 (JPEG)
};

// Decodes a PNG or a JPEG:
//   PNG: every colour type (grey, grey+alpha, palette with or without tRNS, RGB, RGBA) and bit
//        depth (1 to 16); sub-byte grey and palette are expanded, 16-bit channels are scaled to
//        8 bits with rounding (v * 255 / 65535), grey is replicated to RGB, a missing alpha is
//        255, interlaced files are de-interlaced. Ancillary chunks with a bad CRC are skipped
//        (libpng's default); a bad critical chunk is an error.
//   JPEG: baseline and progressive, grey or YCbCr (CMYK/YCCK refused), at most 500 scans (a
//        progressive file with more is a known denial of service), alpha 255. A warning of
//        libjpeg (premature end of data, a corrupt segment) is an error: no grey-filled
//        half-image comes back.
// Throws nusselt::Error on anything else, too large or corrupt, with a message that describes
// the problem without the caller's context (the caller prefixes the file and the glTF field) and
// never contains raw bytes of the input.
DecodedImage decodeImage(const std::uint8_t* bytes, std::size_t size, const ImageLimits& limits = {});

// "PNG" or "JPEG".
const char* imageFormatName(ImageFormat format);

// A short, printable description of the first bytes of an unrecognised file, e.g.
// "52 49 46 46 (\"RIFF\": WebP?)", for error messages.
std::string describeSignature(const std::uint8_t* bytes, std::size_t size);

}  // namespace nusselt
