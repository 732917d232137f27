// sampler_tables.cpp: parallel build, disk cache and flattening of the generic sampler's trees.
#include "quadtree/sampler_tables.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "brdf/registry.h"
#include "quadtree/quadtree_build.h"

namespace nusselt::quadtree {

using namespace shared;

namespace {

// Bump when the tree format or the build algorithm changes: old cache entries become stale.
constexpr std::uint32_t kFormatVersion = 7;  // 6: polar rim annulus, half disc, exponential envelopes, 48-byte leaves;
                                             // 7: leaves below 1/n_max polished from a lattice
constexpr char kMagic[8] = {'N', 'U', 'S', 'Q', 'T', 'R', 'E', 'E'};

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

// One material's trees in local indices (node/leaf links relative to its own arrays).
struct MaterialTrees {
  std::vector<QuadTable> tables;
  std::vector<QuadNode> nodes;
  std::vector<QuadLeaf> leaves;
  MaterialStats stats;
};

struct CacheHeader {
  char magic[8];
  std::uint32_t version;
  std::uint32_t tables, nodes, leaves;
  std::uint64_t key;
  std::uint64_t checksum;  // of the payload
  std::uint32_t cappedLeaves, rimLeaves, maxDepth, tailLeaves, expLeaves, pad;
  double minAcceptance;
};

std::string cacheFile(std::uint64_t key) {
  std::string dir = cacheDirectory();
  if (dir.empty()) return "";
  char name[64];
  std::snprintf(name, sizeof name, "/quadtree-%016llx.bin", static_cast<unsigned long long>(key));
  return dir + name;
}

// 0: hit; 1: missing; 2: rejected (corrupt, stale, wrong size).
int loadCache(std::uint64_t key, MaterialTrees& out) {
  std::string path = cacheFile(key);
  if (path.empty()) return 1;
  std::ifstream in(path, std::ios::binary);
  if (!in) return 1;
  CacheHeader h{};
  if (!in.read(reinterpret_cast<char*>(&h), sizeof h)) return 2;
  if (std::memcmp(h.magic, kMagic, 8) != 0 || h.version != kFormatVersion || h.key != key) return 2;
  std::error_code ec;
  std::uint64_t size = std::filesystem::file_size(path, ec);
  std::uint64_t expect = sizeof h + std::uint64_t(h.tables) * sizeof(QuadTable) + std::uint64_t(h.nodes) * sizeof(QuadNode) +
                         std::uint64_t(h.leaves) * sizeof(QuadLeaf);
  if (ec || size != expect || h.tables == 0) return 2;
  out.tables.resize(h.tables);
  out.nodes.resize(h.nodes);
  out.leaves.resize(h.leaves);
  in.read(reinterpret_cast<char*>(out.tables.data()), h.tables * sizeof(QuadTable));
  in.read(reinterpret_cast<char*>(out.nodes.data()), h.nodes * sizeof(QuadNode));
  in.read(reinterpret_cast<char*>(out.leaves.data()), h.leaves * sizeof(QuadLeaf));
  if (!in) return 2;
  std::uint64_t sum = fnv1a(out.tables.data(), out.tables.size() * sizeof(QuadTable));
  sum = fnv1a(out.nodes.data(), out.nodes.size() * sizeof(QuadNode), sum);
  sum = fnv1a(out.leaves.data(), out.leaves.size() * sizeof(QuadLeaf), sum);
  if (sum != h.checksum) return 2;
  // Links must stay inside the arrays (a corrupt file that passes the checksum is still refused).
  auto valid = [&](std::uint32_t link) {
    if (link == QT_EMPTY) return true;
    if (link & QT_LEAF_BIT) return (link & ~QT_LEAF_BIT) < h.leaves;
    return link < h.nodes;
  };
  for (const QuadTable& t : out.tables)
    if (!valid(t.info.x)) return 2;
  for (std::size_t i = 0; i < out.nodes.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      std::uint32_t l = out.nodes[i].child[c];
      if (!valid(l) || (!(l & QT_LEAF_BIT) && l != QT_EMPTY && l <= i)) return 2;  // children after parents: no cycles
    }
  out.stats.cappedLeaves = h.cappedLeaves;
  out.stats.rimLeaves = h.rimLeaves;
  out.stats.tailLeaves = h.tailLeaves;
  out.stats.expLeaves = h.expLeaves;
  out.stats.maxDepth = h.maxDepth;
  out.stats.minAcceptance = h.minAcceptance;
  return 0;
}

void storeCache(std::uint64_t key, const MaterialTrees& m) {
  std::string path = cacheFile(key);
  if (path.empty()) return;
  CacheHeader h{};
  std::memcpy(h.magic, kMagic, 8);
  h.version = kFormatVersion;
  h.tables = std::uint32_t(m.tables.size());
  h.nodes = std::uint32_t(m.nodes.size());
  h.leaves = std::uint32_t(m.leaves.size());
  h.key = key;
  std::uint64_t sum = fnv1a(m.tables.data(), m.tables.size() * sizeof(QuadTable));
  sum = fnv1a(m.nodes.data(), m.nodes.size() * sizeof(QuadNode), sum);
  sum = fnv1a(m.leaves.data(), m.leaves.size() * sizeof(QuadLeaf), sum);
  h.checksum = sum;
  h.cappedLeaves = m.stats.cappedLeaves;
  h.rimLeaves = m.stats.rimLeaves;
  h.tailLeaves = m.stats.tailLeaves;
  h.expLeaves = m.stats.expLeaves;
  h.maxDepth = m.stats.maxDepth;
  h.minAcceptance = m.stats.minAcceptance;
  // Write to a unique temporary, then rename: readers never see a partial file.
  std::string tmp = path + ".tmp" + std::to_string(::getpid()) + "-" +
                    std::to_string(std::hash<std::thread::id>()(std::this_thread::get_id()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return;
    out.write(reinterpret_cast<const char*>(&h), sizeof h);
    out.write(reinterpret_cast<const char*>(m.tables.data()), m.tables.size() * sizeof(QuadTable));
    out.write(reinterpret_cast<const char*>(m.nodes.data()), m.nodes.size() * sizeof(QuadNode));
    out.write(reinterpret_cast<const char*>(m.leaves.data()), m.leaves.size() * sizeof(QuadLeaf));
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      return;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) std::remove(tmp.c_str());
}

struct Unique {
  std::uint32_t model;
  BrdfParams params;
  ModelTraits traits;
  std::uint32_t nTheta, nPhi;
  bool transmits = false;  // the model transmits: a lower-disc tree per table too
  std::uint64_t key;
  MaterialTrees trees;
  bool fromCache = false;
  std::vector<Tree> built;
  std::vector<double> seconds;
};

QuadTable makeTable(std::uint32_t k, std::uint32_t j, std::uint32_t nTheta, std::uint32_t nPhi) {
  double theta = k * (M_PI / 2) / nTheta;
  double phi = nPhi > 1 ? j * (M_PI / 2) / (nPhi - 1) : 0.0;
  float cp = float(std::cos(phi)), sp = float(std::sin(phi));
  if (nPhi > 1 && j == nPhi - 1) { cp = 0.0f; sp = 1.0f; }
  QuadTable t;
  t.info = uvec4(QT_EMPTY, floatBitsToUint(cp), floatBitsToUint(sp), 0u);
  t.data = vec4(0.0f, float(std::cos(theta)), float(phi), float(std::sin(theta)));
  return t;
}

}  // namespace

std::string cacheDirectory() {
  namespace fs = std::filesystem;
  std::string dir;
  if (const char* e = std::getenv("NUSSELT_CACHE_DIR"); e && *e) dir = e;
  else if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) dir = std::string(x) + "/nusselt";
  else if (const char* home = std::getenv("HOME"); home && *home) dir = std::string(home) + "/.cache/nusselt";
  else return "";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec) || ::access(dir.c_str(), W_OK) != 0) return "";
  return dir;
}

std::uint64_t SamplerTables::bytes() const {
  return sets.size() * sizeof(QuadSet) + tables.size() * sizeof(QuadTable) + nodes.size() * sizeof(QuadNode) +
         leaves.size() * sizeof(QuadLeaf);
}

SamplerTables buildSamplerTables(const std::vector<std::pair<std::uint32_t, BrdfParams>>& materials,
                                 const QuadtreeSettings& settings, std::vector<std::uint32_t>& setIndexPerMaterial) {
  auto start = std::chrono::steady_clock::now();
  SamplerTables out;
  BuildSettings bs;
  bs.nMax = settings.nMax;
  bs.maxDepth = settings.maxDepth;

  // ---- Distinct materials (identical parameter blocks share one set) ----
  std::vector<Unique> uniques;
  std::map<std::pair<std::uint32_t, std::string>, std::uint32_t> seen;
  setIndexPerMaterial.assign(materials.size(), INVALID_INDEX);
  for (std::size_t i = 0; i < materials.size(); ++i) {
    std::uint32_t model = materials[i].first;
    if (model >= MODEL_COUNT || modelIsDelta(model)) continue;
    std::string bytes(reinterpret_cast<const char*>(&materials[i].second), sizeof(BrdfParams));
    auto [it, inserted] = seen.emplace(std::make_pair(model, bytes), std::uint32_t(uniques.size()));
    if (inserted) {
      Unique u;
      u.model = model;
      u.params = materials[i].second;
      u.traits = modelTraits(model, u.params);
      u.nTheta = std::max(1u, settings.thetaTables);
      u.nPhi = u.traits.anisotropic ? std::max(2u, settings.phiTables) : 1u;
      u.transmits = modelById(model).transmits;
      struct KeyData {
        std::uint32_t version, model, nTheta, nPhi, maxDepth;
        float nMax, margin;
        double relTol, absTol;
      } kd{kFormatVersion, model, u.nTheta, u.nPhi, bs.maxDepth, bs.nMax, bs.boundMargin, bs.relTol, bs.absTol};
      std::uint64_t key = fnv1a(&kd, sizeof kd);
      // A measured table is keyed by its content hash (in the block), not by its slot, which
      // depends on the order in which a run loaded its files.
      BrdfParams keyParams = u.params;
      if (model == MODEL_MERL) keyParams.v[0][MERL_SLOT] = 0.0f;
      u.key = fnv1a(&keyParams, sizeof(BrdfParams), key);
      uniques.push_back(std::move(u));
    }
    setIndexPerMaterial[i] = it->second;
  }

  // ---- Cache look-up ----
  for (Unique& u : uniques) {
    if (!settings.useCache || !settings.onlyThetaTables.empty()) continue;
    int r = loadCache(u.key, u.trees);
    if (r == 0 && u.trees.tables.size() == std::size_t(u.nTheta) * u.nPhi * (u.transmits ? 2 : 1)) {
      u.fromCache = true;
      out.cacheHits++;
    } else {
      if (r == 2 || r == 0) out.cacheRejected++;
      out.cacheMisses++;
      u.trees = MaterialTrees{};
    }
  }

  // ---- Parallel build: one job per (material, table) ----
  struct Job {
    std::uint32_t u, t;
  };
  std::vector<Job> jobs;
  for (std::uint32_t ui = 0; ui < uniques.size(); ++ui) {
    Unique& u = uniques[ui];
    if (u.fromCache) continue;
    // A transmitting model's tables: the upper discs [0, nTheta nPhi), then the lower discs of the
    // same known directions (quadtree_layout.h, QT_SET_TRANSMITS).
    std::uint32_t n1 = u.nTheta * u.nPhi, n = n1 * (u.transmits ? 2 : 1);
    u.built.resize(n);
    u.seconds.assign(n, 0.0);
    u.trees.tables.resize(n);
    for (std::uint32_t t = 0; t < n; ++t) u.trees.tables[t] = makeTable((t % n1) / u.nPhi, t % u.nPhi, u.nTheta, u.nPhi);
    // Most expensive first (grazing tables are the deepest): better balance.
    for (std::uint32_t t = n; t-- > 0;) {
      const auto& only = settings.onlyThetaTables;
      if (!only.empty() && std::find(only.begin(), only.end(), (t % n1) / u.nPhi) == only.end()) continue;
      jobs.push_back({ui, t});
    }
  }
  std::atomic<std::size_t> next{0};
  auto worker = [&]() {
    for (;;) {
      std::size_t i = next.fetch_add(1);
      if (i >= jobs.size()) return;
      Unique& u = uniques[jobs[i].u];
      auto t0 = std::chrono::steady_clock::now();
      vec3 v = quadTableDirection(u.trees.tables[jobs[i].t]);
      BuildSettings tbs = bs;
      tbs.lowerDisc = jobs[i].t >= u.nTheta * u.nPhi;
      u.built[jobs[i].t] = buildTree(u.model, u.params, v, tbs);
      u.seconds[jobs[i].t] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
  };
  unsigned nThreads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  nThreads = std::max(1u, std::min<unsigned>(nThreads, unsigned(jobs.size())));
  if (!jobs.empty()) {
    if (settings.beforeBuild) {
      std::size_t built = 0;
      for (const Unique& u : uniques) built += u.fromCache ? 0 : 1;
      settings.beforeBuild(built, jobs.size());
    }
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < nThreads; ++i) pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool) t.join();
  }

  // ---- Assemble per material (local indices), store in the cache ----
  for (Unique& u : uniques) {
    MaterialStats& st = u.trees.stats;
    st.model = u.model;
    if (u.fromCache) {
      st.cacheHit = true;
    } else {
      for (std::size_t t = 0; t < u.built.size(); ++t) {
        Tree& tr = u.built[t];
        std::uint32_t nodeBase = std::uint32_t(u.trees.nodes.size()), leafBase = std::uint32_t(u.trees.leaves.size());
        auto fix = [&](std::uint32_t l) -> std::uint32_t {
          if (l == QT_EMPTY) return l;
          if (l & QT_LEAF_BIT) return QT_LEAF_BIT | ((l & ~QT_LEAF_BIT) + leafBase);
          return l + nodeBase;
        };
        for (QuadNode n : tr.nodes) {
          for (int c = 0; c < 4; ++c) n.child[c] = fix(n.child[c]);
          u.trees.nodes.push_back(n);
        }
        u.trees.leaves.insert(u.trees.leaves.end(), tr.leaves.begin(), tr.leaves.end());
        u.trees.tables[t].info.x = fix(tr.root);
        u.trees.tables[t].data.x = float(tr.mass);
        st.cappedLeaves += tr.stats.cappedLeaves;
        st.rimLeaves += tr.stats.rimLeaves;
        st.tailLeaves += tr.stats.tailLeaves;
        st.expLeaves += tr.stats.expLeaves;
        st.maxDepth = std::max(st.maxDepth, tr.stats.maxDepth);
        st.minAcceptance = std::min(st.minAcceptance, tr.stats.minAcceptance);
        st.evaluations += tr.stats.evaluations;
        st.certifyBoxes += tr.stats.certifyBoxes;
        st.buildSeconds += u.seconds[t];
      }
      u.built.clear();
      if (settings.useCache && settings.onlyThetaTables.empty()) storeCache(u.key, u.trees);
    }
    st.trees = std::uint32_t(u.trees.tables.size());
    st.nodes = std::uint32_t(u.trees.nodes.size());
    st.leaves = std::uint32_t(u.trees.leaves.size());
    st.bytes = sizeof(QuadSet) + st.trees * sizeof(QuadTable) + st.nodes * sizeof(QuadNode) + st.leaves * sizeof(QuadLeaf);
  }

  // ---- Flatten into the shared buffers ----
  for (std::uint32_t ui = 0; ui < uniques.size(); ++ui) {
    Unique& u = uniques[ui];
    std::uint32_t tableBase = std::uint32_t(out.tables.size()), nodeBase = std::uint32_t(out.nodes.size()),
                  leafBase = std::uint32_t(out.leaves.size());
    auto fix = [&](std::uint32_t l) -> std::uint32_t {
      if (l == QT_EMPTY) return l;
      if (l & QT_LEAF_BIT) return QT_LEAF_BIT | ((l & ~QT_LEAF_BIT) + leafBase);
      return l + nodeBase;
    };
    QuadSet s;
    s.info = uvec4(tableBase, u.nTheta, u.nPhi,
                   (u.traits.anisotropic ? QT_SET_ANISOTROPIC : 0u) | (u.transmits ? QT_SET_TRANSMITS : 0u));
    s.data = vec4(settings.defensive, float((M_PI / 2) / u.nTheta), u.nPhi > 1 ? float((M_PI / 2) / (u.nPhi - 1)) : 0.0f, 0.0f);
    out.sets.push_back(s);
    for (QuadTable t : u.trees.tables) {
      t.info.x = fix(t.info.x);
      out.tables.push_back(t);
    }
    for (QuadNode n : u.trees.nodes) {
      for (int c = 0; c < 4; ++c) n.child[c] = fix(n.child[c]);
      out.nodes.push_back(n);
    }
    out.leaves.insert(out.leaves.end(), u.trees.leaves.begin(), u.trees.leaves.end());
    u.trees.stats.set = ui;
    out.materials.push_back(u.trees.stats);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

bool constantInSampledDirection(std::uint32_t model, const BrdfParams& params) {
  if (model >= MODEL_COUNT || modelIsDelta(model) || modelTransmits(model)) return false;
  // Known directions: polar angles 0 .. 89 degrees, azimuths spread by the golden angle (anisotropic
  // models see several); sampled directions: a 32 x 32 grid of (cos theta, phi) cell centres, whose
  // cos theta reaches 1 / 64 (89.1 degrees).
  for (int i = 0; i < 32; ++i) {
    const double tv = (M_PI / 180) * (89.0 * i / 31.0), pv = 2.399963229728653 * i;
    const vec3 v(float(std::sin(tv) * std::cos(pv)), float(std::sin(tv) * std::sin(pv)), float(std::cos(tv)));
    bool first = true;
    vec3 f0(0.0f);
    for (int a = 0; a < 32; ++a)
      for (int b = 0; b < 32; ++b) {
        const double c = (a + 0.5) / 32.0, s = std::sqrt(1.0 - c * c), pw = 2 * M_PI * (b + 0.5) / 32.0;
        const vec3 w(float(s * std::cos(pw)), float(s * std::sin(pw)), float(c));
        const vec3 f = brdfEval(model, params, w, v);
        if (!std::isfinite(f.x) || !std::isfinite(f.y) || !std::isfinite(f.z)) return false;
        if (first) {
          f0 = f;
          first = false;
        } else if (!(f.x == f0.x && f.y == f0.y && f.z == f0.z)) {
          return false;
        }
      }
  }
  return true;
}

QuadHostScope::QuadHostScope(const SamplerTables& t) {
  m_host.sets = t.sets.data();
  m_host.tables = t.tables.data();
  m_host.nodes = t.nodes.data();
  m_host.leaves = t.leaves.data();
  m_previous = shared::g_quadHost;
  shared::g_quadHost = &m_host;
}

QuadHostScope::~QuadHostScope() { shared::g_quadHost = m_previous; }

}  // namespace nusselt::quadtree
