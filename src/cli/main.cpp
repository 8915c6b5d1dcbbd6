// pathex: a thin front end over the library; the command line is cli/app.cpp. It runs on a thread
// with the explicit stack that --max-depth's ceiling is proven against (core/stack.h).
#include <cstdio>

#include "cli/common.h"
#include "core/stack.h"

int main(int argc, char** argv) {
  int code = pathex::cli::kExitBadInput;
  pathex::cli::allow_fast_exit();  // a command that has written its outputs may end without freeing
  if (!pathex::run_on_stack(pathex::kCommandLineStackBytes,
                            [&] { code = pathex::cli::run_command_line(argc, argv); })) {
    std::fprintf(stderr, "pathex: error: cannot start the command line's thread (a %zu MiB stack)\n",
                 pathex::kCommandLineStackBytes >> 20);
  }
  return code;
}
