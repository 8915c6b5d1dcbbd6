// Check files, through `pathex check FILE` itself (reader, cases, verdicts, report). The exit
// code must be 0, 1 or 2; anything else (an escaped exception included) is a finding. Relative
// paths in the file resolve against the current folder: bench/fuzz.sh runs from the repository,
// so seeds may name samples/scenes/... and samples/classes/....
#include <exception>

#include "cli/common.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  const std::string file = fuzz::write_scratch("check.json", fuzz::as_text(data, size));
  CLI::App app{"pathex"};
  cli::Command check = cli::add_check(app);
  const Limits l = fuzz::small_limits();
  std::vector<std::string> args = {"check", file,
                                   "--max-states", std::to_string(l.max_states),
                                   "--max-repeat", std::to_string(l.max_repeat),
                                   "--max-length", std::to_string(l.max_length),
                                   "--max-work", std::to_string(l.max_work),
                                   "--max-file-size", std::to_string(l.max_file_bytes)};
  std::reverse(args.begin(), args.end());  // CLI11 parses a reversed vector
  app.parse(args);
  const int code = check.run();
  if (code < 0 || code > 2) fuzz::finding("an exit code other than 0, 1 or 2");
  return 0;
}
