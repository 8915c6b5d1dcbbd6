// Recursive-descent parser for path expressions. Precedence, loosest first:
//   alternation `|`, intersection `&`, concatenation, prefix `~`, postfix `* + ? {n} {n,} {n,m}`.
// Each level is one function. Nesting is bounded by Limits::max_depth (checked on the height of
// every node built, so `~~~~S` and `S****` count as well as parentheses) and repetition counts by
// Limits::max_repeat: a hostile expression fails with a located error, never a stack overflow.
#include "regex/parser.h"

#include <cctype>
#include <string>

namespace pathex {
namespace {

class Parser {
 public:
  Parser(std::string_view text, const Limits& limits, const NameLookup& names)
      : text_(text), limits_(limits), names_(names) {
    out_.source = std::string(text);
  }

  Result<Regex> run() {
    skip_space();
    if (at_end()) return fail(1, "empty expression, expected a letter, '.', '[', '(', '~' or '$name'");
    int root = parse_alt();
    if (failed_) return err_;
    skip_space();
    if (!at_end()) {
      if (peek() == ')') return fail(col(), "unmatched ')'");
      return fail(col(), "unexpected '" + std::string(1, peek()) + "'");
    }
    out_.root = root;
    return std::move(out_);
  }

 private:
  // --- lexing helpers ---
  bool at_end() const { return pos_ >= text_.size(); }
  char peek() const { return text_[pos_]; }
  int col() const { return static_cast<int>(pos_) + 1; }
  void skip_space() {
    while (!at_end() && std::isspace(static_cast<unsigned char>(peek()))) ++pos_;
  }

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

  int add(Node n, int column) {
    n.column = column;
    const int i = out_.add(std::move(n));
    if (out_.at(i).height > limits_.max_depth && !failed_)
      fail(column, limit_message("nesting depth", static_cast<std::size_t>(limits_.max_depth), "levels", "--max-depth"),
           ErrorCode::kLimit);
    return i;
  }

  // Starts an atom? (Used to decide whether concatenation continues.)
  bool starts_term() const {
    if (at_end()) return false;
    const char c = peek();
    return c == '(' || c == '[' || c == '.' || c == '~' || c == '$' || std::isalpha(static_cast<unsigned char>(c));
  }

  // --- grammar ---
  // alt := and ('|' and)*
  int parse_alt() {
    const int column = col();
    Node n;
    n.kind = NodeKind::kAlt;
    n.kids.push_back(parse_and());
    skip_space();
    while (!failed_ && !at_end() && peek() == '|') {
      ++pos_;
      n.kids.push_back(parse_and());
      skip_space();
    }
    if (failed_) return -1;
    return n.kids.size() == 1 ? n.kids[0] : add(std::move(n), column);
  }

  // and := cat ('&' cat)*
  int parse_and() {
    const int column = col();
    Node n;
    n.kind = NodeKind::kAnd;
    n.kids.push_back(parse_cat());
    skip_space();
    while (!failed_ && !at_end() && peek() == '&') {
      ++pos_;
      n.kids.push_back(parse_cat());
      skip_space();
    }
    if (failed_) return -1;
    return n.kids.size() == 1 ? n.kids[0] : add(std::move(n), column);
  }

  // cat := unary unary*
  int parse_cat() {
    skip_space();
    const int column = col();
    if (!starts_term()) {
      if (at_end()) fail(col(), "expected a letter, '.', '[', '(', '~' or '$name' before the end");
      else if (peek() == ')') fail(col(), "expected a letter, '.', '[', '(', '~' or '$name' before ')'");
      else if (peek() == '*' || peek() == '+' || peek() == '?' || peek() == '{')
        fail(col(), "'" + std::string(1, peek()) + "' has nothing to repeat");
      else fail(col(), "unexpected '" + std::string(1, peek()) + "', expected a letter, '.', '[', '(', '~' or '$name'");
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
      ++pos_;
      skip_space();
      if (!starts_term()) {
        if (at_end()) fail(col(), "'~' needs an operand");
        else fail(col(), "'~' needs an operand, found '" + std::string(1, peek()) + "'");
        return -1;
      }
      const int kid = parse_unary();
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
      skip_space();
      if (at_end()) break;
      const char c = peek();
      const int column = col();
      int min = 0, max = 0;
      if (c == '*') { min = 0; max = kUnbounded; ++pos_; }
      else if (c == '+') { min = 1; max = kUnbounded; ++pos_; }
      else if (c == '?') { min = 0; max = 1; ++pos_; }
      else if (c == '{') {
        if (!parse_braces(&min, &max)) return -1;
      } else break;
      Node n;
      n.kind = NodeKind::kRepeat;
      n.min = min;
      n.max = max;
      n.kids = {cur};
      cur = add(std::move(n), column);
    }
    return failed_ ? -1 : cur;
  }

  bool parse_number(int* out) {
    skip_space();
    const int column = col();
    if (at_end() || !std::isdigit(static_cast<unsigned char>(peek()))) {
      if (at_end()) fail(col(), "expected a number in '{}' before the end");
      else fail(col(), "expected a number in '{}', found '" + std::string(1, peek()) + "'");
      return false;
    }
    long long v = 0;
    while (!at_end() && std::isdigit(static_cast<unsigned char>(peek()))) {
      v = v * 10 + (peek() - '0');
      if (v > limits_.max_repeat) {
        fail(column, limit_message("repetition count", static_cast<std::size_t>(limits_.max_repeat), "repetitions", "--max-repeat"),
             ErrorCode::kLimit);
        return false;
      }
      ++pos_;
    }
    *out = static_cast<int>(v);
    return true;
  }

  bool parse_braces(int* min, int* max) {
    const int open = col();
    ++pos_;  // '{'
    if (!parse_number(min)) return false;
    skip_space();
    if (!at_end() && peek() == '}') { ++pos_; *max = *min; return true; }
    if (at_end() || peek() != ',') {
      if (at_end()) fail(open, "missing '}' to close '{'");
      else fail(col(), "expected ',' or '}' in repetition, found '" + std::string(1, peek()) + "'");
      return false;
    }
    ++pos_;  // ','
    skip_space();
    if (!at_end() && peek() == '}') { ++pos_; *max = kUnbounded; return true; }
    skip_space();
    const int max_col = col();
    if (!parse_number(max)) return false;
    skip_space();
    if (at_end() || peek() != '}') {
      if (at_end()) fail(open, "missing '}' to close '{'");
      else fail(col(), "expected '}' in repetition, found '" + std::string(1, peek()) + "'");
      return false;
    }
    ++pos_;
    if (*min > *max) {
      fail(max_col, "repetition {" + std::to_string(*min) + "," + std::to_string(*max) +
                        "}: the maximum is smaller than the minimum");
      return false;
    }
    return true;
  }

  // atom := letter | '.' | set | '(' alt ')' | '$' name
  int parse_atom() {
    skip_space();
    const int column = col();
    const char c = peek();
    Node n;
    n.kind = NodeKind::kSet;
    if (c == '.') { ++pos_; n.mask = kScatterMask; return add(std::move(n), column); }
    if (c == '[') return parse_set();
    if (c == '(') {
      ++pos_;
      skip_space();
      if (!at_end() && peek() == ')') {
        fail(col(), "empty group '()', expected an expression inside");
        return -1;
      }
      const int inner = parse_alt();
      if (failed_) return -1;
      skip_space();
      if (at_end() || peek() != ')') {
        fail(column, "missing ')' to close this '('");
        return -1;
      }
      ++pos_;
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
        else
          fail(col(), "unexpected '" + std::string(1, c) + "' in set, expected one of L E S D or ']'");
        return -1;
      }
      m |= static_cast<LetterMask>(1u << *l);
      any = true;
      ++pos_;
    }
    if (!any) { fail(col(), "empty set '[]', expected at least one of L E S D"); return -1; }
    ++pos_;  // ']'
    Node n;
    n.kind = NodeKind::kSet;
    // A negated set means the scattering letters not listed, like `.` it never matches L or E.
    n.mask = negate ? static_cast<LetterMask>(kScatterMask & ~m) : m;
    return add(std::move(n), open);
  }

  int parse_name() {
    const int column = col();
    ++pos_;  // '$'
    const std::size_t start = pos_;
    while (!at_end() && (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_' || peek() == '-')) ++pos_;
    if (pos_ == start) {
      fail(column, "'$' must be followed by a class name");
      return -1;
    }
    const std::string_view name = text_.substr(start, pos_ - start);
    const Regex* def = names_ ? names_(name) : nullptr;
    if (!def) {
      fail(column, "unknown class name '$" + std::string(name) + "'", ErrorCode::kUnknownName);
      return -1;
    }
    // Graft, then record the column of the reference on the grafted root for error reporting.
    const int root = out_.graft(*def, def->root);
    out_.nodes[static_cast<std::size_t>(root)].column = column;
    if (out_.at(root).height > limits_.max_depth) {
      fail(column, limit_message("nesting depth", static_cast<std::size_t>(limits_.max_depth), "levels", "--max-depth"),
           ErrorCode::kLimit);
      return -1;
    }
    return root;
  }

  std::string_view text_;
  const Limits& limits_;
  const NameLookup& names_;
  std::size_t pos_ = 0;
  Regex out_;
  bool failed_ = false;
  Error err_;
};

}  // namespace

Result<Regex> parse(std::string_view text, const Limits& limits, const NameLookup& names) {
  return Parser(text, limits, names).run();
}

}  // namespace pathex
