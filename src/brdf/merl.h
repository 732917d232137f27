// merl.h: measured BRDFs in the MERL 100 binary layout (docs/measured.md): reading and checking
// files, the process's store of tables (read by the shared evaluation, shaders/shared/brdf/merl.h,
// through g_merlTables), and writing MERL-format files from the analytic models (tests, tools).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "../../shaders/shared/brdf/dispatch.h"

namespace nusselt {

// The format's scale factors: a file value times these is the BRDF [1/sr] per channel.
constexpr double kMerlScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};
constexpr std::uint64_t kMerlFileBytes = 12 + 3ull * MERL_NODES * 8;

// One table in the store.
struct MerlTable {
  std::string name;               // as the user named it (messages)
  std::uint64_t hash = 0;         // FNV-1a of the file's bytes
  std::uint32_t unmeasured = 0;   // nodes with a negative ("not measured") entry, filled on load
  std::vector<float> rgb;         // MERL_TABLE_FLOATS: the shared code's layout
  std::vector<float> luminance;   // MERL_NODES: luminance of each node (the builder's bounds)
  std::vector<float> maxOverPhi;  // 90 x 90: max over phi_d of `luminance` at each (theta_h, theta_d) node
  // Maxima of `luminance` over aligned blocks of 2^L nodes per axis, L = 1.. (merlNodeMax).
  std::vector<std::vector<float>> pyramid;
  std::uint32_t pyramidDims[8][3] = {};
};

// The dimensions (theta_half, theta_diff, phi_diff) a file must declare: the format's 90 x 90 x 180
// for every table nusselt renders; decodeMerl accepts others so that a fuzzer can reach whole
// small tables (tests/fuzz/fuzz_merl.cpp).
struct MerlDims {
  std::int32_t thetaH = std::int32_t(MERL_THETA_H_RES), thetaD = std::int32_t(MERL_THETA_D_RES), phiD = std::int32_t(MERL_PHI_D_RES);
};

// Checks and decodes the bytes of a MERL file declaring `dims`: the header, the size (12 bytes of
// header and 3 x nodes doubles, nothing after), every entry finite and its BRDF at most 1e30;
// scales the entries, fills the "not measured" (negative) ones (loadMerl) and returns the table's
// name, unmeasured count and rgb (node order of `dims`, theta_half-major), without the
// builder's bounds. Throws nusselt::Error naming `displayName` for the first problem found.
MerlTable decodeMerl(const unsigned char* bytes, std::size_t size, const std::string& displayName, const MerlDims& dims = {});

// Reads a MERL binary file (three int32 dimensions 90 90 180, then the red, green and blue tables
// of doubles, theta_half-major) into the store and returns its parameter block. Entries < 0 are
// "not measured": each such node takes the value of the nearest measured node along theta_d
// (then theta_h, then phi_d) at the same other coordinates. The same content loaded twice shares
// its slot. Throws nusselt::Error naming `displayName` for a file that cannot be read, a wrong
// dimension header, a wrong size (truncated or trailing bytes), a NaN or Inf entry (with its
// channel and indices), an entry too large for a float, or a table with no measured entry.
shared::BrdfParams loadMerl(const std::string& path, const std::string& displayName);

// The table of a merl parameter block (throws for a slot that was never loaded).
const MerlTable& merlTable(const shared::BrdfParams& params);
std::uint32_t merlSlot(const shared::BrdfParams& params);

// Max of the node luminances over [i0, i1] x [j0, j1] x [k0, k1] (inclusive node indices, k taken
// modulo 180, k1 - k0 < 180); an upper bound that may include a few neighbouring nodes.
float merlNodeMax(const MerlTable& t, int i0, int i1, int j0, int j1, int k0, int k1);

// The table a MERL file written from `model` would hold, in file units (BRDF / scale), the
// format's order (channel-major, then theta_h, theta_d, phi_d): f at each node's directions
// (phi_h = 0), and -1 ("not measured") where wi or wo lies below the surface.
std::vector<double> tabulateMerl(std::uint32_t model, const shared::BrdfParams& params);
// Writes a MERL binary file (header and table; throws nusselt::Error on I/O failure).
void writeMerlFile(const std::string& path, const std::vector<double>& fileValues);

// The directions of node (i, j, k) (phi_h = 0): false when one lies below the surface.
bool merlNodeDirections(std::uint32_t i, std::uint32_t j, std::uint32_t k, shared::vec3& wi, shared::vec3& wo);

}  // namespace nusselt
