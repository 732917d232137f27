// bench_error_report.cpp: the Markdown report of `nusselt bench error` from the run's CSV files
// (bench_error_report.h). Every sentence here that carries a number takes it from the files; what
// the numbers mean and why they come out as they do is in docs/results-method.md, which the report
// links to.
#include "cli/bench_error_report.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "util/error.h"

namespace nusselt {
namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
std::string fmtTime(double s) {
  if (!std::isfinite(s)) return "-";
  if (s < 1e-3) return fmt("%.3g us", s * 1e6);
  if (s < 1) return fmt("%.3g ms", s * 1e3);
  return fmt("%.3g s", s);
}
std::string fmtRatio(double r) { return std::isfinite(r) ? fmt(r < 0.1 || r >= 100 ? "%.2g" : "%.2f", r) : "-"; }
std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string o;
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? sep : "") + v[i];
  return o;
}

// ---- Reading ------------------------------------------------------------------------------------

struct Csv {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // line number of each row in the file

  std::size_t col(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    throw Error(path + ": no column '" + name + "' in the header line");
  }
  double number(std::size_t row, std::size_t c) const {
    const std::string& s = rows[row][c];
    char* end = nullptr;
    errno = 0;
    double v = s.empty() ? 0 : std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0')
      throw Error(path + " line " + std::to_string(lines[row]) + ", column '" + header[c] + "': '" + s +
                  "' is not a number");
    return v;
  }
  double number(std::size_t row, const std::string& name) const { return number(row, col(name)); }
  const std::string& text(std::size_t row, const std::string& name) const { return rows[row][col(name)]; }
};

std::vector<std::string> splitLine(const std::string& line, const std::string& path, int lineNo) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c != '"') cur += c;
      else if (i + 1 < line.size() && line[i + 1] == '"') { cur += '"'; ++i; }
      else quoted = false;
    } else if (c == '"' && cur.empty()) quoted = true;
    else if (c == ',') { out.push_back(cur); cur.clear(); }
    else cur += c;
  }
  if (quoted) throw Error(path + " line " + std::to_string(lineNo) + ": a quoted field is not closed");
  out.push_back(cur);
  return out;
}

// The file at `path` with a header line; every row must have the header's number of fields.
Csv readCsv(const std::string& path, const char* writtenBy) {
  Csv c;
  c.path = path;
  std::ifstream f(path);
  if (!f) throw Error(path + ": cannot read it (" + writtenBy + " writes it)");
  std::string line;
  int lineNo = 0;
  while (std::getline(f, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> fields = splitLine(line, path, lineNo);
    if (c.header.empty()) { c.header = std::move(fields); continue; }
    if (fields.size() != c.header.size())
      throw Error(path + " line " + std::to_string(lineNo) + ": " + std::to_string(fields.size()) +
                  " fields, the header line has " + std::to_string(c.header.size()));
    c.rows.push_back(std::move(fields));
    c.lines.push_back(lineNo);
  }
  if (c.header.empty()) throw Error(path + ": empty (no header line)");
  return c;
}

// run.csv: key,value rows; a key that is a list (model, angle, ...) repeats, in order.
struct Run {
  Csv csv;
  std::vector<std::string> all(const std::string& key) const {
    std::vector<std::string> out;
    for (const auto& r : csv.rows)
      if (r[0] == key) out.push_back(r[1]);
    return out;
  }
  std::string get(const std::string& key) const {
    for (const auto& r : csv.rows)
      if (r[0] == key) return r[1];
    throw Error(csv.path + ": no row for key '" + key + "'");
  }
  double num(const std::string& key) const {
    for (std::size_t i = 0; i < csv.rows.size(); ++i)
      if (csv.rows[i][0] == key) return csv.number(i, 1);
    throw Error(csv.path + ": no row for key '" + key + "'");
  }
};

struct PointRow {
  std::string model, preset, strategy, integrand, thetaText;
  double theta = 0, z = 0, ns = 0, t3 = 0;  // theta: read to check it is a number; shown as thetaText
  bool agree = true, extrapolated = false, analyticIsCosine = false;
  double failed = 0, tabBytes = 0;
};

// The rows of the CSV file at `path` as Row, each filled by fill(csv, row index, row).
template <class Row, class Fill>
std::vector<Row> readRows(const std::string& path, const char* writtenBy, Fill fill) {
  Csv c = readCsv(path, writtenBy);
  std::vector<Row> out(c.rows.size());
  for (std::size_t i = 0; i < c.rows.size(); ++i) fill(c, i, out[i]);
  return out;
}

std::vector<PointRow> readPoint(const std::string& path) {
  return readRows<PointRow>(path, "experiment 1", [&](const Csv& c, std::size_t i, PointRow& r) {
    r.model = c.text(i, "model");
    r.preset = c.text(i, "preset");
    r.strategy = c.text(i, "strategy");
    r.integrand = c.text(i, "integrand");
    if (r.integrand != "albedo" && r.integrand != "env")
      throw Error(path + " line " + std::to_string(c.lines[i]) + ", column 'integrand': '" + r.integrand +
                  "' is neither albedo nor env");
    r.thetaText = c.text(i, "theta");
    r.theta = c.number(i, "theta");
    r.z = c.number(i, "z");
    r.agree = c.number(i, "agree") != 0;
    r.ns = c.number(i, "ns_per_sample");
    r.t3 = c.number(i, "t_1e-3");
    r.extrapolated = c.number(i, "extrapolated_1e-3") != 0;
    r.analyticIsCosine = c.number(i, "analytic_is_cosine") != 0;
    r.failed = c.number(i, "failed_samples");
    r.tabBytes = c.number(i, "tab_bytes_per_table");
  });
}

struct SceneRow {
  std::string experiment, scene, variant, rerunZ;
  double relMse = 0, seconds = 0, z = 0, nonFinite = 0;
  bool agree = true;
  double cost() const { return relMse * seconds; }
};

std::vector<SceneRow> readScenes(const std::string& path) {
  return readRows<SceneRow>(path, "experiment 2", [](const Csv& c, std::size_t i, SceneRow& r) {
    r.experiment = c.text(i, "experiment");
    r.scene = c.text(i, "scene");
    r.variant = c.text(i, "variant");
    r.rerunZ = c.text(i, "rerun_z");
    r.relMse = c.number(i, "rel_mse");
    r.seconds = c.number(i, "seconds");
    r.z = c.number(i, "z_mean");
    r.agree = c.number(i, "agree") != 0;
    r.nonFinite = c.number(i, "nonfinite");
  });
}

// ---- Model families -----------------------------------------------------------------------------

// The report groups the models by the shape of their lobe, which decides which strategy can follow
// it (docs/results-method.md, "Model families"). A model in none of these lists is shown under
// "Other"; a measured material (model merl-<file>) under "Measured".
struct Family {
  const char* name;
  std::vector<std::string> models;
};
const std::vector<Family>& families() {
  static const std::vector<Family> f = {
      {"Diffuse", {"lambert", "oren_nayar", "minnaert"}},
      {"Phong-like lobes", {"phong_specular", "phong", "lewis", "blinn", "ashikhmin_shirley", "lafortune"}},
      {"Microfacet and physically based", {"torrance_sparrow", "ward", "gltf_pbr", "coupled", "beard_maxwell", "htsg", "rough_dielectric", "rough_thin_dielectric"}},
      {"Other empirical", {"schlick", "strauss", "poulin_fournier"}},
  };
  return f;
}
std::string familyOf(const std::string& model) {
  for (const Family& f : families())
    if (std::find(f.models.begin(), f.models.end(), model) != f.models.end()) return f.name;
  return model.rfind("merl-", 0) == 0 ? "Measured" : "Other";
}

// ---- Experiment 1: cases ------------------------------------------------------------------------

// One model x preset x angle x integrand: its row per strategy (in the run's strategy order).
struct Case {
  std::string model, preset, thetaText, integrand;
  std::vector<const PointRow*> s;
  int winner = -1;           // fastest to 1e-3
  int bestOther = -1;        // fastest but the quadtree
  double ratio = NAN;        // quadtree's time over bestOther's (finite, or NaN)
};

std::vector<Case> makeCases(const std::vector<PointRow>& rows, const std::vector<std::string>& strategies,
                            const std::string& integrand) {
  std::vector<Case> cases;
  std::map<std::string, std::size_t> index;
  for (const PointRow& r : rows) {
    if (r.integrand != integrand) continue;
    std::string key = r.model + "\n" + r.preset + "\n" + r.thetaText;
    auto [it, added] = index.emplace(key, cases.size());
    if (added) {
      Case c;
      c.model = r.model;
      c.preset = r.preset;
      c.thetaText = r.thetaText;
      c.integrand = integrand;
      c.s.assign(strategies.size(), nullptr);
      cases.push_back(c);
    }
    auto si = std::find(strategies.begin(), strategies.end(), r.strategy);
    if (si != strategies.end()) cases[it->second].s[si - strategies.begin()] = &r;
  }
  // A time that is not a number counts as never reaching the error; ties go to the first strategy.
  auto faster = [](const PointRow* a, const PointRow* b) {
    return !std::isnan(a->t3) && (std::isnan(b->t3) || a->t3 < b->t3);
  };
  for (Case& c : cases) {
    for (std::size_t i = 0; i < c.s.size(); ++i) {
      if (!c.s[i]) continue;
      if (c.winner < 0 || faster(c.s[i], c.s[c.winner])) c.winner = int(i);
      if (i > 0 && (c.bestOther < 0 || faster(c.s[i], c.s[c.bestOther]))) c.bestOther = int(i);
    }
    if (c.s[0] && c.bestOther >= 0) {
      double q = c.s[0]->t3, b = c.s[c.bestOther]->t3;
      if (std::isfinite(q) && std::isfinite(b) && b > 0) c.ratio = q / b;
    }
  }
  return cases;
}

struct GeoMean {
  double logSum = 0;
  int n = 0;
  void add(double x) {
    if (std::isfinite(x) && x > 0) { logSum += std::log(x); ++n; }
  }
  double value() const { return n ? std::exp(logSum / n) : NAN; }
};

std::string caseName(const Case& c) { return c.model + " " + c.preset + " " + c.thetaText + "°"; }

// "analytic 12, quadtree 9, ..." (strategies in the run's order, those with no win left out).
std::string winCounts(const std::vector<const Case*>& cases, const std::vector<std::string>& strategies) {
  std::vector<std::string> parts;
  for (std::size_t i = 0; i < strategies.size(); ++i) {
    int n = 0;
    for (const Case* c : cases) n += c->winner == int(i);
    if (n) parts.push_back(strategies[i] + " " + std::to_string(n));
  }
  return parts.empty() ? "none" : join(parts);
}

// ---- The report ---------------------------------------------------------------------------------

void writeSettings(std::ostringstream& o, const Run& run, const std::vector<PointRow>& rows) {
  std::vector<std::string> files = run.all("file");
  o << "Settings: models " << join(run.all("model")) << "; presets " << join(run.all("preset"));
  if (!files.empty()) o << "; measured materials (model `merl-<file name>`, preset `measured`) " << join(files);
  int reps = int(run.num("reps"));
  o << "; incident angles " << join(run.all("angle")) << "°; sample counts 2^0 .. 2^" << run.get("max_log2")
    << "; relative error = RMS over " << reps << " repetitions (itself uncertain by about "
    << fmt("%.0f", 100.0 / std::sqrt(2.0 * reps)) << " %)";
  double lo = INFINITY, hi = 0;
  for (const PointRow& r : rows)
    if (r.strategy == "tabulated") { lo = std::min(lo, r.tabBytes); hi = std::max(hi, r.tabBytes); }
  if (hi > 0)
    o << "; the tabulated strategy at the quadtree's memory per table (`bytesPerTableLike`): " << fmt("%.1f", lo / 1024)
      << " to " << fmt("%.1f", hi / 1024) << " KiB per table";
  o << ".\n\n";
}

void writeFamilyTable(std::ostringstream& o, const std::vector<const Case*>& cases,
                      const std::vector<std::string>& strategies) {
  // Rows: model x preset in the order of the run; per strategy the geometric mean over the angles.
  std::vector<std::pair<std::string, std::string>> keys;
  for (const Case* c : cases)
    if (std::find(keys.begin(), keys.end(), std::make_pair(c->model, c->preset)) == keys.end())
      keys.push_back({c->model, c->preset});
  o << "| model | preset |";
  for (const std::string& s : strategies) o << " " << s << " |";
  o << " fastest (angles) | quadtree / best other |\n|---|---|";
  for (std::size_t i = 0; i < strategies.size(); ++i) o << "---|";
  o << "---|---|\n";
  for (const auto& [model, preset] : keys) {
    std::vector<const Case*> sel;
    for (const Case* c : cases)
      if (c->model == model && c->preset == preset) sel.push_back(c);
    std::vector<double> mean(strategies.size(), NAN);
    std::vector<bool> star(strategies.size(), false), asCos(strategies.size(), false);
    for (std::size_t i = 0; i < strategies.size(); ++i) {
      double logSum = 0;
      bool ok = true;
      for (const Case* c : sel) {
        const PointRow* r = c->s[i];
        if (!r || !(r->t3 > 0) || !std::isfinite(r->t3)) { ok = false; break; }
        logSum += std::log(r->t3);
        star[i] = star[i] || r->extrapolated;
        asCos[i] = asCos[i] || r->analyticIsCosine;
      }
      if (ok && !sel.empty()) mean[i] = std::exp(logSum / double(sel.size()));
    }
    int best = -1;
    for (std::size_t i = 0; i < strategies.size(); ++i)
      if (std::isfinite(mean[i]) && (best < 0 || mean[i] < mean[best])) best = int(i);
    o << "| " << model << " | " << preset << " |";
    for (std::size_t i = 0; i < strategies.size(); ++i) {
      std::string cell = (star[i] && std::isfinite(mean[i]) ? "~" : "") + fmtTime(mean[i]);
      if (int(i) == best) cell = "**" + cell + "**";
      if (asCos[i]) cell += " (=cosine)";
      o << " " << cell << " |";
    }
    // The winners with their angles: "analytic (0, 30), tabulated (60)".
    std::vector<std::string> parts;
    for (std::size_t i = 0; i < strategies.size(); ++i) {
      std::vector<std::string> angles;
      for (const Case* c : sel)
        if (c->winner == int(i)) angles.push_back(c->thetaText);
      if (!angles.empty()) parts.push_back(strategies[i] + " (" + join(angles) + ")");
    }
    GeoMean g;
    for (const Case* c : sel) g.add(c->ratio);
    o << " " << join(parts) << " | " << fmtRatio(g.value()) << " |\n";
  }
  o << "\n";
}

// Experiment 1's cases, by integrand and family.
struct PointCases {
  std::vector<Case> env, alb;
  std::vector<std::string> families;  // present ones, in the report's order
  std::vector<const Case*> envOf(const std::string& fam) const {
    std::vector<const Case*> sel;
    for (const Case& c : env)
      if (familyOf(c.model) == fam) sel.push_back(&c);
    return sel;
  }
};

PointCases makePointCases(const std::vector<PointRow>& rows, const std::vector<std::string>& strategies) {
  PointCases p;
  p.env = makeCases(rows, strategies, "env");
  p.alb = makeCases(rows, strategies, "albedo");
  std::vector<std::string> names;
  for (const Family& f : families()) names.push_back(f.name);
  names.push_back("Other");
  names.push_back("Measured");
  for (const std::string& n : names)
    if (!p.envOf(n).empty()) p.families.push_back(n);
  return p;
}

std::vector<const Case*> pointers(const std::vector<Case>& cases) {
  std::vector<const Case*> out;
  for (const Case& c : cases) out.push_back(&c);
  return out;
}

// The summary's bullets for experiment 1.
void writePointSummary(std::ostringstream& o, const std::vector<PointRow>& rows, const PointCases& p,
                       const std::vector<std::string>& strategies, double zPoint) {
  int quadWins = 0;
  GeoMean all;
  double nsQ = 0, nsC = 0;
  int nsN = 0;
  const std::size_t cos = std::size_t(std::find(strategies.begin(), strategies.end(), "cosine") - strategies.begin());
  for (const Case& c : p.env) {
    quadWins += c.winner == 0;
    all.add(c.ratio);
    if (c.s[0] && cos < c.s.size() && c.s[cos]) { nsQ += c.s[0]->ns; nsC += c.s[cos]->ns; ++nsN; }
  }
  o << "One shading point, environment integrand (b), time to a relative error of 1e-3 (the albedo integrand (a) "
       "is exact for the quadtree by construction, so it is not the comparison: "
       "[integrands](results-method.md#integrands)):\n\n";
  o << "- The quadtree is the fastest strategy in " << quadWins << " of " << p.env.size()
    << " cases (model x preset x angle); the fastest over all cases: " << winCounts(pointers(p.env), strategies)
    << ".\n";
  o << "- The quadtree's time over the best other strategy's: geometric mean " << fmtRatio(all.value()) << " over "
    << all.n << " cases (below 1: the quadtree is faster).\n";
  if (nsN)
    o << "- Cost per sample, mean over the cases: quadtree " << fmt("%.1f", nsQ / nsN) << " ns, cosine "
      << fmt("%.1f", nsC / nsN) << " ns (" << fmtRatio(nsQ / nsC) << " x).\n";
  o << "- Albedo integrand (a), for the record: the fastest " << winCounts(pointers(p.alb), strategies) << " ("
    << p.alb.size() << " cases).\n";
  int disagree = 0;
  double failed = 0;
  std::vector<std::string> bad;
  for (const PointRow& r : rows) {
    if (r.integrand == "env") failed += r.failed;  // one count per batch, on both integrands' rows
    if (!r.agree) {
      ++disagree;
      bad.push_back(r.model + " " + r.preset + " " + r.thetaText + "° " + r.strategy + " " + r.integrand + " (z " +
                    fmt("%.2f", r.z) + ")");
    }
  }
  o << "- Agreement with the quadrature references: " << (rows.size() - std::size_t(disagree)) << " of "
    << rows.size() << " estimates within |z| <= " << fmt("%.2f", zPoint)
    << (bad.empty() ? "" : "; disagreeing: " + join(bad)) << ".\n";
  if (failed > 0) o << "- Failed samples (no direction, zero pdf or a non-finite weight; counted as 0): " << fmt("%.0f", failed) << " in all.\n";
}

// The discussion's table: experiment 1 per model family.
void writeFamilySummary(std::ostringstream& o, const PointCases& p, const std::vector<std::string>& strategies) {
  o << "| family | cases | quadtree fastest | fastest, all strategies | quadtree / best other (geo. mean) | "
       "quadtree's best case | quadtree's worst case |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& fam : p.families) {
    std::vector<const Case*> sel = p.envOf(fam);
    GeoMean g;
    const Case *best = nullptr, *worst = nullptr;
    int qw = 0;
    for (const Case* c : sel) {
      g.add(c->ratio);
      qw += c->winner == 0;
      if (!std::isfinite(c->ratio)) continue;
      if (!best || c->ratio < best->ratio) best = c;
      if (!worst || c->ratio > worst->ratio) worst = c;
    }
    o << "| " << fam << " | " << sel.size() << " | " << qw << " | " << winCounts(sel, strategies) << " | "
      << fmtRatio(g.value()) << " |";
    for (const Case* c : {best, worst}) {
      if (c) o << " " << caseName(*c) << ": " << fmtRatio(c->ratio) << " x " << strategies[c->bestOther] << "'s time";
      o << " |";
    }
    o << "\n";
  }
  o << "\n";
}

void writePointFamilies(std::ostringstream& o, const Run& run, const std::vector<PointRow>& rows,
                        const PointCases& p, const std::vector<std::string>& strategies) {
  o << "## Experiment 1: one shading point, by model family\n\n";
  writeSettings(o, run, rows);
  o << "Each cell: the time to reach a relative error of 1e-3 in the environment integrand, geometric mean over "
       "the angles (`~`: at least one of them extrapolated beyond 2^"
    << run.get("max_log2") << " samples, `-`: not reached); **bold**: the smallest in the row; `(=cosine)`: the "
       "model has no analytic sampler and `analytic` falls back to cosine. `fastest (angles)`: the fastest strategy "
       "at each angle; `quadtree / best other`: geometric mean over the angles of the quadtree's time over the "
       "fastest other strategy's. Every angle, both integrands, the time to 1e-2 and the z of each estimate: "
       "`point_summary.csv`.\n\n";
  for (const std::string& fam : p.families) {
    o << "### " << fam << "\n\n";
    writeFamilyTable(o, p.envOf(fam), strategies);
  }
}

std::vector<std::string> sceneNames(const std::vector<SceneRow>& rows) {
  std::vector<std::string> names;
  for (const SceneRow& r : rows)
    if (std::find(names.begin(), names.end(), r.scene) == names.end()) names.push_back(r.scene);
  return names;
}

// A scene's "strategies" renders in the run's strategy order (nullptr: not rendered).
std::vector<const SceneRow*> strategyRows(const std::vector<SceneRow>& rows, const std::string& scene,
                                          const std::vector<std::string>& strategies) {
  std::vector<const SceneRow*> by(strategies.size(), nullptr);
  for (const SceneRow& r : rows)
    if (r.experiment == "strategies" && r.scene == scene) {
      auto it = std::find(strategies.begin(), strategies.end(), r.variant);
      if (it != strategies.end()) by[it - strategies.begin()] = &r;
    }
  return by;
}

// The lowest relMSE x seconds of `by`, from index `first` on (nullptr: none).
const SceneRow* cheapest(const std::vector<const SceneRow*>& by, std::size_t first) {
  const SceneRow* best = nullptr;
  for (std::size_t i = first; i < by.size(); ++i)
    if (by[i] && (!best || by[i]->cost() < best->cost())) best = by[i];
  return best;
}

// The summary's bullets for experiment 2.
void writeSceneSummary(std::ostringstream& o, const std::vector<SceneRow>& rows,
                       const std::vector<std::string>& strategies, double zScene) {
  std::vector<std::string> ratios;
  for (const std::string& n : sceneNames(rows)) {
    std::vector<const SceneRow*> by = strategyRows(rows, n, strategies);
    const SceneRow* other = cheapest(by, 1);
    if (by[0] && other)
      ratios.push_back(n + " " + fmtRatio(by[0]->cost() / other->cost()) + " (against " + other->variant + ")");
  }
  o << "- Scenes, the quadtree's relMSE x seconds over the best other strategy's (below 1: the quadtree is "
       "better): " << join(ratios, "; ") << ".\n";
  int disagree = 0;
  double nonFinite = 0;
  std::vector<std::string> reruns;
  for (const SceneRow& r : rows) {
    disagree += !r.agree;
    nonFinite += r.nonFinite;
    if (!r.rerunZ.empty())
      reruns.push_back(r.scene + " " + r.variant + ": z " + fmt("%.2f", r.z) + ", reruns " + r.rerunZ + " (" +
                       (r.agree ? "agree" : "**disagrees**") + ")");
  }
  o << "- Agreement of the image means with the reference's: " << (rows.size() - std::size_t(disagree)) << " of "
    << rows.size() << " renders within |z| <= " << fmt("%.2f", zScene) << " (after reruns: "
    << "[agreement](results-method.md#agreement))";
  if (!reruns.empty()) o << "; rerun after a first z beyond it: " << join(reruns, "; ");
  o << ".\n";
  if (nonFinite > 0) o << "- Non-finite samples in the renders: " << fmt("%.0f", nonFinite) << ".\n";
}

void writeScenes(std::ostringstream& o, const Run& run, const std::vector<SceneRow>& rows,
                 const std::vector<std::string>& strategies) {
  o << "## Experiment 2: scenes\n\n";
  o << "Width " << run.get("width") << " pixels, " << run.get("spp") << " spp per render, reference: quadtree at "
    << run.get("ref_spp") << " spp. Scenes: ";
  std::vector<std::string> notes;
  for (const std::string& n : sceneNames(rows)) {
    std::vector<std::string> note = run.all("scene." + n);
    notes.push_back("`" + n + "`" + (note.empty() ? "" : ": " + note[0]));
  }
  o << join(notes, "; ") << ".\n\n";
  o << "### Strategies\n\n";
  o << "Each cell: relMSE x seconds over the best in the row (1 = the best; lower is better); the last columns: "
       "the best one's relMSE and seconds.\n\n| scene |";
  for (const std::string& s : strategies) o << " " << s << " |";
  o << " best relMSE | best seconds |\n|---|";
  for (std::size_t i = 0; i < strategies.size(); ++i) o << "---|";
  o << "---|---|\n";
  for (const std::string& n : sceneNames(rows)) {
    std::vector<const SceneRow*> by = strategyRows(rows, n, strategies);
    const SceneRow* best = cheapest(by, 0);
    if (!best) continue;
    o << "| " << n << " |";
    for (const SceneRow* r : by) {
      if (!r) { o << " |"; continue; }
      std::string cell = fmtRatio(r->cost() / best->cost());
      if (r == best) cell = "**" + cell + "**";
      if (!r->agree) cell += " (disagrees)";
      o << " " << cell << " |";
    }
    o << " " << fmt("%.3e", best->relMse) << " | " << fmt("%.3g", best->seconds) << " |\n";
  }
  o << "\n";
  for (const char* exp : {"rng", "components"}) {
    bool any = false;
    for (const SceneRow& r : rows) any |= r.experiment == exp;
    if (!any) continue;
    o << "### " << (std::string(exp) == "rng" ? "Random numbers: PCG against QMC (quadtree)"
                                              : "Combined materials: component choice by albedo against uniform (quadtree)")
      << "\n\n| scene | variant | relMSE | seconds | relMSE x seconds | x best | z |\n|---|---|---|---|---|---|---|\n";
    for (const SceneRow& r : rows) {
      if (r.experiment != exp) continue;
      double best = INFINITY;
      for (const SceneRow& q : rows)
        if (q.experiment == exp && q.scene == r.scene) best = std::min(best, q.cost());
      o << "| " << r.scene << " | " << r.variant << " | " << fmt("%.3e", r.relMse) << " | " << fmt("%.3g", r.seconds)
        << " | " << fmt("%.3e", r.cost()) << " | " << fmtRatio(r.cost() / best) << " | " << fmt("%.2f", r.z) << " |\n";
    }
    o << "\n";
  }
}

}  // namespace

std::string csvField(const std::string& text) {
  bool quote = text.find_first_of(",\"\r\n") != std::string::npos ||
               (!text.empty() && (text.front() == ' ' || text.back() == ' '));
  if (!quote) return text;
  std::string o = "\"";
  for (char c : text) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string benchErrorReport(const std::string& dir) {
  Run run{readCsv(dir + "/run.csv", "nusselt bench error")};
  if (run.csv.header != std::vector<std::string>{"key", "value"})
    throw Error(run.csv.path + ": the header line must be key,value");
  const bool point = run.num("experiment_point") != 0, scenes = run.num("experiment_scenes") != 0;
  std::vector<PointRow> pointRows;
  std::vector<SceneRow> sceneRows;
  if (point) pointRows = readPoint(dir + "/point_summary.csv");
  if (scenes) sceneRows = readScenes(dir + "/scenes.csv");
  const std::vector<std::string> strategies = run.all("strategy");
  if (strategies.empty() || strategies[0] != "quadtree")
    throw Error(run.csv.path + ": the first row for key 'strategy' must be quadtree (the strategy compared)");

  std::ostringstream o;
  o << "# Speed against error: results\n\n";
  o << "Generated by `" << run.get("command") << "` (" << run.get("run") << ") on " << run.get("device") << " in "
    << fmt("%.0f", run.num("total_seconds")) << " s. Every number below is computed from that run's CSV files "
    << "(`run.csv`" << (point ? ", `point_summary.csv`" : "") << (scenes ? ", `scenes.csv`" : "")
    << " in its output directory); `nusselt bench error --report-from "
       "DIR` writes this report again from them. How the figures are measured, the model families and the "
       "mechanisms behind the results: [results-method.md](results-method.md) (docs/results-method.md).\n\n";
  const bool havePoint = point && !pointRows.empty(), haveScenes = scenes && !sceneRows.empty();
  PointCases cases;
  if (havePoint) cases = makePointCases(pointRows, strategies);
  o << "## Summary\n\n";
  if (!havePoint && !haveScenes) o << "- This run measured nothing (experiment 1 and experiment 2 both left out).\n";
  if (havePoint) writePointSummary(o, pointRows, cases, strategies, run.num("z_point"));
  if (haveScenes) writeSceneSummary(o, sceneRows, strategies, run.num("z_scene"));
  o << "\n## Discussion\n\n";
  if (havePoint) {
    o << "One shading point, environment integrand (b), by model family (the grouping: "
         "[model families](results-method.md#model-families); per model in the next section):\n\n";
    writeFamilySummary(o, cases, strategies);
  }
  o << "The mechanisms behind these figures (exact analytic samplers, the cost of rejection sampling on this "
       "device, piecewise-constant tables against narrow lobes): [mechanisms](results-method.md#mechanisms).\n\n";
  if (havePoint) writePointFamilies(o, run, pointRows, cases, strategies);
  if (haveScenes) writeScenes(o, run, sceneRows, strategies);
  o << "## Files\n\n";
  o << "In the run's output directory: `run.csv` (the settings above, key,value)";
  if (point)
    o << "; `point_summary.csv` (the full matrix of experiment 1: one row per model, preset, angle, strategy and "
         "integrand, with the reference, mean, z, ns per sample, times to 1e-2 and 1e-3, failures and memory); "
         "`point.csv` (the error curves: relative error at every sample count); `point-<model>-<preset>.png` "
         "(rows (a) albedo and (b) environment, columns the angles; x = time per estimate, log10 s from "
      << run.get("plot_log10_seconds_min") << " to " << run.get("plot_log10_seconds_max")
      << "; y = relative error, log10 from " << run.get("plot_log10_error_min") << " to "
      << run.get("plot_log10_error_max") << ", grey lines at 1e-2 and 1e-3; colours: " << [&] {
           std::vector<std::string> c;
           for (const std::string& s : strategies) c.push_back(s + " " + run.get("plot_colour." + s));
           return join(c);
         }() << ")";
  if (scenes)
    o << "; `scenes.csv` (every render); `scene-<name>.png` (the reference, then the strategies in the order of "
         "the table, error heat maps below) and the EXRs beside it (`scene-<name>-<strategy>.exr`, "
         "`-reference.exr`; compare with `tools/compare_exr.sh`)";
  o << ".\n";
  return o.str();
}

}  // namespace nusselt
