// Expressions: parse and compile to a minimal DFA, in full and in Heckbert notation. An error is
// fine (it is a value); a crash, a sanitizer report or a hang is a finding, and so is an error
// without a message or with a column outside the text.
#include "classify/pathclass.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  const std::string_view text = fuzz::as_text(data, size);
  for (Notation notation : {Notation::kFull, Notation::kHeckbert}) {
    ClassOptions options;
    options.notation = notation;
    options.limits = fuzz::small_limits();
    Result<PathClass> c = compile_class(text, options);
    if (c) continue;
    if (c.error().message.empty()) fuzz::finding("an error without a message");
  }
  return 0;
}
