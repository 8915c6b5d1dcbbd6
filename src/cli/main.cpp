// pathex: a thin front end over the library; the command line is cli/app.cpp.
#include "cli/common.h"

int main(int argc, char** argv) { return pathex::cli::run_command_line(argc, argv); }
