// Recursive-descent parser for path expressions (grammar/pathex.ebnf). Precedence, loosest first:
//   alternation `|`, intersection `&`, concatenation, prefix `~`, postfix `* + ? {n} {n,} {n,m}`.
// Each level is one function. Nesting is bounded by Limits::max_depth twice over: on the way
// down, every open '(' and pending '~' counts one level, so the recursion itself is bounded (a
// hostile `((((…` or `~~~~…` fails with a located error instead of overflowing the stack); on the
// way up, the height of every node built is checked, so `S****` counts as well. Repetition counts
// are bounded by Limits::max_repeat.
//
// Error messages say what was found and what was expected; the column is that of the offending
// character, or of the opening bracket for an unclosed '(', '[' or '{', or one past the end when
// the text stops too early. grammar/corpus/invalid.json pins every message and column.
#include "regex/parser.h"

#include <cctype>
#include <string>

#include "regex/parse_cursor.h"

namespace pathex {
namespace {

constexpr const char* kOperand = "a letter, '.', '[', '(', '~' or '$name'";

bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }

class Parser : detail::ParseCursor {
 public:
  Parser(std::string_view text, const Limits& limits, const NameLookup& names)
      : ParseCursor(text, limits), names_(names) {}

  Result<Regex> run() {
    skip_space();
    if (at_end()) return fail(1, std::string("empty expression, expected ") + kOperand);
    const int root = parse_alt();
    if (failed_) return err_;
    skip_space();
    if (!at_end()) {
      unexpected_after_operand();
      return err_;
    }
    out_.root = root;
    return std::move(out_);
  }

 private:
  // Starts an atom? (Used to decide whether concatenation continues.) Any letter does, so that
  // lowercase and unknown letters get their own message from parse_atom.
  bool starts_term() const {
    if (at_end()) return false;
    const char c = peek();
    return c == '(' || c == '[' || c == '.' || c == '~' || c == '$' || std::isalpha(static_cast<unsigned char>(c));
  }

  // A complete operand was parsed and the next character can neither continue nor end it.
  void unexpected_after_operand() {
    const char c = peek();
    if (c == ')' && open_groups_ == 0) {
      fail(col(), "unmatched ')'");
    } else if (c == ']' || c == '}') {
      fail(col(), std::string("unmatched '") + c + "'");
    } else {
      fail(col(), "unexpected " + found() + ", expected an operand (L E S D . [ ( ~ $name), an operator (| & * + ? {) or " +
                      (open_groups_ > 0 ? "')'" : "the end"));
    }
  }

  // --- grammar ---
  // alt := and ('|' and)*
  int parse_alt() {
    skip_space();
    const int column = col();
    Node n;
    n.kind = NodeKind::kAlt;
    n.kids.push_back(parse_and(""));
    skip_space();
    while (!failed_ && !at_end() && peek() == '|') {
      ++pos_;
      n.kids.push_back(parse_and("'|'"));
      skip_space();
    }
    if (failed_) return -1;
    return n.kids.size() == 1 ? n.kids[0] : add(std::move(n), column);
  }

  // and := cat ('&' cat)*. `after` names the operator before it, for messages ("" at the start).
  int parse_and(const char* after) {
    skip_space();
    const int column = col();
    Node n;
    n.kind = NodeKind::kAnd;
    n.kids.push_back(parse_cat(after));
    skip_space();
    while (!failed_ && !at_end() && peek() == '&') {
      ++pos_;
      n.kids.push_back(parse_cat("'&'"));
      skip_space();
    }
    if (failed_) return -1;
    return n.kids.size() == 1 ? n.kids[0] : add(std::move(n), column);
  }

  // cat := unary unary*
  int parse_cat(const char* after) {
    skip_space();
    const int column = col();
    if (!starts_term()) {
      const char c = at_end() ? '\0' : peek();
      if (c == '*' || c == '+' || c == '?' || c == '{') {
        fail(col(), "'" + std::string(1, c) + "' has nothing to repeat");
      } else if (c == ')' && open_groups_ == 0) {
        fail(col(), "unmatched ')'");
      } else {
        fail(col(), std::string("expected ") + kOperand + (*after ? std::string(" after ") + after : std::string()) +
                        ", found " + found());
      }
      return -1;
    }
    Node n;
    n.kind = NodeKind::kConcat;
    while (!failed_) {
      n.kids.push_back(parse_unary());
      skip_space();
      if (!starts_term()) break;
    }
    if (failed_) return -1;
    return n.kids.size() == 1 ? n.kids[0] : add(std::move(n), column);
  }

  // unary := '~' unary | postfix
  int parse_unary() {
    skip_space();
    if (!at_end() && peek() == '~') {
      const int column = col();
      if (!descend(column)) return -1;
      ++pos_;
      skip_space();
      if (!starts_term()) {
        fail(col(), "'~' needs an operand, found " + found());
        return -1;
      }
      const int kid = parse_unary();
      --nesting_;
      if (failed_) return -1;
      Node n;
      n.kind = NodeKind::kNot;
      n.kids = {kid};
      return add(std::move(n), column);
    }
    return parse_postfix();
  }

  // postfix := atom ('*' | '+' | '?' | '{' n '}' | '{' n ',' '}' | '{' n ',' m '}')*
  int parse_postfix() {
    int cur = parse_atom();
    while (!failed_) {
      const int rep = parse_repetition(cur);
      if (rep < 0) return -1;
      if (rep == cur) break;
      cur = rep;
    }
    return failed_ ? -1 : cur;
  }

  // atom := letter | '.' | set | '(' alt ')' | '$' name. The cursor is on a character for which
  // starts_term() holds.
  int parse_atom() {
    skip_space();
    const int column = col();
    const char c = peek();
    Node n;
    n.kind = NodeKind::kSet;
    if (c == '.') { ++pos_; n.mask = kScatterMask; return add(std::move(n), column); }
    if (c == '[') return parse_set();
    if (c == '(') {
      if (!descend(column)) return -1;
      ++pos_;
      skip_space();
      if (!at_end() && peek() == ')') {
        fail(col(), "empty group '()', expected an expression inside");
        return -1;
      }
      ++open_groups_;
      const int inner = parse_alt();
      if (failed_) return -1;
      skip_space();
      if (at_end()) {
        fail(column, "missing ')' to close this '('");
        return -1;
      }
      if (peek() != ')') {
        // Something inside the group that cannot continue it: point at that, not at the '('.
        unexpected_after_operand();
        return -1;
      }
      ++pos_;
      --open_groups_;
      --nesting_;
      return inner;
    }
    if (c == '$') return parse_name();
    if (auto l = letter_from_char(c)) {
      ++pos_;
      n.mask = static_cast<LetterMask>(1u << *l);
      return add(std::move(n), column);
    }
    if (std::islower(static_cast<unsigned char>(c))) {
      fail(column, "lowercase letter '" + std::string(1, c) + "': letters are uppercase L E S D");
    } else {
      fail(column, "unknown letter '" + std::string(1, c) + "', expected one of L E S D");
    }
    return -1;
  }

  // set := '[' '^'? letter+ ']' with whitespace allowed between the letters; "[^" is one token.
  int parse_set() {
    const int open = col();
    ++pos_;  // '['
    bool negate = false;
    if (!at_end() && peek() == '^') { negate = true; ++pos_; }
    LetterMask m = 0;
    bool any = false;
    while (true) {
      skip_space();
      if (at_end()) { fail(open, "missing ']' to close this '['"); return -1; }
      const char c = peek();
      if (c == ']') break;
      auto l = letter_from_char(c);
      if (!l) {
        if (std::islower(static_cast<unsigned char>(c)))
          fail(col(), "lowercase letter '" + std::string(1, c) + "' in set: letters are uppercase L E S D");
        else if (c == '^')
          fail(col(), "'^' negates a set only right after '[', as in [^S]");
        else if (std::isalpha(static_cast<unsigned char>(c)))
          fail(col(), "unknown letter '" + std::string(1, c) + "' in set, expected one of L E S D or ']'");
        else
          fail(col(), "unexpected " + found() + " in set, expected one of L E S D or ']'");
        return -1;
      }
      m |= static_cast<LetterMask>(1u << *l);
      any = true;
      ++pos_;
    }
    if (!any) {
      fail(col(), std::string("empty set '") + (negate ? "[^]" : "[]") + "', expected at least one of L E S D");
      return -1;
    }
    ++pos_;  // ']'
    Node n;
    n.kind = NodeKind::kSet;
    // A negated set means the scattering letters not listed, like `.` it never matches L or E.
    n.mask = negate ? static_cast<LetterMask>(kScatterMask & ~m) : m;
    return add(std::move(n), open);
  }

  // name-ref := '$' name, name := [A-Za-z_][A-Za-z0-9_-]*. Resolved here and grafted in.
  int parse_name() {
    const int column = col();
    ++pos_;  // '$'
    if (at_end() || !is_name_start(peek())) {
      fail(col(), "expected a class name after '$' (a letter or '_', then letters, digits, '_' or '-'), found " +
                      found());
      return -1;
    }
    const std::size_t start = pos_;
    while (!at_end() && is_name_char(peek())) ++pos_;
    const std::string_view name = text_.substr(start, pos_ - start);
    const Regex* def = names_ ? names_(name) : nullptr;
    if (!def) {
      fail(column,
           "unknown class name '$" + std::string(name) + "', expected a built-in name or one defined earlier in the class file",
           ErrorCode::kUnknownName);
      return -1;
    }
    // Graft, then record the column of the reference on the grafted root for error reporting.
    const int root = out_.graft(*def, def->root);
    out_.nodes[static_cast<std::size_t>(root)].column = column;
    if (out_.at(root).height > limits_.max_depth) {
      fail_depth(column);
      return -1;
    }
    return root;
  }

  const NameLookup& names_;
  int open_groups_ = 0;  // open '(' only: decides between "unmatched ')'" and "expected ')'"
};

}  // namespace

Result<Regex> parse(std::string_view text, const Limits& limits, const NameLookup& names) {
  return Parser(text, limits, names).run();
}

}  // namespace pathex
