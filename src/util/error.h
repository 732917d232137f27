// error.h: the one exception type of nusselt. Its message is what the user reads: it names the
// file and the field (or the option) and says what was expected.
#pragma once
#include <stdexcept>
#include <string>

namespace nusselt {

struct Error : std::runtime_error {
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Exit codes of the command line (documented in README "Exit status").
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,     // a render or I/O failure, or bad input (scene, parameters)
  kExitUsage = 2,       // a bad command line
  kExitInterrupted = 130 // SIGINT/SIGTERM: the partial image was written
};

}  // namespace nusselt
