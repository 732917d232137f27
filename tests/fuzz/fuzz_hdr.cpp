// fuzz_hdr.cpp: libFuzzer target for the Radiance RGBE decoder (io/radiance_hdr.h, issue 17).
//
// The bytes are an .hdr file, as `--env` would read it. nusselt::Error is the decoder's one
// documented failure; any other exception, a crash, a leak, an ASan or UBSan report, or a decoded
// image that breaks its contract (dimensions within the caps, 3 floats per texel, finite values
// >= 0) is a finding. The out-of-memory finding of its first run (a 45-byte file claiming
// 11104 x 22222 texels made the decoder allocate 3 GB before reading a pixel) is in the corpus as
// regression_oom_header.hdr.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "io/radiance_hdr.h"
#include "util/error.h"

namespace {

// The texel cap lowered to 2^20 (as fuzz_image does), so that a header claiming a huge image of
// old-style runs (8 bytes can stand for 65536 texels) is refused or decoded quickly.
constexpr std::int64_t kMaxTexels = std::int64_t(1) << 20;

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_hdr: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    nusselt::RgbeImage image = nusselt::decodeRadianceHdr(data, size, "fuzz.hdr", kMaxTexels);
    const std::int64_t texels = std::int64_t(image.width) * image.height;
    if (image.width <= 0 || image.height <= 0) finding("empty image returned");
    if (image.width > nusselt::kHdrMaxSide || image.height > nusselt::kHdrMaxSide || texels > kMaxTexels)
      finding("image above the caps returned");
    if (image.rgb.size() != std::size_t(3 * texels)) finding("RGB buffer size disagrees with the dimensions");
    // +Inf is the one non-finite value allowed: a texel that a header's EXPOSURE below 1 scales
    // beyond the float range (the environment reader drops and counts it); never NaN or < 0.
    for (float v : image.rgb)
      if (std::isnan(v) || v < 0) finding("NaN or negative texel decoded");
  } catch (const nusselt::Error&) {
    // The documented failure.
  }
  return 0;
}
