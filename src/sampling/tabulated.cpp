// tabulated.cpp: see tabulated.h.
#include "sampling/tabulated.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>

#include "quadtree/quadtree_build.h"

namespace nusselt::sampling {

using namespace shared;

std::uint64_t bytesPerTableLike(std::uint64_t quadtreeBytes, std::uint32_t trees) {
  return std::max<std::uint64_t>(1024, trees ? quadtreeBytes / trees : quadtreeBytes);
}

void tabulatedGrid(std::uint64_t bytesPerTable, std::uint32_t& nu, std::uint32_t& np) {
  // nu + nu * 2 nu floats of CDFs after the TabTable header.
  double floats = double(bytesPerTable > sizeof(TabTable) ? bytesPerTable - sizeof(TabTable) : 0) / 4.0;
  double n = std::floor((-1.0 + std::sqrt(1.0 + 8.0 * floats)) / 4.0);
  nu = std::uint32_t(std::clamp(n, 2.0, 16384.0));
  np = 2 * nu;
}

std::uint64_t TabulatedTables::bytes() const {
  return sets.size() * sizeof(TabSet) + tables.size() * sizeof(TabTable) + data.size() * sizeof(float);
}

namespace {

// Fills table T (its CDFs at T.info.x) for the canonical known direction vk.
std::uint64_t buildTable(std::uint32_t model, const BrdfParams& p, vec3 vk, std::uint32_t nu, std::uint32_t np, TabTable& T,
                         float* cdf) {
  // f on the half-step grid: u_a = a / (2 nu), a = 0..2nu (the rim row a quarter step inside, where
  // models that grow like cos^-s are still finite), phi_b = b pi / np, b = 0..2np-1 (periodic).
  const std::uint32_t A = 2 * nu + 1, B = 2 * np;
  std::vector<double> f(std::size_t(A) * B);
  for (std::uint32_t a = 0; a < A; ++a) {
    double u = std::min(double(a) / (2.0 * nu), 1.0 - 0.25 / (2.0 * nu));
    double r = std::sqrt(u), z = std::sqrt(1.0 - u);
    for (std::uint32_t b = 0; b < B; ++b) {
      double ph = M_PI * b / np;
      vec3 w(float(r * std::cos(ph)), float(r * std::sin(ph)), float(z));
      f[std::size_t(a) * B + b] = quadEvalLum(model, p, w, vk);
    }
  }
  // Cell value = max of its 3 x 3 points; albedo by Simpson's rule over the cell (disc measure,
  // cell area pi / (nu np)).
  std::vector<double> cell(std::size_t(nu) * np);
  double albedo = 0;
  static const double sw[3] = {1, 4, 1};
  for (std::uint32_t i = 0; i < nu; ++i)
    for (std::uint32_t j = 0; j < np; ++j) {
      double mx = 0, simpson = 0;
      for (int da = 0; da < 3; ++da)
        for (int db = 0; db < 3; ++db) {
          double v = f[std::size_t(2 * i + da) * B + (2 * j + db) % B];
          mx = std::max(mx, v);
          simpson += sw[da] * sw[db] * v;
        }
      cell[std::size_t(i) * np + j] = mx;
      albedo += simpson / 36.0 * M_PI / (double(nu) * np);
    }
  // CDFs: marginal over rows, conditional within each row (the last entries exactly 1).
  std::vector<double> row(nu, 0.0);
  double total = 0;
  for (std::uint32_t i = 0; i < nu; ++i) {
    for (std::uint32_t j = 0; j < np; ++j) row[i] += cell[std::size_t(i) * np + j];
    total += row[i];
  }
  bool mass = total > 0 && std::isfinite(total);
  double run = 0;
  for (std::uint32_t i = 0; i < nu; ++i) {
    run += row[i];
    cdf[i] = i + 1 == nu ? 1.0f : (mass ? float(run / total) : float(i + 1) / float(nu));
    float* c = cdf + nu + std::size_t(i) * np;
    double rr = 0;
    for (std::uint32_t j = 0; j < np; ++j) {
      rr += cell[std::size_t(i) * np + j];
      c[j] = j + 1 == np ? 1.0f : (row[i] > 0 ? float(rr / row[i]) : float(j + 1) / float(np));
    }
  }
  T.info.y = mass ? 1u : 0u;
  T.data.x = float(albedo);
  return std::uint64_t(A) * B;
}

}  // namespace

TabulatedTables buildTabulatedTables(const std::vector<std::pair<std::uint32_t, BrdfParams>>& materials,
                                     const TabulatedSettings& settings, std::vector<std::uint32_t>& setIndexPerMaterial) {
  auto t0 = std::chrono::steady_clock::now();
  TabulatedTables out;
  std::uint32_t nu = 0, np = 0;
  tabulatedGrid(settings.bytesPerTable, nu, np);
  const std::uint32_t nt = std::max(1u, settings.thetaTables);
  const std::uint64_t floatsPerTable = nu + std::uint64_t(nu) * np;

  struct Job { std::uint32_t model; BrdfParams params; std::uint32_t table; vec3 vk; bool build; };
  std::vector<Job> jobs;
  std::map<std::pair<std::uint32_t, std::string>, std::uint32_t> seen;
  setIndexPerMaterial.assign(materials.size(), INVALID_INDEX);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    std::uint32_t model = materials[m].first;
    if (model >= MODEL_COUNT || modelIsDelta(model)) continue;
    std::string key(reinterpret_cast<const char*>(&materials[m].second), sizeof(BrdfParams));
    auto [it, inserted] = seen.emplace(std::make_pair(model, key), std::uint32_t(out.sets.size()));
    setIndexPerMaterial[m] = it->second;
    if (!inserted) continue;
    bool aniso = quadtree::modelTraits(model, materials[m].second).anisotropic;
    std::uint32_t nphi = aniso ? std::max(2u, settings.phiTables) : 1u;
    TabSet S{};
    S.info = uvec4(std::uint32_t(out.tables.size()), nt, nphi, aniso ? TB_SET_ANISOTROPIC : 0u);
    S.grid = uvec4(nu, np, 0u, 0u);
    float dTheta = float(0.5 * M_PI / nt), dPhi = nphi > 1 ? float(0.5 * M_PI / (nphi - 1)) : 0.0f;
    S.data = vec4(settings.defensive, dTheta, dPhi, 0.0f);
    out.sets.push_back(S);
    for (std::uint32_t k = 0; k < nt; ++k)
      for (std::uint32_t j = 0; j < nphi; ++j) {
        double th = double(k) * dTheta, ph = double(j) * dPhi;
        TabTable T{};
        T.info = uvec4(std::uint32_t(out.tables.size() * floatsPerTable), 0u, 0u, 0u);
        vec3 vk(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
        T.data = vec4(0.0f, vk.z, float(std::sin(th)), float(ph));
        bool build = settings.onlyThetaTables.empty() ||
                     std::find(settings.onlyThetaTables.begin(), settings.onlyThetaTables.end(), k) !=
                         settings.onlyThetaTables.end();
        jobs.push_back({model, materials[m].second, std::uint32_t(out.tables.size()), vk, build});
        out.tables.push_back(T);
      }
  }
  if (out.tables.size() * floatsPerTable > 0xffffffffull)
    throw std::runtime_error("tabulated sampler: more than 2^32 floats of tables");
  out.data.assign(out.tables.size() * floatsPerTable, 0.0f);
  // Tables not built: valid uniform CDFs, no mass (cosine only).
  for (std::size_t t = 0; t < out.tables.size(); ++t) {
    float* c = out.data.data() + t * floatsPerTable;
    for (std::uint32_t i = 0; i < nu; ++i) c[i] = float(i + 1) / float(nu);
    for (std::uint32_t i = 0; i < nu; ++i)
      for (std::uint32_t j = 0; j < np; ++j) c[nu + std::size_t(i) * np + j] = float(j + 1) / float(np);
    c[nu - 1] = 1.0f;
  }

  std::atomic<std::size_t> next{0};
  std::atomic<std::uint64_t> evals{0};
  auto work = [&]() {
    for (std::size_t q; (q = next++) < jobs.size();) {
      const Job& jb = jobs[q];
      if (!jb.build) continue;
      TabTable& T = out.tables[jb.table];
      evals += buildTable(jb.model, jb.params, jb.vk, nu, np, T, out.data.data() + T.info.x);
    }
  };
  unsigned threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = std::max(1u, std::min<unsigned>(threads, unsigned(jobs.size())));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  out.evaluations = evals;
  if (out.sets.empty()) {  // valid (never read) buffers for the GPU
    out.sets.resize(1);
    out.tables.resize(1);
    out.data.resize(1);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

TabHostScope::TabHostScope(const TabulatedTables& t) {
  m_host.sets = t.sets.data();
  m_host.tables = t.tables.data();
  m_host.data = t.data.data();
  m_previous = shared::g_tabHost;
  shared::g_tabHost = &m_host;
}

TabHostScope::~TabHostScope() { shared::g_tabHost = m_previous; }

}  // namespace nusselt::sampling
