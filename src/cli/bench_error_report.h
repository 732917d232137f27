// bench_error_report.h: the report of `nusselt bench error`, made from the CSV files of one run
// and nothing else (no device, no GPU work): run.csv (the settings: command line, device, models,
// angles, counts, thresholds; key,value rows), point_summary.csv (experiment 1, when the run had
// it) and scenes.csv (experiment 2, when it had it). The experiment (bench_error.cpp) writes
// those files and then calls benchErrorReport on its own output directory, and
// `nusselt bench error --report-from DIR` calls it on an old one: one report path, so the two
// give the same bytes. Method and mechanisms: docs/results-method.md.
#pragma once
#include <string>
#include <vector>

namespace nusselt {

// The Markdown report of the run whose CSV files are in `dir`. Throws nusselt::Error naming the
// file (and the line and column) when one is missing, unreadable or malformed.
std::string benchErrorReport(const std::string& dir);

// One CSV field as written by the experiment: quoted (with inner quotes doubled) when it holds a
// comma, a quote or leading/trailing space; as is otherwise. The reader undoes it.
std::string csvField(const std::string& text);

}  // namespace nusselt
