// progress.h: progress display of a render on stderr.
//
// On a terminal (isatty(stderr), or forceTerminal) a one-line bar, redrawn in place at most
// ~10 times per second so that a fast render does not spend its time printing:
//   render [#########...........] 45/100 spp  12.3 spp/s  8.1 Msamples/s  ETA 0:04
// Not a terminal (a log file, CI): nothing while running, so logs stay readable; finish() prints
// one summary line either way:
//   render: 100 spp in 3.2 s (31.2 spp/s, 8.1 Msamples/s)
// "spp/s" is samples-per-pixel passes per second; "Msamples/s" is paths per second (pixel samples;
// a Metropolis render: mutations)
// (passes/s * unitsPerStep), shown when unitsPerStep > 0. Not thread-safe: call from one thread.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace nusselt {

// "m:ss" below an hour, "h:mm:ss" above; "--:--" for negative, NaN or infinite values (an ETA
// that is not known yet).
std::string formatDuration(double seconds);

class Progress {
 public:
  // label: first word of the bar and of the summary ("render"). total: number of steps (spp).
  // unitsPerStep: paths per step (pixels; chains for Metropolis), for Msamples/s (0: not shown).
  // quiet: print nothing at all.
  Progress(std::string label, uint64_t total, uint64_t unitsPerStep, bool forceTerminal = false,
           bool quiet = false);
  // Clears an unfinished bar's line, so an error message after an aborted render starts on a
  // fresh line instead of after the bar.
  ~Progress();

  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `done` steps completed so far (absolute, not an increment).
  void update(uint64_t done);
  // Replaces the bar with the summary line, using the last update() as the count (so an
  // interrupted render reports what it actually did). A non-empty `extra` is appended after a
  // space. Idempotent: a second call prints nothing.
  void finish(const std::string& extra = "");

  // The bar line for `done` steps after `elapsedSeconds` (no carriage return); public for tests.
  std::string barLine(uint64_t done, double elapsedSeconds) const;
  // The summary line (no newline); public for tests.
  std::string summaryLine(uint64_t done, double elapsedSeconds, const std::string& extra) const;

 private:
  using Clock = std::chrono::steady_clock;
  double elapsed() const;

  std::string label_;
  uint64_t total_;
  uint64_t unitsPerStep_;
  bool terminal_;
  bool quiet_;
  uint64_t done_ = 0;
  bool barShown_ = false;
  bool finished_ = false;
  Clock::time_point start_;
  Clock::time_point lastDraw_;
};

}  // namespace nusselt
