// main.cpp: nusselt's entry point; everything else is in the library (src/cli/commands.cpp).
#include "cli/commands.h"

int main(int argc, char** argv) { return nusselt::runCli(argc, argv); }
