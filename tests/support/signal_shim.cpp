// A test hook that lives in the tests: an LD_PRELOAD library that sends the process a signal at
// the Nth file-system call of the kinds that writing an output set makes (tests/io/output_set_test.cpp
// walks N over every such call of `pathex trace`). Environment:
//   PATHEX_SHIM_AT      N (1-based); unset or 0: only count
//   PATHEX_SHIM_SIGNAL  the signal number (default SIGTERM)
//   PATHEX_SHIM_DIR     only calls on paths containing this text count (fsync always counts)
//   PATHEX_SHIM_COUNT   a file that receives the number of calls counted, at exit
//   PATHEX_SHIM_AWAIT   files (separated by ':') that must all exist before the signal is sent:
//                       the process waits for them at the Nth call (a synchronisation point
//                       between processes that the test controls, tests/cli/shard_cli_test.cpp)
// The signal goes to the calling thread (raise), before the call itself runs, so that it arrives
// exactly at this call. A process-directed kill() would not: the kernel may hand it to another
// thread (the main thread, which waits for the command line's thread, core/stack.h), whose handler
// then runs a moment later, after the program has moved on.
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

#include "await_files.h"

namespace {

std::atomic<long> g_calls{0};

const char* env(const char* name) { return std::getenv(name); }

bool watched(const char* path) {
  const char* dir = env("PATHEX_SHIM_DIR");
  return path != nullptr && (dir == nullptr || std::strstr(path, dir) != nullptr);
}

void count(bool counts) {
  if (!counts) return;
  const long n = ++g_calls;
  const char* at = env("PATHEX_SHIM_AT");
  if (at == nullptr || std::atol(at) != n) return;
  pathex_test::await_files("PATHEX_SHIM_AWAIT");
  const char* sig = env("PATHEX_SHIM_SIGNAL");
  ::raise(sig ? std::atoi(sig) : SIGTERM);
}

struct Report {
  ~Report() {
    if (const char* file = env("PATHEX_SHIM_COUNT")) {
      if (FILE* f = std::fopen(file, "w")) {
        std::fprintf(f, "%ld\n", g_calls.load());
        std::fclose(f);
      }
    }
  }
} g_report;

template <class F>
F next(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" {

int mkdir(const char* path, mode_t mode) {
  count(watched(path));
  return next<int (*)(const char*, mode_t)>("mkdir")(path, mode);
}
char* mkdtemp(char* templ) {
  count(watched(templ));
  return next<char* (*)(char*)>("mkdtemp")(templ);
}
int mkstemp(char* templ) {
  count(watched(templ));
  return next<int (*)(char*)>("mkstemp")(templ);
}
int fsync(int fd) {
  count(true);
  return next<int (*)(int)>("fsync")(fd);
}
int rename(const char* from, const char* to) {
  count(watched(from) || watched(to));
  return next<int (*)(const char*, const char*)>("rename")(from, to);
}
int renameat2(int fromfd, const char* from, int tofd, const char* to, unsigned flags) {
  count(watched(from) || watched(to));
  return next<int (*)(int, const char*, int, const char*, unsigned)>("renameat2")(fromfd, from, tofd, to, flags);
}
int unlink(const char* path) {
  count(watched(path));
  return next<int (*)(const char*)>("unlink")(path);
}
int rmdir(const char* path) {
  count(watched(path));
  return next<int (*)(const char*)>("rmdir")(path);
}
int remove(const char* path) {
  count(watched(path));
  return next<int (*)(const char*)>("remove")(path);
}

}  // extern "C"
