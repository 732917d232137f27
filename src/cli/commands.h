// commands.h: the command line of nusselt (`nusselt --help`). Returns the process exit status.
#pragma once
#include <functional>

namespace CLI {
class App;
}

namespace nusselt {

int runCli(int argc, char** argv);

// Modules add their own subcommands. A subcommand's CLI11 callback stores in `run` the work to
// do; runCli calls it after parsing, inside the error handling every command shares (a
// nusselt::Error becomes "error: ..." and exit status 1).
using CommandRunner = std::function<int()>;
// `nusselt sample` and `nusselt bench precompute` (src/cli/sampler_commands.cpp).
void registerSamplerCommands(CLI::App& app, CLI::App& bench, CommandRunner& run);
// `nusselt bench error` (src/cli/bench_error.cpp); registered by registerSamplerCommands.
void registerBenchError(CLI::App& bench, CommandRunner& run);
// `nusselt bench bins` (src/cli/bench_bins.cpp); registered by registerSamplerCommands.
void registerBenchBins(CLI::App& bench, CommandRunner& run);
// `nusselt preview` (src/cli/preview.cpp).
void registerPreviewCommand(CLI::App& app, CommandRunner& run);
// `nusselt models` (src/cli/models_command.cpp).
void registerModelsCommand(CLI::App& app, CommandRunner& run);
// `nusselt guide-view` (src/cli/guide_view.cpp).
void registerGuideViewCommand(CLI::App& app, CommandRunner& run);

}  // namespace nusselt
