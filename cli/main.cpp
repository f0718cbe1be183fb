// polycube command line: one file per subcommand in cli/, wired here.
#include "cli/commands.h"

int main(int argc, char** argv) { return polycube::cli::run(argc, argv); }
