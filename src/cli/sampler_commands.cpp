// sampler_commands.cpp: `nusselt sample` and `nusselt bench precompute` (the quadtree sampler).
// Scaffold: the commands are added with the sampler (issue 4).
#include "cli/commands.h"

namespace nusselt {
void registerSamplerCommands(CLI::App&, CLI::App&, CommandRunner&) {}
}  // namespace nusselt
