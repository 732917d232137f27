// commands.h: the command line of nusselt (`nusselt --help`). Returns the process exit status.
#pragma once
namespace nusselt {
int runCli(int argc, char** argv);
}
