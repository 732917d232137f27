// merl.cpp: MERL binary files, the table store, and MERL files written from analytic models.
#include "brdf/merl.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>

#include "util/error.h"

namespace nusselt {

using namespace shared;

namespace {

constexpr int kH = int(MERL_THETA_H_RES), kD = int(MERL_THETA_D_RES), kP = int(MERL_PHI_D_RES);

std::mutex g_storeMutex;
std::vector<std::unique_ptr<MerlTable>> g_store;  // slot = index; never shrinks (g_merlTables points into it)

std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

std::size_t node(int i, int j, int k) { return (std::size_t(i) * kD + std::size_t(j)) * kP + std::size_t(k); }

// Fills the nodes marked unmeasured from the nearest measured node along theta_d (ties: the
// smaller theta_d), then along theta_h, then along phi_d (periodic), each pass using what the
// previous ones filled. Returns false when no node is measured.
bool fillUnmeasured(std::vector<float>& rgb, std::vector<unsigned char>& measured, const MerlDims& dims) {
  const int kH = dims.thetaH, kD = dims.thetaD, kP = dims.phiD;
  auto node = [&](int i, int j, int k) { return (std::size_t(i) * kD + std::size_t(j)) * kP + std::size_t(k); };
  auto copy = [&](std::size_t to, std::size_t from) {
    for (int c = 0; c < 3; ++c) rgb[3 * to + c] = rgb[3 * from + c];
  };
  std::vector<unsigned char> next = measured;
  // Along one axis: `len` nodes of the line through `base` with `stride`, periodic or not.
  auto fillLine = [&](std::size_t base, std::size_t stride, int len, bool periodic) {
    for (int a = 0; a < len; ++a) {
      std::size_t n = base + std::size_t(a) * stride;
      if (measured[n]) continue;
      for (int d = 1; d < len; ++d) {
        int cand[2] = {a - d, a + d};
        bool done = false;
        for (int b : cand) {
          if (periodic) b = ((b % len) + len) % len;
          else if (b < 0 || b >= len) continue;
          std::size_t m = base + std::size_t(b) * stride;
          if (measured[m]) {
            copy(n, m);
            next[n] = 1;
            done = true;
            break;
          }
        }
        if (done) break;
      }
    }
  };
  for (int i = 0; i < kH; ++i)
    for (int k = 0; k < kP; ++k) fillLine(node(i, 0, k), kP, kD, false);
  measured = next;
  for (int j = 0; j < kD; ++j)
    for (int k = 0; k < kP; ++k) fillLine(node(0, j, k), std::size_t(kD) * kP, kH, false);
  measured = next;
  for (int i = 0; i < kH; ++i)
    for (int j = 0; j < kD; ++j) fillLine(node(i, j, 0), 1, kP, true);
  measured = next;
  return std::all_of(measured.begin(), measured.end(), [](unsigned char m) { return m != 0; });
}

void buildPyramid(MerlTable& t) {
  std::uint32_t dims[3] = {MERL_THETA_H_RES, MERL_THETA_D_RES, MERL_PHI_D_RES};
  const std::vector<float>* prev = &t.luminance;
  std::uint32_t pd[3] = {dims[0], dims[1], dims[2]};
  for (int L = 1; L < 8; ++L) {
    std::uint32_t d[3];
    for (int a = 0; a < 3; ++a) d[a] = (pd[a] + 1) / 2;
    std::vector<float> level(std::size_t(d[0]) * d[1] * d[2], 0.0f);
    for (std::uint32_t i = 0; i < pd[0]; ++i)
      for (std::uint32_t j = 0; j < pd[1]; ++j)
        for (std::uint32_t k = 0; k < pd[2]; ++k) {
          float v = (*prev)[(std::size_t(i) * pd[1] + j) * pd[2] + k];
          float& dst = level[(std::size_t(i / 2) * d[1] + j / 2) * d[2] + k / 2];
          dst = std::max(dst, v);
        }
    t.pyramid.push_back(std::move(level));
    for (int a = 0; a < 3; ++a) t.pyramidDims[L][a] = d[a], pd[a] = d[a];
    prev = &t.pyramid.back();
  }
  for (int a = 0; a < 3; ++a) t.pyramidDims[0][a] = dims[a];
}

std::string channelName(int c) { return c == 0 ? "red" : c == 1 ? "green" : "blue"; }

}  // namespace

std::uint32_t merlSlot(const BrdfParams& params) { return std::uint32_t(brdfParam(params, MERL_SLOT) + 0.5f); }

const MerlTable& merlTable(const BrdfParams& params) {
  std::uint32_t slot = merlSlot(params);
  std::lock_guard<std::mutex> lock(g_storeMutex);
  if (slot >= g_store.size()) throw Error("internal: merl table slot " + std::to_string(slot) + " was never loaded");
  return *g_store[slot];
}

MerlTable decodeMerl(const unsigned char* bytes, std::size_t size, const std::string& displayName, const MerlDims& dims) {
  const std::string who = displayName + ": ";
  const std::uint64_t nodes = std::uint64_t(dims.thetaH) * std::uint64_t(dims.thetaD) * std::uint64_t(dims.phiD);
  const std::uint64_t expected = 12 + 3 * nodes * 8;
  const std::string layout = "(" + std::to_string(dims.thetaH) + ", " + std::to_string(dims.thetaD) + ", " +
                             std::to_string(dims.phiD) + ")";
  if (size < 12)
    throw Error(who + "truncated: " + std::to_string(size) + " bytes, shorter than the 12-byte dimension header");
  std::int32_t found[3];
  std::memcpy(found, bytes, 12);
  if (found[0] != dims.thetaH || found[1] != dims.thetaD || found[2] != dims.phiD)
    throw Error(who + "dimension header (" + std::to_string(found[0]) + ", " + std::to_string(found[1]) + ", " +
                std::to_string(found[2]) + "), expected " + layout + " (theta_half, theta_diff, phi_diff) of the MERL layout");
  if (size < expected)
    throw Error(who + "truncated: " + std::to_string(size) + " bytes, a MERL file has " + std::to_string(expected));
  if (size > expected)
    throw Error(who + std::to_string(size - expected) + " bytes after the table (" + std::to_string(expected) +
                " expected): not a MERL file");

  MerlTable table;
  table.name = displayName;
  table.rgb.assign(3 * nodes, 0.0f);
  std::vector<unsigned char> measured(nodes, 1);
  const unsigned char* data = bytes + 12;
  const std::size_t perTheta = std::size_t(dims.thetaD) * std::size_t(dims.phiD);
  auto where = [&](int c, std::size_t n) {
    return channelName(c) + " entry [theta_h " + std::to_string(n / perTheta) + ", theta_d " +
           std::to_string(n / std::size_t(dims.phiD) % std::size_t(dims.thetaD)) + ", phi_d " +
           std::to_string(n % std::size_t(dims.phiD)) + "]";
  };
  for (int c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < nodes; ++n) {
      double v;
      std::memcpy(&v, data + (std::size_t(c) * nodes + n) * 8, 8);
      if (!std::isfinite(v)) throw Error(who + where(c, n) + " is " + (std::isnan(v) ? "NaN" : "infinite"));
      if (v < 0) {
        measured[n] = 0;
        continue;
      }
      double f = v * kMerlScale[c];
      if (f > 1e30)
        throw Error(who + where(c, n) + " = " + std::to_string(v) + " is too large (BRDF above 1e30 / sr)");
      table.rgb[3 * n + std::size_t(c)] = float(f);
    }
  table.unmeasured = std::uint32_t(std::count(measured.begin(), measured.end(), 0));
  if (!fillUnmeasured(table.rgb, measured, dims)) throw Error(who + "no entry is measured (every value is negative)");
  return table;
}

BrdfParams loadMerl(const std::string& path, const std::string& displayName) {
  const std::string who = displayName + ": ";
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(who + "cannot open the MERL file (" + std::strerror(errno) + ")");
  const std::streamoff size = in.tellg();
  if (size < 0) throw Error(who + "cannot read the MERL file");
  in.seekg(0);
  if (std::uint64_t(size) > kMerlFileBytes + 1024 * 1024)
    throw Error(who + "is " + std::to_string(size) + " bytes, a MERL file has " + std::to_string(kMerlFileBytes) +
                " (90 x 90 x 180 x 3 doubles after a 12-byte header)");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) throw Error(who + "cannot read the MERL file");
  auto paramsOf = [](std::size_t slot, std::uint64_t hash) {
    BrdfParams p{};
    p.v[0][MERL_SLOT] = float(slot);
    p.v[0][MERL_HASH_LO] = float(hash & 0xffffff);
    p.v[0][MERL_HASH_HI] = float((hash >> 24) & 0xffffff);
    return p;
  };
  // The same content loaded before shares its slot (it passed every check then).
  const std::uint64_t hash = fnv1a(bytes.data(), bytes.size());
  if (bytes.size() == kMerlFileBytes) {
    std::lock_guard<std::mutex> lock(g_storeMutex);
    for (std::size_t s = 0; s < g_store.size(); ++s)
      if (g_store[s]->hash == hash) return paramsOf(s, hash);
  }
  auto table = std::make_unique<MerlTable>(decodeMerl(bytes.data(), bytes.size(), displayName));
  table->hash = hash;
  bytes = {};
  table->luminance.resize(MERL_NODES);
  for (std::size_t n = 0; n < MERL_NODES; ++n)
    table->luminance[n] = std::max(0.0f, luminance(vec3(table->rgb[3 * n], table->rgb[3 * n + 1], table->rgb[3 * n + 2])));
  buildPyramid(*table);
  table->maxOverPhi.assign(std::size_t(kH) * kD, 0.0f);
  for (std::size_t n = 0; n < MERL_NODES; ++n) {
    float& m = table->maxOverPhi[n / kP];
    m = std::max(m, table->luminance[n]);
  }

  std::lock_guard<std::mutex> lock(g_storeMutex);
  if (g_store.size() >= MERL_MAX_TABLES)
    throw Error(who + "more than " + std::to_string(MERL_MAX_TABLES) + " distinct measured tables in one run");
  std::uint32_t slot = std::uint32_t(g_store.size());
  g_merlTables[slot] = table->rgb.data();
  BrdfParams p = paramsOf(slot, table->hash);
  g_store.push_back(std::move(table));
  return p;
}

float merlNodeMax(const MerlTable& t, int i0, int i1, int j0, int j1, int k0, int k1) {
  i0 = std::clamp(i0, 0, kH - 1);
  i1 = std::clamp(i1, 0, kH - 1);
  j0 = std::clamp(j0, 0, kD - 1);
  j1 = std::clamp(j1, 0, kD - 1);
  if (k1 - k0 >= kP - 1) k0 = 0, k1 = kP - 1;
  k0 = ((k0 % kP) + kP) % kP;
  k1 = k0 + (k1 - k0 + kP) % kP;  // k1 >= k0, possibly >= kP (wraps)
  if (k1 >= kP) return std::max(merlNodeMax(t, i0, i1, j0, j1, k0, kP - 1), merlNodeMax(t, i0, i1, j0, j1, 0, k1 - kP));
  // The finest level whose covering blocks number at most 64.
  int L = 0;
  while (L < 7) {
    std::int64_t n = std::int64_t((i1 >> L) - (i0 >> L) + 1) * ((j1 >> L) - (j0 >> L) + 1) * ((k1 >> L) - (k0 >> L) + 1);
    if (n <= 64) break;
    ++L;
  }
  const std::vector<float>& lv = L == 0 ? t.luminance : t.pyramid[std::size_t(L - 1)];
  const std::uint32_t* d = t.pyramidDims[L];
  float m = 0;
  for (int i = i0 >> L; i <= i1 >> L; ++i)
    for (int j = j0 >> L; j <= j1 >> L; ++j)
      for (int k = k0 >> L; k <= k1 >> L; ++k) m = std::max(m, lv[(std::size_t(i) * d[1] + std::size_t(j)) * d[2] + std::size_t(k)]);
  return m;
}

bool merlNodeDirections(std::uint32_t i, std::uint32_t j, std::uint32_t k, vec3& wi, vec3& wo) {
  const double th = double(i) * i / (double(kH) * kH) * (M_PI / 2), td = double(j) / kD * (M_PI / 2),
               pd = double(k) / kP * M_PI;
  const double h[3] = {std::sin(th), 0, std::cos(th)};
  const double t[3] = {std::cos(th), 0, -std::sin(th)}, b[3] = {0, 1, 0};
  const double d[3] = {std::sin(td) * std::cos(pd), std::sin(td) * std::sin(pd), std::cos(td)};
  double a[3], o[3];
  for (int c = 0; c < 3; ++c) a[c] = d[0] * t[c] + d[1] * b[c] + d[2] * h[c];
  const double ah = a[0] * h[0] + a[1] * h[1] + a[2] * h[2];
  for (int c = 0; c < 3; ++c) o[c] = 2 * ah * h[c] - a[c];
  wi = vec3(float(a[0]), float(a[1]), float(a[2]));
  wo = vec3(float(o[0]), float(o[1]), float(o[2]));
  return a[2] > 0 && o[2] > 0;
}

std::vector<double> tabulateMerl(std::uint32_t model, const BrdfParams& params) {
  std::vector<double> out(MERL_TABLE_FLOATS, -1.0);
  for (int i = 0; i < kH; ++i)
    for (int j = 0; j < kD; ++j)
      for (int k = 0; k < kP; ++k) {
        vec3 wi, wo;
        if (!merlNodeDirections(std::uint32_t(i), std::uint32_t(j), std::uint32_t(k), wi, wo)) continue;
        vec3 f = brdfEval(model, params, wi, wo);
        for (int c = 0; c < 3; ++c) out[std::size_t(c) * MERL_NODES + node(i, j, k)] = double(f[c]) / kMerlScale[c];
      }
  return out;
}

void writeMerlFile(const std::string& path, const std::vector<double>& values) {
  if (values.size() != MERL_TABLE_FLOATS) throw Error("internal: a MERL table has " + std::to_string(MERL_TABLE_FLOATS) + " values");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error(path + ": cannot write (" + std::strerror(errno) + ")");
  const std::int32_t dims[3] = {kH, kD, kP};
  bool ok = std::fwrite(dims, 4, 3, f) == 3 && std::fwrite(values.data(), 8, values.size(), f) == values.size();
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) throw Error(path + ": write failed (" + std::strerror(errno) + ")");
}

}  // namespace nusselt
