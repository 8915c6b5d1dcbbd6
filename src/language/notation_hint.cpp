#include "language/notation_hint.h"

#include "automata/ops.h"

namespace pathex {

std::optional<std::string> heckbert_hint(std::string_view text, const PathClass& cls, const ClassOptions& options,
                                         const ClassTable* names) {
  if (options.notation != Notation::kFull) return std::nullopt;
  std::string what;
  if (is_empty(cls.dfa)) {
    what = "matches no path in full notation";
  } else if (text.find_first_of(".[$~&") == std::string_view::npos) {  // written like a Heckbert string
    auto all_members_in = [&](const char* expr) {
      Result<PathClass> c = compile_class(expr, ClassOptions{});
      return c && is_subset(cls.dfa, c->dfa);
    };
    if (all_members_in("LSS.*E")) what = "matches only paths from a laser (LSS…) in full notation";
    else if (all_members_in("L.*SSE")) what = "matches only paths into a spot meter (…SSE) in full notation";
    else return std::nullopt;
  } else {
    return std::nullopt;
  }
  ClassOptions heckbert = options;
  heckbert.notation = Notation::kHeckbert;
  Result<PathClass> h = compile_class(text, heckbert, names);
  if (!h || is_empty(h->dfa)) return std::nullopt;
  return "'" + std::string(text) + "' " + what +
         ", which writes two letters for each light and sensor; for Heckbert's classic L…E add --notation heckbert";
}

}  // namespace pathex
