// fuzz_merl.cpp: libFuzzer target for the MERL reader (brdf/merl.h decodeMerl, issue 20).
//
// The bytes are a MERL binary file. They are decoded twice:
//   - against the format's 90 x 90 x 180 layout, as loadMerl reads every file: an input of the
//     fuzzer's sizes (below 35 MB) must be refused, quickly, with the documented error;
//   - against a small layout, so that whole tables (entries, "not measured" fills, NaN/Inf and
//     range checks) are reachable: the dimensions the header declares when each is in [1, 16],
//     else (4, 3, 6) (then a header mismatch, like a wrong real header).
// nusselt::Error naming the file is the one documented failure. Any other exception, a crash, a
// leak, an ASan or UBSan report, an error that does not name the file, or an accepted table that
// breaks its contract (3 floats per node, every value finite, >= 0 and at most 1e30, no more
// unmeasured nodes than nodes, and some node measured) is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "brdf/merl.h"
#include "util/error.h"

namespace {

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_merl: %s\n", what.c_str());
  std::abort();
}

void decode(const std::uint8_t* data, std::size_t size, const nusselt::MerlDims& dims) {
  const std::string name = "fuzz.binary";
  try {
    nusselt::MerlTable t = nusselt::decodeMerl(data, size, name, dims);
    const std::size_t nodes = std::size_t(dims.thetaH) * std::size_t(dims.thetaD) * std::size_t(dims.phiD);
    if (t.rgb.size() != 3 * nodes) finding("rgb size disagrees with the dimensions");
    if (t.unmeasured >= nodes) finding("a table with no measured node accepted");
    for (float v : t.rgb)
      if (!std::isfinite(v) || v < 0 || v > 1e30f) finding("a decoded value that is NaN, infinite, negative or above 1e30");
  } catch (const nusselt::Error& e) {
    if (std::strncmp(e.what(), "fuzz.binary: ", 13) != 0) finding(std::string("error without the file's name: ") + e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  decode(data, size, nusselt::MerlDims{});
  nusselt::MerlDims small{4, 3, 6};
  if (size >= 12) {
    std::int32_t h[3];
    std::memcpy(h, data, 12);
    if (h[0] >= 1 && h[0] <= 16 && h[1] >= 1 && h[1] <= 16 && h[2] >= 1 && h[2] <= 16) small = {h[0], h[1], h[2]};
  }
  decode(data, size, small);
  return 0;
}
