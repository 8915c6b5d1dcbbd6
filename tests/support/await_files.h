// Shared by the LD_PRELOAD test shims (signal_shim.cpp, mpi_deal_shim.cpp): a synchronisation point
// between processes that a test controls through the file system.
#pragma once

#include <sys/stat.h>

#include <cstdlib>
#include <ctime>
#include <string>

namespace pathex_test {

inline void pause_ms(long ms) {
  const timespec t{ms / 1000, (ms % 1000) * 1'000'000};
  ::nanosleep(&t, nullptr);
}

// Waits until every file named in the environment variable `variable` (separated by ':') exists,
// polling with stat every 10 ms. Does nothing when the variable is unset.
inline void await_files(const char* variable) {
  const char* list = std::getenv(variable);
  if (list == nullptr) return;
  std::string rest = list;
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::string file = rest.substr(0, colon);
    rest = colon == std::string::npos ? "" : rest.substr(colon + 1);
    struct stat st {};
    while (!file.empty() && ::stat(file.c_str(), &st) != 0) pause_ms(10);
  }
}

}  // namespace pathex_test
