#include "regex/repeat.h"

#include <cctype>

#include "regex/ast.h"

namespace pathex {

Result<RepeatCounts> read_repeat(std::string_view text, std::size_t* pos, const Limits& limits,
                                 const std::function<std::string(std::size_t)>& found) {
  std::size_t p = *pos;
  const int open = static_cast<int>(p) + 1;
  auto at_end = [&] { return p >= text.size(); };
  auto is_digit = [&] { return !at_end() && std::isdigit(static_cast<unsigned char>(text[p])); };
  auto skip_space = [&] {
    while (!at_end() && std::isspace(static_cast<unsigned char>(text[p]))) ++p;
  };
  auto error = [&](int column, std::string message, ErrorCode code = ErrorCode::kSyntax) {
    Error e = make_error(code, std::move(message));
    e.column = column;
    return e;
  };
  auto unclosed = [&] { return error(open, "missing '}' to close this '{'"); };
  // A number at the cursor, failing as soon as it exceeds max_repeat.
  auto number = [&](int* out) -> std::optional<Error> {
    const int column = static_cast<int>(p) + 1;
    long long v = 0;
    while (is_digit()) {
      v = v * 10 + (text[p] - '0');
      if (v > limits.max_repeat)
        return error(column, limit_message("repetition count", static_cast<std::size_t>(limits.max_repeat), "repetitions",
                                           "--max-repeat"),
                     ErrorCode::kLimit);
      ++p;
    }
    *out = static_cast<int>(v);
    return std::nullopt;
  };

  RepeatCounts c;
  ++p;  // '{'
  skip_space();
  if (at_end()) return unclosed();
  if (!is_digit()) return error(static_cast<int>(p) + 1, "expected a number after '{', found " + found(p));
  if (auto e = number(&c.min)) return *e;
  skip_space();
  if (at_end()) return unclosed();
  if (text[p] == '}') {
    c.max = c.min;
  } else {
    if (text[p] != ',') return error(static_cast<int>(p) + 1, "expected ',' or '}' in repetition, found " + found(p));
    ++p;  // ','
    skip_space();
    if (at_end()) return unclosed();
    if (text[p] == '}') {
      c.max = kUnbounded;
    } else {
      if (!is_digit()) return error(static_cast<int>(p) + 1, "expected a number or '}' after ',', found " + found(p));
      const int max_col = static_cast<int>(p) + 1;
      if (auto e = number(&c.max)) return *e;
      skip_space();
      if (at_end()) return unclosed();
      if (text[p] != '}') return error(static_cast<int>(p) + 1, "expected '}' in repetition, found " + found(p));
      if (c.min > c.max)
        return error(max_col, "repetition {" + std::to_string(c.min) + "," + std::to_string(c.max) +
                                  "}: the maximum is smaller than the minimum");
    }
  }
  *pos = p + 1;  // past '}'
  return c;
}

}  // namespace pathex
