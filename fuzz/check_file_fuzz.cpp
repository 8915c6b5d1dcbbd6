// Check files, through the library's reader and decider (check/check_file.h), what `pathex check
// FILE` runs before it prints: every outcome is a value (cases, outcomes or a located error);
// anything escaping is a finding. Relative paths in the file resolve against the current folder:
// bench/fuzz.sh runs from the repository, so seeds may name samples/scenes/... and samples/classes/....
#include "check/check_file.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  const std::string file = fuzz::write_scratch("check.json", fuzz::as_text(data, size));
  const Limits limits = fuzz::small_limits();
  Result<std::vector<Case>> cases = parse_check(std::string(fuzz::as_text(data, size)), file);
  if (!cases) {
    if (cases.error().render().empty()) fuzz::finding("an error without a message");
    return 0;
  }
  Result<std::vector<Outcome>> outcomes = decide_check(file, *cases, limits);
  if (outcomes) {
    std::size_t requirements = 0;
    for (const Case& c : *cases) requirements += c.require.size();
    if (outcomes->size() != requirements) fuzz::finding("not one outcome per requirement");
  }
  return 0;
}
