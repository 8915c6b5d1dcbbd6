#include "regex/ast.h"

#include <algorithm>

namespace pathex {

int Regex::add(Node n) {
  int h = 0;
  for (int k : n.kids) h = std::max(h, at(k).height);
  n.height = h + 1;
  nodes.push_back(std::move(n));
  return static_cast<int>(nodes.size()) - 1;
}

int Regex::graft(const Regex& other, int other_root) {
  const Node& src = other.at(other_root);
  Node copy = src;
  copy.kids.clear();
  for (int k : src.kids) copy.kids.push_back(graft(other, k));
  return add(std::move(copy));
}

namespace {

std::string set_text(LetterMask m, bool dump_style) {
  for (int l = 0; l < kNumLetters; ++l)
    if (m == (1u << l)) return std::string(1, letter_char(l));
  if (m == kScatterMask && !dump_style) return ".";
  if (m == 0) return dump_style ? "[]" : "[^DS]";
  std::string s = "[";
  for (int l = 0; l < kNumLetters; ++l)
    if (m & (1u << l)) s += letter_char(l);
  return s + "]";
}

std::string repeat_suffix(int min, int max) {
  if (min == 0 && max == kUnbounded) return "*";
  if (min == 1 && max == kUnbounded) return "+";
  if (min == 0 && max == 1) return "?";
  if (max == kUnbounded) return "{" + std::to_string(min) + ",}";
  if (min == max) return "{" + std::to_string(min) + "}";
  return "{" + std::to_string(min) + "," + std::to_string(max) + "}";
}

// Binding strength: loosest 0 (|) to tightest 5 (atoms).
int level(const Node& n) {
  switch (n.kind) {
    case NodeKind::kAlt: return 0;
    case NodeKind::kAnd: return 1;
    case NodeKind::kConcat: return 2;
    case NodeKind::kNot: return 3;
    case NodeKind::kRepeat: return 4;
    case NodeKind::kSet: return 5;
  }
  return 5;
}

void print(const Regex& r, int i, std::string& out) {
  const Node& n = r.at(i);
  auto child = [&](int k, int min_level) {
    const bool paren = level(r.at(k)) < min_level;
    if (paren) out += '(';
    print(r, k, out);
    if (paren) out += ')';
  };
  switch (n.kind) {
    case NodeKind::kSet: out += set_text(n.mask, false); break;
    case NodeKind::kAlt:
    case NodeKind::kAnd:
    case NodeKind::kConcat: {
      const int lv = level(n);
      const char* sep = n.kind == NodeKind::kAlt ? "|" : n.kind == NodeKind::kAnd ? "&" : "";
      for (std::size_t j = 0; j < n.kids.size(); ++j) {
        if (j) out += sep;
        child(n.kids[j], lv + 1);
      }
      break;
    }
    case NodeKind::kNot: out += '~'; child(n.kids[0], 3); break;
    case NodeKind::kRepeat: child(n.kids[0], 4); out += repeat_suffix(n.min, n.max); break;
  }
}

}  // namespace

Regex reversed(const Regex& r) {
  Regex out = r;
  for (Node& n : out.nodes)
    if (n.kind == NodeKind::kConcat) std::reverse(n.kids.begin(), n.kids.end());
  return out;
}

std::string dump(const Regex& r, int i) {
  const Node& n = r.at(i);
  auto kids = [&](const char* name) {
    std::string s = std::string(name) + "{";
    for (std::size_t j = 0; j < n.kids.size(); ++j) {
      if (j) s += ' ';
      s += dump(r, n.kids[j]);
    }
    return s + "}";
  };
  switch (n.kind) {
    case NodeKind::kSet: return set_text(n.mask, true);
    case NodeKind::kConcat: return kids("cat");
    case NodeKind::kAlt: return kids("alt");
    case NodeKind::kAnd: return kids("and");
    case NodeKind::kNot: return kids("not");
    case NodeKind::kRepeat: {
      const std::string inner = dump(r, n.kids[0]);
      if (n.min == 0 && n.max == kUnbounded) return "star{" + inner + "}";
      if (n.min == 1 && n.max == kUnbounded) return "plus{" + inner + "}";
      if (n.min == 0 && n.max == 1) return "opt{" + inner + "}";
      return "rep{" + std::to_string(n.min) + "," +
             (n.max == kUnbounded ? std::string() : std::to_string(n.max)) + " " + inner + "}";
    }
  }
  return "";
}

std::string dump(const Regex& r) { return r.root < 0 ? std::string() : dump(r, r.root); }

std::string to_string(const Regex& r) {
  std::string out;
  if (r.root >= 0) print(r, r.root, out);
  return out;
}

}  // namespace pathex
