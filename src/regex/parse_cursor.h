// The cursor, error slot and node builder both expression parsers share (full-path expressions,
// regex/parser.cpp, and light path expressions, regex/lpe.cpp), so that their columns, "found"
// wording, depth limit and repetition counts cannot drift apart. A parser derives from it and
// adds its grammar.
#pragma once

#include <cctype>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "core/limits.h"
#include "regex/ast.h"
#include "regex/repeat.h"

namespace pathex::detail {

class ParseCursor {
 protected:
  ParseCursor(std::string_view text, const Limits& limits) : text_(text), limits_(limits) {
    out_.source = std::string(text);
  }

  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return text_[pos_]; }
  int col() const { return static_cast<int>(pos_) + 1; }
  void skip_space() {
    while (!at_end() && std::isspace(static_cast<unsigned char>(peek()))) ++pos_;
  }

  // The character at the cursor as messages show it: 'x'; a whole UTF-8 sequence such as 'Ψ'
  // rather than its first byte; "byte 0x01" for a control or stray byte; "the end".
  std::string found() const { return at_end() ? "the end" : describe_char_at(text_, pos_); }

  // Records the first error only: later failures while unwinding keep the first one's column.
  Error fail(int column, std::string message, ErrorCode code = ErrorCode::kSyntax) {
    if (!failed_) {
      failed_ = true;
      err_.code = code;
      err_.column = column;
      err_.message = std::move(message);
      err_.source = std::string(text_);
    }
    return err_;
  }

  void fail_depth(int column) {
    fail(column, limit_message("nesting depth", static_cast<std::size_t>(limits_.max_depth), "levels", "--max-depth"),
         ErrorCode::kLimit);
  }

  // Appends a node; its height is checked against the depth limit on the way up.
  int add(Node n, int column) {
    n.column = column;
    const int i = out_.add(std::move(n));
    if (out_.at(i).height > limits_.max_depth) fail_depth(column);
    return i;
  }

  // Entering a group (or a pending prefix operator) at `column`: one more level of recursion, so
  // the recursion itself is bounded by the depth limit on the way down.
  bool descend(int column) {
    if (++nesting_ >= limits_.max_depth) {
      fail_depth(column);
      return false;
    }
    return true;
  }

  // A repetition operator at the cursor, `*` `+` `?` or braces, applied to node `operand`: the
  // new node's index; `operand` itself when there is none (the cursor stays); -1 on an error.
  int parse_repetition(int operand) {
    skip_space();
    if (at_end()) return operand;
    const int column = col();
    int min = 0, max = 0;
    switch (peek()) {
      case '*': min = 0; max = kUnbounded; ++pos_; break;
      case '+': min = 1; max = kUnbounded; ++pos_; break;
      case '?': min = 0; max = 1; ++pos_; break;
      case '{':
        if (!parse_braces(&min, &max)) return -1;
        break;
      default: return operand;
    }
    Node n;
    n.kind = NodeKind::kRepeat;
    n.min = min;
    n.max = max;
    n.kids = {operand};
    return add(std::move(n), column);
  }

  // '{' n '}' | '{' n ',' '}' | '{' n ',' m '}' (regex/repeat.h).
  bool parse_braces(int* min, int* max) {
    Result<RepeatCounts> c = read_repeat(text_, &pos_, limits_, [this](std::size_t at) {
      const std::size_t here = pos_;
      pos_ = at;
      std::string f = found();
      pos_ = here;
      return f;
    });
    if (!c) {
      fail(c.error().column, c.error().message, c.error().code);
      return false;
    }
    *min = c->min;
    *max = c->max;
    return true;
  }

  std::string_view text_;
  const Limits& limits_;
  std::size_t pos_ = 0;
  int nesting_ = 0;  // open groups and pending prefix operators on the recursion stack
  Regex out_;
  bool failed_ = false;
  Error err_;
};

}  // namespace pathex::detail
