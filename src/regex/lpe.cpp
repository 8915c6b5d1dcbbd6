// LPE parser: text -> eye-first full-notation Regex (the meaning is in lpe.h). Recursive descent
// over OSL's grammar; each primary denotes a set of events, which is translated on the spot into
// the full-path letters those events stand for. Nesting is bounded by Limits::max_depth (open
// '(' and '[' on the way down, node heights on the way up) and repetition counts by
// Limits::max_repeat, as in the full parser.
#include "regex/lpe.h"

#include <cctype>
#include <cstdint>
#include <set>
#include <string>

#include "regex/parse_cursor.h"

namespace pathex {
namespace {

// Event types and scattering types as bits. An event set is (types, scatters): the events whose
// type is in `types` and whose scattering label is in `scatters`. Camera, light, emissive-object
// and background events carry the label "none".
constexpr std::uint8_t kTC = 1, kTR = 2, kTT = 4, kTV = 8, kTL = 16, kTO = 32, kTB = 64, kAllTypes = 127;
constexpr std::uint8_t kSD = 1, kSG = 2, kSS = 4, kSStraight = 8, kSNone = 16, kAllScatters = 31;

std::uint8_t type_bit(char c) {
  switch (c) {
    case 'C': return kTC;
    case 'R': return kTR;
    case 'T': return kTT;
    case 'V': return kTV;
    case 'L': return kTL;
    case 'O': return kTO;
    case 'B': return kTB;
    default: return 0;
  }
}

std::uint8_t scatter_bit(char c) {
  switch (c) {
    case 'D': return kSD;
    case 'G': return kSG;
    case 'S': return kSS;
    case 's': return kSStraight;
    default: return 0;
  }
}

constexpr const char* kEvents = "an event (C R T L O, D G S, '.', '<', '[' or '(')";

class LpeParser : detail::ParseCursor {
 public:
  LpeParser(std::string_view text, const std::vector<LightType>& lights, const std::vector<SensorType>& sensors,
            const Limits& limits)
      : ParseCursor(text, limits), lights_(lights), sensors_(sensors) {}

  Result<Regex> run() {
    skip_space();
    if (at_end()) return fail(1, std::string("empty light path expression, expected ") + kEvents);
    const int root = parse_seq('\0', 0);
    if (failed_) return err_;
    out_.root = root;
    return std::move(out_);
  }

 private:
  int set_node(LetterMask m, int column) {
    Node n;
    n.kind = NodeKind::kSet;
    n.mask = m;
    return add(std::move(n), column);
  }
  int join(NodeKind kind, std::vector<int> kids, int column) {
    if (kids.size() == 1) return kids[0];
    Node n;
    n.kind = kind;
    n.kids = std::move(kids);
    return add(std::move(n), column);
  }

  // --- translation of an event set into full-path letters (eye-first) ---

  // Two-letter words w (c_i c_j) as a tree: X·Y when they form a product of letter sets, else
  // their alternation.
  int pairs_node(const std::set<std::string>& words, int column) {
    if (words.empty()) return set_node(0, column);
    LetterMask first = 0, second = 0;
    for (const std::string& w : words) {
      first |= static_cast<LetterMask>(1u << *letter_from_char(w[0]));
      second |= static_cast<LetterMask>(1u << *letter_from_char(w[1]));
    }
    if (static_cast<std::size_t>(__builtin_popcount(first) * __builtin_popcount(second)) == words.size())
      return join(NodeKind::kConcat, {set_node(first, column), set_node(second, column)}, column);
    std::vector<int> alts;
    for (const std::string& w : words)
      alts.push_back(join(NodeKind::kConcat, {set_node(static_cast<LetterMask>(1u << *letter_from_char(w[0])), column),
                                              set_node(static_cast<LetterMask>(1u << *letter_from_char(w[1])), column)},
                          column));
    return join(NodeKind::kAlt, std::move(alts), column);
  }

  // E c(k+2) c(k+1): the camera event read eye-first.
  int camera_node(int column) {
    std::set<std::string> words;
    for (SensorType t : sensors_) {
      const std::string s = sensor_letters(t);
      words.insert(std::string{s[1], s[0]});
    }
    return join(NodeKind::kConcat, {set_node(1u << kE, column), pairs_node(words, column)}, column);
  }

  // c1 c0 L: the emission event read eye-first, for all light types or area lights only.
  int light_node(bool area_only, int column) {
    std::set<std::string> words;
    for (LightType t : lights_) {
      if (area_only && t != LightType::kArea) continue;
      const std::string s = light_letters(t);
      words.insert(std::string{s[1], s[0]});
    }
    if (words.empty()) return set_node(0, column);
    return join(NodeKind::kConcat, {pairs_node(words, column), set_node(1u << kL, column)}, column);
  }

  int event_node(std::uint8_t types, std::uint8_t scatters, int column) {
    std::vector<int> alts;
    LetterMask interior = 0;
    if (types & (kTR | kTT)) {
      if (scatters & (kSD | kSG)) interior |= 1u << kD;
      if (scatters & kSS) interior |= 1u << kS;
    }
    if (interior) alts.push_back(set_node(interior, column));
    if (scatters & kSNone) {
      if (types & kTC) alts.push_back(camera_node(column));
      if (types & kTL) alts.push_back(light_node(/*area_only=*/false, column));
      else if (types & kTO) alts.push_back(light_node(/*area_only=*/true, column));
    }
    if (alts.empty()) return set_node(0, column);  // no event pathex has: the empty language
    return join(NodeKind::kAlt, std::move(alts), column);
  }

  // --- symbols ---

  // A positively written event type or scattering type that pathex has no counterpart for.
  bool refuse_unsupported(char c, int column) {
    if (c == 'V') {
      fail(column, "V (volume scattering) is not supported: pathex paths have no volume events");
      return true;
    }
    if (c == 'B') {
      fail(column, "B (background) is not supported: an infinite light is one of the lights (letters LDD, as an area light); L is every light");
      return true;
    }
    if (c == 's') {
      fail(column, "s (straight, pass-through) is not supported: every pathex vertex scatters");
      return true;
    }
    return false;
  }

  void refuse_label(int column) {
    fail(column, "custom labels ('…') are not supported: pathex paths carry no object or light names");
  }

  void unknown_symbol(char c, int column, const char* expected) {
    if (c == 'A')
      fail(column, "A (albedo) is not supported: it is not a light path");
    else if (c == '$')
      fail(column, "names ($…) are not part of LPE syntax; combine LPE classes in a class file instead");
    else if (c == 'E')
      fail(column, "unknown event 'E': LPEs write the camera as C (camera first, then the light)");
    else
      fail(column, "unknown event " + found() + ", expected " + expected);
  }

  // --- grammar ---

  // seq := item*, up to `close` (')' or the end). Handles '|' the way OSL does: it joins the
  // last item with the next one.
  int parse_seq(char close, int open_column) {
    const int column = col();
    // Each item with the alternatives '|' joined to it, and the column of its first '|'.
    std::vector<std::vector<int>> items;
    std::vector<int> bar_columns;
    while (!failed_) {
      skip_space();
      if (at_end()) {
        if (close) fail(open_column, "missing ')' to close this '('");
        break;
      }
      const char c = peek();
      if (c == close) break;
      if (c == '|') {
        const int bar = col();
        if (items.empty()) {
          fail(bar, "'|' has nothing before it: in an LPE, '|' joins the item before it with the one after it");
          break;
        }
        ++pos_;
        skip_space();
        if (at_end() || peek() == close || peek() == '|') {
          fail(col(), std::string("expected ") + kEvents + " after '|', found " + found());
          break;
        }
        const int rhs = parse_item();
        if (failed_) break;
        if (items.back().size() == 1) bar_columns.back() = bar;
        items.back().push_back(rhs);
        continue;
      }
      items.push_back({parse_item()});
      bar_columns.push_back(0);
    }
    if (failed_) return -1;
    if (items.empty()) {
      fail(col(), "empty group '()', expected an event inside");
      return -1;
    }
    std::vector<int> seq;
    for (std::size_t i = 0; i < items.size(); ++i) seq.push_back(join(NodeKind::kAlt, std::move(items[i]), bar_columns[i]));
    return join(NodeKind::kConcat, std::move(seq), column);
  }

  // item := primary repeat?
  int parse_item() {
    int cur = parse_primary();
    if (failed_) return -1;
    const int rep = parse_repetition(cur);
    if (rep < 0 || rep == cur) return rep;
    cur = rep;
    skip_space();
    if (!failed_ && !at_end() && (peek() == '*' || peek() == '+' || peek() == '?' || peek() == '{'))
      fail(col(), "'" + std::string(1, peek()) + "' after a repetition: an LPE item takes one; group it first, as in (D*)+");
    return failed_ ? -1 : cur;
  }

  // primary := symbol | '.' | '<' tuple '>' | '(' seq ')' | '[' item+ ']' | '[^' symbol+ ']'
  int parse_primary() {
    skip_space();
    const int column = col();
    const char c = peek();
    if (c == '(') {
      if (!descend(column)) return -1;
      ++pos_;
      const int inner = parse_seq(')', column);
      if (failed_) return -1;
      ++pos_;  // ')'
      --nesting_;
      return inner;
    }
    if (c == '[') {
      if (pos_ + 1 < text_.size() && text_[pos_ + 1] == '^') {
        std::uint8_t types = 0, scatters = 0;
        if (!parse_negated(&types, &scatters, /*category=*/0)) return -1;
        return event_node(types, scatters, column);
      }
      return parse_alternatives();
    }
    if (c == '<') return parse_tuple();
    if (c == '.') {
      ++pos_;
      return event_node(kAllTypes, kAllScatters, column);
    }
    if (c == '\'') {
      refuse_label(column);
      return -1;
    }
    if (c == '*' || c == '+' || c == '?' || c == '{') {
      fail(column, "'" + std::string(1, c) + "' has nothing to repeat");
      return -1;
    }
    if (c == ')' || c == ']' || c == '>' || c == '}') {
      fail(column, "unmatched '" + std::string(1, c) + "'");
      return -1;
    }
    if (refuse_unsupported(c, column)) return -1;
    if (const std::uint8_t t = type_bit(c)) {
      ++pos_;
      return event_node(t, kAllScatters, column);
    }
    if (const std::uint8_t s = scatter_bit(c)) {
      ++pos_;
      return event_node(kAllTypes, s, column);
    }
    unknown_symbol(c, column, kEvents);
    return -1;
  }

  // '[' item+ ']': the alternation of its items (each may be a tuple, a group, a repetition).
  int parse_alternatives() {
    const int open = col();
    if (!descend(open)) return -1;
    ++pos_;  // '['
    std::vector<int> alts;
    while (!failed_) {
      skip_space();
      if (at_end()) {
        fail(open, "missing ']' to close this '['");
        return -1;
      }
      if (peek() == ']') break;
      if (peek() == '|') {
        fail(col(), "'|' inside '[…]': the items of a set are alternatives already");
        return -1;
      }
      alts.push_back(parse_item());
    }
    if (failed_) return -1;
    if (alts.empty()) {
      fail(col(), std::string("empty set '[]', expected ") + kEvents + " inside");
      return -1;
    }
    ++pos_;  // ']'
    --nesting_;
    return join(NodeKind::kAlt, std::move(alts), open);
  }

  // '[^' symbol+ ']'. `category` 1 = event types only, 2 = scattering types only, 0 = either
  // (decided by the first symbol; mixing is refused). At the top level the complement is taken in
  // the category of the symbols listed, the other component being any.
  bool parse_negated(std::uint8_t* types, std::uint8_t* scatters, int category) {
    const int open = col();
    pos_ += 2;  // "[^"
    std::uint8_t listed_types = 0, listed_scatters = 0;
    while (true) {
      skip_space();
      if (at_end()) {
        fail(open, "missing ']' to close this '['");
        return false;
      }
      const char c = peek();
      if (c == ']') break;
      const int column = col();
      if (c == '\'') {
        refuse_label(column);
        return false;
      }
      const std::uint8_t t = type_bit(c), s = scatter_bit(c);
      if (!t && !s) {
        unknown_symbol(c, column, category == 1   ? "an event type (C R T V L O B) or ']'"
                                  : category == 2 ? "a scattering type (D G S) or ']'"
                                                  : "an event type (C R T V L O B), a scattering type (D G S) or ']'");
        return false;
      }
      const int cat = t ? 1 : 2;
      if (category == 0) category = cat;
      if (cat != category) {
        fail(column, category == 1 ? "'[^…]' lists event types (C R T V L O B); a scattering type cannot join them"
                                   : "'[^…]' lists scattering types (D G S); an event type cannot join them");
        return false;
      }
      listed_types |= t;
      listed_scatters |= s;
      ++pos_;
    }
    if (!listed_types && !listed_scatters) {
      fail(col(), "empty set '[^]', expected at least one event or scattering type");
      return false;
    }
    ++pos_;  // ']'
    if (category == 1) {
      *types = static_cast<std::uint8_t>(kAllTypes & ~listed_types);
      *scatters = kAllScatters;
    } else {
      *types = kAllTypes;
      // "none" is never listed, so camera and light events stay in a negated scattering set.
      *scatters = static_cast<std::uint8_t>(kAllScatters & ~listed_scatters);
    }
    return true;
  }

  // One component of a tuple: its event types (category 1) or scattering types (category 2).
  bool parse_component(int category, std::uint8_t* bits) {
    skip_space();
    const int column = col();
    const char* expected = category == 1 ? "an event type (C R T L O), '.', '[' or '>'"
                                         : "a scattering type (D G S), '.', '[' or '>'";
    if (at_end()) return true;  // reported by the caller as an unclosed '<'
    const char c = peek();
    auto symbol_bits = [&](char s) -> std::uint8_t { return category == 1 ? type_bit(s) : scatter_bit(s); };
    if (c == '.') {
      ++pos_;
      *bits = category == 1 ? kAllTypes : kAllScatters;
      return true;
    }
    if (c == '\'') {
      refuse_label(column);
      return false;
    }
    if (c == '<') {
      fail(column, "'<' inside '<…>': event tuples do not nest");
      return false;
    }
    if (c == '[' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '^') {
      std::uint8_t t = 0, s = 0;
      if (!parse_negated(&t, &s, category)) return false;
      *bits = category == 1 ? t : s;
      return true;
    }
    if (c == '[') {
      const int open = col();
      ++pos_;
      std::uint8_t m = 0;
      while (true) {
        skip_space();
        if (at_end()) {
          fail(open, "missing ']' to close this '['");
          return false;
        }
        const char d = peek();
        if (d == ']') break;
        if (d == '\'') {
          refuse_label(col());
          return false;
        }
        if (refuse_unsupported(d, col())) return false;
        const std::uint8_t b = symbol_bits(d);
        if (!b) {
          unknown_symbol(d, col(), category == 1 ? "an event type (C R T L O) or ']'" : "a scattering type (D G S) or ']'");
          return false;
        }
        m |= b;
        ++pos_;
      }
      if (!m) {
        fail(col(), "empty set '[]' in '<…>'");
        return false;
      }
      ++pos_;
      *bits = m;
      return true;
    }
    if (c == '*' || c == '+' || c == '?' || c == '{') {
      fail(column, "repetitions are not allowed inside '<…>'");
      return false;
    }
    if (refuse_unsupported(c, column)) return false;
    const std::uint8_t b = symbol_bits(c);
    if (!b) {
      if (category == 1 && scatter_bit(c))
        fail(column, "'" + std::string(1, c) + "' is a scattering type; '<…>' starts with the event type, as in <R" +
                         std::string(1, c) + ">");
      else if (category == 2 && type_bit(c))
        fail(column, "'" + std::string(1, c) + "' is an event type; the second place of '<…>' is the scattering type");
      else
        unknown_symbol(c, column, expected);
      return false;
    }
    ++pos_;
    *bits = b;
    return true;
  }

  // '<' type scattering? '>'
  int parse_tuple() {
    const int open = col();
    ++pos_;  // '<'
    std::uint8_t types = kAllTypes, scatters = kAllScatters;
    skip_space();
    if (!at_end() && peek() != '>') {
      if (!parse_component(1, &types)) return -1;
      skip_space();
      if (!at_end() && peek() != '>') {
        if (!parse_component(2, &scatters)) return -1;
        skip_space();
        if (!at_end() && (peek() == '\'' || peek() == '[')) {  // a third component: custom labels
          refuse_label(col());
          return -1;
        }
        if (!at_end() && peek() != '>') {
          fail(col(), "expected '>' after the event and scattering types, found " + found());
          return -1;
        }
      }
    }
    if (at_end()) {
      fail(open, "missing '>' to close this '<'");
      return -1;
    }
    ++pos_;  // '>'
    return event_node(types, scatters, open);
  }

  const std::vector<LightType>& lights_;
  const std::vector<SensorType>& sensors_;
};

}  // namespace

Result<Regex> parse_lpe(std::string_view text, const std::vector<LightType>& lights,
                        const std::vector<SensorType>& sensors, const Limits& limits) {
  return LpeParser(text, lights, sensors, limits).run();
}

}  // namespace pathex
