// Repetition counts `{n}`, `{n,}` and `{n,m}`: one reader for both expression parsers (full-path
// expressions, regex/parser.h, and light path expressions, regex/lpe.h), so that their counts,
// limits and messages cannot drift apart. Whitespace inside the braces is skipped.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"

namespace pathex {

struct RepeatCounts {
  int min = 0;
  int max = 0;  // kUnbounded (regex/ast.h) for {n,}
};

// `*pos` is on '{'. On success, `*pos` is just past '}'. Errors carry the 1-based column (the
// '{' itself when the text ends inside the braces) and say what was found there, written by
// `found(position)` ("'x'", "the end", …) as the calling parser writes it; counts above
// limits.max_repeat are kLimit errors naming --max-repeat. The error's source is left empty.
Result<RepeatCounts> read_repeat(std::string_view text, std::size_t* pos, const Limits& limits,
                                 const std::function<std::string(std::size_t)>& found);

}  // namespace pathex
