// Class files: the JSON document and every expression in it, compiled in order.
#include "fuzz_support.h"
#include "io/class_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  ClassTable table;
  ClassOptions options;
  options.limits = fuzz::small_limits();
  Result<bool> r = load_class_file(std::string(fuzz::as_text(data, size)), "fuzz.json", options, &table);
  if (!r && r.error().message.empty()) fuzz::finding("an error without a message");
  return 0;
}
