#include "util/stop_signal.h"

#include <csignal>

namespace nusselt {

std::atomic<int> g_stopSignal{0};

void onStopSignal(int sig) {
  g_stopSignal.store(sig);
  std::signal(sig, SIG_DFL);  // a second signal ends the program at once
}

ScopedStopSignals::ScopedStopSignals() {
  g_stopSignal = 0;
  m_int = std::signal(SIGINT, onStopSignal);
  m_term = std::signal(SIGTERM, onStopSignal);
}

ScopedStopSignals::~ScopedStopSignals() {
  std::signal(SIGINT, m_int);
  std::signal(SIGTERM, m_term);
}

}  // namespace nusselt
