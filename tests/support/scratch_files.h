// Files a test writes into its process's scratch folder (support/cli_run.h's scratch_dir), and
// messages shown relative to it and to the source tree, for the scene tests' exact locations.
#pragma once

#include <fstream>
#include <string>

#include "support/cli_run.h"

namespace pathex::test {

inline const std::string& scratch() {
  static const std::string dir = scratch_dir().string();
  return dir;
}

// Writes `bytes` to scratch()/name and returns that path.
inline std::string write(const std::string& name, const std::string& bytes) {
  const std::string path = scratch() + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// `s` with the scratch folder's and the source tree's prefixes removed.
inline std::string relative(std::string s) {
  for (const std::string& prefix : {scratch() + "/", std::string(PATHEX_SOURCE_DIR) + "/"})
    for (std::size_t at; (at = s.find(prefix)) != std::string::npos;) s.erase(at, prefix.size());
  return s;
}

}  // namespace pathex::test
