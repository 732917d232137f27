// preview.cpp: `nusselt preview` (issue 7). Scaffold: the command is added with the preview.
#include "cli/commands.h"

namespace nusselt {
void registerPreviewCommand(CLI::App&, CommandRunner&) {}
}  // namespace nusselt
