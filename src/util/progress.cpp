// progress.cpp: see progress.h.
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include <sys/ioctl.h>
#include <unistd.h>

namespace nusselt {
namespace {

constexpr int kBarWidth = 20;
// ~10 redraws per second: smooth enough to read, cheap enough not to matter.
constexpr auto kRedrawInterval = std::chrono::milliseconds(100);

// Two or three significant digits: "0.05", "3.2", "31.2", "812".
std::string formatRate(double rate) {
  char buf[32];
  if (rate >= 100.0) std::snprintf(buf, sizeof buf, "%.0f", rate);
  else if (rate >= 1.0) std::snprintf(buf, sizeof buf, "%.1f", rate);
  else std::snprintf(buf, sizeof buf, "%.2f", rate);
  return buf;
}

// Terminal width of stderr, or 0 if unknown (not a terminal, or the ioctl fails).
int terminalWidth() {
  winsize ws{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) return ws.ws_col;
  return 0;
}

}  // namespace

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  // Round to whole seconds first so that 59.7 s prints as 1:00, not 0:60.
  double rounded = std::floor(seconds + 0.5);
  if (rounded > 1e9) return "--:--";  // absurd ETA (rate ~0): don't print a 10-digit hour count
  uint64_t total = uint64_t(rounded);
  uint64_t h = total / 3600, m = (total / 60) % 60, s = total % 60;
  char buf[48];
  if (h > 0)
    std::snprintf(buf, sizeof buf, "%llu:%02llu:%02llu", (unsigned long long)h,
                  (unsigned long long)m, (unsigned long long)s);
  else
    std::snprintf(buf, sizeof buf, "%llu:%02llu", (unsigned long long)m, (unsigned long long)s);
  return buf;
}

Progress::Progress(std::string label, uint64_t total, uint64_t unitsPerStep, bool forceTerminal,
                   bool quiet)
    : label_(std::move(label)),
      total_(total),
      unitsPerStep_(unitsPerStep),
      terminal_(forceTerminal || ::isatty(STDERR_FILENO)),
      quiet_(quiet),
      start_(Clock::now()),
      lastDraw_(start_) {}

Progress::~Progress() {
  if (barShown_ && !finished_) {
    std::fputs("\n", stderr);
    std::fflush(stderr);
  }
}

double Progress::elapsed() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

std::string Progress::barLine(uint64_t done, double elapsedSeconds) const {
  uint64_t shown = std::min(done, total_);
  int filled = total_ == 0 ? kBarWidth : int(shown * kBarWidth / total_);
  std::string line = label_ + " [" + std::string(size_t(filled), '#') +
                     std::string(size_t(kBarWidth - filled), '.') + "] " + std::to_string(done) +
                     "/" + std::to_string(total_) + " spp";
  if (done > 0 && elapsedSeconds > 0.0) {
    double rate = double(done) / elapsedSeconds;
    line += "  " + formatRate(rate) + " spp/s";
    if (unitsPerStep_ > 0) line += "  " + formatRate(rate * double(unitsPerStep_) / 1e6) + " Msamples/s";
    double remaining = done >= total_ ? 0.0 : double(total_ - done) / rate;
    line += "  ETA " + formatDuration(remaining);
  } else {
    line += "  ETA --:--";
  }
  return line;
}

std::string Progress::summaryLine(uint64_t done, double elapsedSeconds,
                                  const std::string& extra) const {
  std::string line = label_ + ": ";
  line += done == total_ ? std::to_string(done)
                         : std::to_string(done) + " of " + std::to_string(total_);
  char buf[64];
  if (elapsedSeconds < 60.0) std::snprintf(buf, sizeof buf, "%.1f s", elapsedSeconds);
  else std::snprintf(buf, sizeof buf, "%s", formatDuration(elapsedSeconds).c_str());
  line += std::string(" spp in ") + buf;
  // Below a millisecond the rates are noise (and absurdly large); leave them out.
  if (done > 0 && elapsedSeconds >= 1e-3) {
    double rate = double(done) / elapsedSeconds;
    line += " (" + formatRate(rate) + " spp/s";
    if (unitsPerStep_ > 0) line += ", " + formatRate(rate * double(unitsPerStep_) / 1e6) + " Msamples/s";
    line += ")";
  }
  if (!extra.empty()) line += " " + extra;
  return line;
}

void Progress::update(uint64_t done) {
  done_ = done;
  if (quiet_ || !terminal_ || finished_) return;
  Clock::time_point now = Clock::now();
  // Always draw the first update and the last pass; rate-limit everything in between.
  if (barShown_ && now - lastDraw_ < kRedrawInterval && done < total_) return;
  lastDraw_ = now;
  std::string line = barLine(done, std::chrono::duration<double>(now - start_).count());
  // A line longer than the terminal wraps, and "\r" then only returns to the start of the last
  // row, leaving a trail of partial bars: cut it to fit.
  int width = terminalWidth();
  if (width > 1 && line.size() >= size_t(width)) line.resize(size_t(width - 1));
  // "\r" back to column 0, then the line, then erase the rest of the previous (longer) line.
  std::fprintf(stderr, "\r%s\x1b[K", line.c_str());
  std::fflush(stderr);
  barShown_ = true;
}

void Progress::finish(const std::string& extra) {
  if (finished_) return;
  finished_ = true;
  if (quiet_) return;
  std::string line = summaryLine(done_, elapsed(), extra);
  if (barShown_) std::fputs("\r\x1b[K", stderr);
  std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
}

}  // namespace nusselt
