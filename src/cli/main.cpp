// pathex: a thin front end over the library; the command line is cli/app.cpp. It runs on a thread
// with the explicit stack that --max-depth's ceiling is proven against (core/stack.h).
#include <malloc.h>

#include <cstdio>

#include "cli/common.h"
#include "core/stack.h"

int main(int argc, char** argv) {
  // glibc's allocator serves blocks of 128 KiB and more (the dynamic threshold starts there) with
  // their own mmap and returns freed memory at the heap's top to the kernel, so every output
  // buffer, JSON document and string of a render is faulted in afresh, page by page (~10 us each
  // on a VM). A command-line process that exits soon keeps what it freed for reuse instead: blocks
  // below 32 MiB come from the heap, and its top is given back only past 256 MiB free. 30 % fewer
  // page faults for a 256 x 256 render (bench/README.md, issue 19).
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  int code = pathex::cli::kExitBadInput;
  pathex::cli::allow_fast_exit();  // a command that has written its outputs may end without freeing
  if (!pathex::run_on_stack(pathex::kCommandLineStackBytes,
                            [&] { code = pathex::cli::run_command_line(argc, argv); })) {
    std::fprintf(stderr, "pathex: error: cannot start the command line's thread (a %zu MiB stack)\n",
                 pathex::kCommandLineStackBytes >> 20);
  }
  return code;
}
