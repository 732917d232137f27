// stop_signal.h: SIGINT and SIGTERM as a request to stop long work at the next safe point (the
// end of a sample pass), so that what has been computed can still be written. A second signal
// ends the program at once.
#pragma once
#include <atomic>

namespace nusselt {

// The signal (SIGINT, SIGTERM) that asked the program to stop, or 0.
extern std::atomic<int> g_stopSignal;
void onStopSignal(int sig);

// Installs onStopSignal for SIGINT and SIGTERM (and clears g_stopSignal) for its lifetime, then
// restores the previous handlers.
class ScopedStopSignals {
 public:
  ScopedStopSignals();
  ~ScopedStopSignals();
  ScopedStopSignals(const ScopedStopSignals&) = delete;
  ScopedStopSignals& operator=(const ScopedStopSignals&) = delete;

 private:
  void (*m_int)(int);
  void (*m_term)(int);
};

}  // namespace nusselt
