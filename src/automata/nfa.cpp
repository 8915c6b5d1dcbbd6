// Thompson's construction. Each call returns a fragment (entry, exit); the caller wires exits
// with ε-edges. Repetition {n,m} copies the operand's fragment, so before copying we check that
// the copies fit under Limits::max_states — the check that keeps nested counters from exploding.
#include "automata/nfa.h"

#include <unordered_map>

#include "automata/dfa.h"
#include "automata/ops.h"
#include "core/budget.h"

namespace pathex {
namespace {

struct Frag {
  int in = -1;
  int out = -1;
};

class Builder {
 public:
  Builder(const Regex& r, const Limits& limits) : r_(r), limits_(limits) {}

  Result<Nfa> run() {
    const Frag f = build(r_.root);
    if (failed_) return err_;
    nfa_.start = f.in;
    nfa_.accept = f.out;
    return std::move(nfa_);
  }

 private:
  bool reserve(std::size_t more, int column) {
    if (failed_) return false;
    if (nfa_.states.size() + more > limits_.max_states) {
      fail(Error{ErrorCode::kLimit, limit_message("the automaton", limits_.max_states, "states", "--max-states"),
                 r_.source, column, ""});
      return false;
    }
    return true;
  }
  void fail(Error e) {
    if (!failed_) { failed_ = true; err_ = std::move(e); }
  }
  int state() {
    WorkBudget::charge(1);
    nfa_.states.emplace_back();
    return static_cast<int>(nfa_.states.size()) - 1;
  }
  void eps(int a, int b) { nfa_.states[static_cast<std::size_t>(a)].eps.push_back(b); }

  // Number of NFA states the subtree needs, saturating; used to refuse oversized repeats early.
  std::size_t estimate(int i) const {
    const Node& n = r_.at(i);
    const std::size_t cap = limits_.max_states + 1;
    auto sat_add = [&](std::size_t a, std::size_t b) { return a + b > cap ? cap : a + b; };
    switch (n.kind) {
      case NodeKind::kSet: return 2;
      case NodeKind::kConcat:
      case NodeKind::kAlt: {
        std::size_t s = 2;
        for (int k : n.kids) s = sat_add(s, estimate(k));
        return s;
      }
      case NodeKind::kAnd:
      case NodeKind::kNot: return 2;  // replaced by an embedded DFA; its size is checked when built
      case NodeKind::kRepeat: {
        const std::size_t one = estimate(n.kids[0]);
        // min mandatory copies plus one looping copy, or max copies.
        const std::size_t copies = static_cast<std::size_t>(n.max == kUnbounded ? n.min + 1 : n.max);
        return one != 0 && copies > cap / one ? cap : sat_add(2, one * copies);
      }
    }
    return cap;
  }

  Frag build(int i) {
    if (failed_) return {};
    const Node& n = r_.at(i);
    switch (n.kind) {
      case NodeKind::kSet: {
        if (!reserve(2, n.column)) return {};
        const int a = state(), b = state();
        nfa_.states[static_cast<std::size_t>(a)].edges.push_back({n.mask, b});
        return {a, b};
      }
      case NodeKind::kConcat: {
        Frag whole;
        for (int k : n.kids) {
          const Frag f = build(k);
          if (failed_) return {};
          if (whole.in < 0) whole = f;
          else { eps(whole.out, f.in); whole.out = f.out; }
        }
        return whole;
      }
      case NodeKind::kAlt: {
        if (!reserve(2, n.column)) return {};
        const int a = state(), b = state();
        for (int k : n.kids) {
          const Frag f = build(k);
          if (failed_) return {};
          eps(a, f.in);
          eps(f.out, b);
        }
        return {a, b};
      }
      case NodeKind::kAnd:
      case NodeKind::kNot: return embed_boolean(i);
      case NodeKind::kRepeat: return build_repeat(i);
    }
    return {};
  }

  Frag build_repeat(int i) {
    const Node& n = r_.at(i);
    if (!reserve(estimate(i), n.column)) return {};
    const int a = state(), b = state();
    int cur = a;
    // Mandatory copies.
    for (int j = 0; j < n.min; ++j) {
      const Frag f = build(n.kids[0]);
      if (failed_) return {};
      eps(cur, f.in);
      cur = f.out;
    }
    if (n.max == kUnbounded) {
      // One more copy that loops: cur -> f -> back to cur.
      const Frag f = build(n.kids[0]);
      if (failed_) return {};
      eps(cur, f.in);
      eps(f.out, cur);
      eps(cur, b);
    } else {
      // Optional copies, each may be skipped to the end.
      for (int j = n.min; j < n.max; ++j) {
        eps(cur, b);
        const Frag f = build(n.kids[0]);
        if (failed_) return {};
        eps(cur, f.in);
        cur = f.out;
      }
      eps(cur, b);
    }
    return {a, b};
  }

  // `&` and `~`: compile operands to minimal DFAs, combine, embed the live part as a fragment.
  // The combined DFA is computed once per node: a repetition embeds the same node many times
  // (`(S{1000}&D*){1000}` used to compile S{1000} a thousand times).
  Frag embed_boolean(int i) {
    const Node& n = r_.at(i);
    auto cached = booleans_.find(i);
    if (cached == booleans_.end()) {
      Result<Dfa> d = combine_boolean(n);
      if (!d) { fail(d.error()); return {}; }
      cached = booleans_.emplace(i, std::move(d.value())).first;
    }
    const Dfa& d = cached->second;
    const std::vector<std::uint8_t>& live = live_.try_emplace(i, d.live()).first->second;
    return embed_dfa(n, d, live);
  }

  // The DFA of an `&` or `~` node: its operands' minimal DFAs, intersected or complemented.
  Result<Dfa> combine_boolean(const Node& n) {
    Regex sub;
    sub.source = r_.source;
    std::vector<Dfa> parts;
    for (int k : n.kids) {
      sub.nodes = r_.nodes;
      sub.root = k;
      Result<Dfa> d = compile(sub, limits_);
      if (!d) return d.error();
      parts.push_back(std::move(d.value()));
    }
    if (n.kind == NodeKind::kNot) return dfa_complement(parts[0]);
    Dfa d = parts[0];
    for (std::size_t j = 1; j < parts.size(); ++j) d = dfa_intersect(d, parts[j]);
    return d;
  }

  // The embedding of node i's combined DFA d as a fragment.
  Frag embed_dfa(const Node& n, const Dfa& d, const std::vector<std::uint8_t>& live) {
    if (!reserve(static_cast<std::size_t>(d.num_states) + 2, n.column)) return {};
    const int base = static_cast<int>(nfa_.states.size());
    for (int s = 0; s < d.num_states; ++s) state();
    const int a = state(), b = state();
    if (live[static_cast<std::size_t>(d.start)]) eps(a, base + d.start);
    for (int s = 0; s < d.num_states; ++s) {
      if (!live[static_cast<std::size_t>(s)]) continue;
      auto& st = nfa_.states[static_cast<std::size_t>(base + s)];
      for (int l = 0; l < kNumLetters; ++l) {
        const int t = d.step(s, l);
        if (live[static_cast<std::size_t>(t)]) st.edges.push_back({static_cast<LetterMask>(1u << l), base + t});
      }
      if (d.accept[static_cast<std::size_t>(s)]) eps(base + s, b);
    }
    return {a, b};
  }

  const Regex& r_;
  const Limits& limits_;
  Nfa nfa_;
  std::unordered_map<int, Dfa> booleans_;                     // node index -> its combined DFA
  std::unordered_map<int, std::vector<std::uint8_t>> live_;   // node index -> that DFA's live states
  bool failed_ = false;
  Error err_;
};

}  // namespace

Result<Nfa> build_nfa(const Regex& r, const Limits& limits) { return Builder(r, limits).run(); }

Nfa reversed_nfa(const Dfa& d) {
  Nfa n;
  n.states.resize(static_cast<std::size_t>(d.num_states) + 2);
  const int start = d.num_states, accept = d.num_states + 1;
  n.start = start;
  n.accept = accept;
  for (int s = 0; s < d.num_states; ++s) {
    for (int l = 0; l < kNumLetters; ++l)
      n.states[static_cast<std::size_t>(d.step(s, l))].edges.push_back({static_cast<LetterMask>(1u << l), s});
    if (d.accept[static_cast<std::size_t>(s)]) n.states[static_cast<std::size_t>(start)].eps.push_back(s);
  }
  n.states[static_cast<std::size_t>(d.start)].eps.push_back(accept);
  return n;
}

Nfa substituted_nfa(const Dfa& d, Letter letter, const std::vector<std::string>& words) {
  Nfa n;
  n.states.resize(static_cast<std::size_t>(d.num_states) + 1);
  const int accept = d.num_states;
  n.start = d.start;
  n.accept = accept;
  auto fresh = [&] {
    n.states.emplace_back();
    return static_cast<int>(n.states.size()) - 1;
  };
  for (int s = 0; s < d.num_states; ++s) {
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = d.step(s, l);
      if (l != letter) {
        n.states[static_cast<std::size_t>(s)].edges.push_back({static_cast<LetterMask>(1u << l), t});
        continue;
      }
      for (const std::string& w : words) {
        int cur = s;
        for (std::size_t j = 0; j < w.size(); ++j) {
          const int nx = j + 1 == w.size() ? t : fresh();
          const Letter wl = *letter_from_char(w[j]);
          n.states[static_cast<std::size_t>(cur)].edges.push_back({static_cast<LetterMask>(1u << wl), nx});
          cur = nx;
        }
        if (w.empty()) n.states[static_cast<std::size_t>(s)].eps.push_back(t);
      }
    }
    if (d.accept[static_cast<std::size_t>(s)]) n.states[static_cast<std::size_t>(s)].eps.push_back(accept);
  }
  return n;
}

}  // namespace pathex
