// fuzz_image.cpp: libFuzzer target for the PNG and JPEG decoders (io/image_decode.h, issue 18).
//
// The bytes are an image file as a glTF scene would embed it. nusselt::Error is the decoder's
// one documented failure; any other exception, a crash, a leak, an ASan or UBSan report, or a
// decoded image that breaks its contract (size, dimensions within the caps) is a finding. The
// pixel cap is lowered to 2^20 so that a header claiming a huge image is refused (or decoded)
// quickly, as the real cap would be with more time.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "io/image_decode.h"
#include "util/error.h"

namespace {

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_image: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  nusselt::ImageLimits limits;
  limits.maxPixels = std::uint64_t(1) << 20;
  limits.maxBytes = std::uint64_t(1) << 20;
  try {
    nusselt::DecodedImage image = nusselt::decodeImage(data, size, limits);
    const std::uint64_t pixels = std::uint64_t(image.width) * std::uint64_t(image.height);
    if (image.width <= 0 || image.height <= 0) finding("empty image returned");
    if (pixels > limits.maxPixels) finding("image above the pixel cap returned");
    if (image.rgba.size() != 4 * pixels) finding("RGBA buffer size disagrees with the dimensions");
    if (image.sourceChannels < 1 || image.sourceChannels > 4) finding("bad source channel count");
  } catch (const nusselt::Error&) {
    // The documented failure.
  }
  return 0;
}
