// Language operations. The boolean ones are one product construction parameterised by the
// boolean function of the two acceptance bits; the decision questions reduce to emptiness of a
// product; the evidence (shortest member, enumeration, counts) walks the DFA breadth-first, using
// distances to acceptance so that it never explores a dead end.
#include "automata/ops.h"

#include <functional>
#include <unordered_map>

#include "core/budget.h"

namespace pathex {
namespace {

Dfa single_state(bool accepting) {
  Dfa d;
  d.num_states = 1;
  d.next.assign(kNumLetters, 0);
  d.accept = {static_cast<std::uint8_t>(accepting ? 1 : 0)};
  return d;
}

// Product of two complete DFAs over reachable pairs, accepting where op(a, b) holds.
Dfa product(const Dfa& a, const Dfa& b, const std::function<bool(bool, bool)>& op) {
  std::unordered_map<std::uint64_t, int> id;
  std::vector<std::pair<int, int>> pairs;
  auto intern = [&](int x, int y) {
    WorkBudget::charge(1);
    const std::uint64_t key = (static_cast<std::uint64_t>(x) << 32) | static_cast<std::uint32_t>(y);
    auto [it, inserted] = id.emplace(key, static_cast<int>(pairs.size()));
    if (inserted) pairs.push_back({x, y});
    return it->second;
  };
  Dfa d;
  d.start = intern(a.start, b.start);
  for (std::size_t q = 0; q < pairs.size(); ++q) {
    const auto [x, y] = pairs[q];
    d.accept.push_back(op(a.accept[static_cast<std::size_t>(x)] != 0, b.accept[static_cast<std::size_t>(y)] != 0) ? 1 : 0);
    for (int l = 0; l < kNumLetters; ++l) d.next.push_back(intern(a.step(x, l), b.step(y, l)));
  }
  d.num_states = static_cast<int>(pairs.size());
  return minimize(d);
}

// Shortest distance from each state to an accepting state (-1 if none).
std::vector<int> distance_to_accept(const Dfa& a) {
  std::vector<std::vector<int>> preds(static_cast<std::size_t>(a.num_states));
  for (int s = 0; s < a.num_states; ++s)
    for (int l = 0; l < kNumLetters; ++l) preds[static_cast<std::size_t>(a.step(s, l))].push_back(s);
  std::vector<int> dist(static_cast<std::size_t>(a.num_states), -1);
  std::vector<int> queue;
  for (int s = 0; s < a.num_states; ++s)
    if (a.accept[static_cast<std::size_t>(s)]) { dist[static_cast<std::size_t>(s)] = 0; queue.push_back(s); }
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (int p : preds[static_cast<std::size_t>(queue[q])])
      if (dist[static_cast<std::size_t>(p)] < 0) {
        dist[static_cast<std::size_t>(p)] = dist[static_cast<std::size_t>(queue[q])] + 1;
        queue.push_back(p);
      }
  return dist;
}

}  // namespace

Dfa dfa_empty() { return single_state(false); }
Dfa dfa_all() { return single_state(true); }

Dfa dfa_word(std::string_view w) {
  Dfa d;
  const int n = static_cast<int>(w.size());
  d.num_states = n + 2;  // 0..n along the word, n+1 dead
  const int dead = n + 1;
  d.next.assign(static_cast<std::size_t>(d.num_states) * kNumLetters, dead);
  d.accept.assign(static_cast<std::size_t>(d.num_states), 0);
  for (int i = 0; i < n; ++i) d.next[static_cast<std::size_t>(i) * kNumLetters + *letter_from_char(w[static_cast<std::size_t>(i)])] = i + 1;
  d.accept[static_cast<std::size_t>(n)] = 1;
  return minimize(d);
}

Dfa dfa_universe() {
  // States: 0 start, 1..5 after L and 0..4 scattering letters (capped), 6 accept, 7 dead.
  Dfa d;
  d.num_states = 8;
  d.next.assign(8 * kNumLetters, 7);
  d.accept.assign(8, 0);
  d.next[0 * kNumLetters + kL] = 1;
  for (int i = 1; i <= 5; ++i) {
    const int after = i == 5 ? 5 : i + 1;
    d.next[static_cast<std::size_t>(i) * kNumLetters + kS] = after;
    d.next[static_cast<std::size_t>(i) * kNumLetters + kD] = after;
  }
  d.next[5 * kNumLetters + kE] = 6;
  d.accept[6] = 1;
  return minimize(d);
}

Dfa dfa_universe_bounded(int max_bounces) {
  // States: 0 start; 1 + i after L and i scattering letters, i = 0 .. max_bounces + 4; then
  // accept and dead. Built directly: no parse, no limit to trip over.
  const int top = std::max(max_bounces, 0) + 4;
  const int accept = top + 2, dead = top + 3;
  Dfa d;
  d.num_states = top + 4;
  d.next.assign(static_cast<std::size_t>(d.num_states) * kNumLetters, dead);
  d.accept.assign(static_cast<std::size_t>(d.num_states), 0);
  d.next[0 * kNumLetters + kL] = 1;
  for (int i = 0; i <= top; ++i) {
    const std::size_t row = static_cast<std::size_t>(1 + i) * kNumLetters;
    if (i < top) d.next[row + kS] = d.next[row + kD] = 2 + i;
    if (i >= 4) d.next[row + kE] = accept;
  }
  d.accept[static_cast<std::size_t>(accept)] = 1;
  return minimize(d);
}

Dfa dfa_union(const Dfa& a, const Dfa& b) { return product(a, b, [](bool x, bool y) { return x || y; }); }
Dfa dfa_intersect(const Dfa& a, const Dfa& b) { return product(a, b, [](bool x, bool y) { return x && y; }); }
Dfa dfa_difference(const Dfa& a, const Dfa& b) { return product(a, b, [](bool x, bool y) { return x && !y; }); }

Dfa dfa_complement(const Dfa& a) {
  Dfa d = a;
  for (auto& acc : d.accept) acc = acc ? 0 : 1;
  return minimize(d);
}

Result<Dfa> dfa_concat(const Dfa& a, const Dfa& b, const Limits& limits) {
  // Embed both as NFAs: every accepting state of a gets an ε-edge to b's start.
  Nfa n;
  const int na = a.num_states;
  n.states.resize(static_cast<std::size_t>(na + b.num_states) + 1);
  n.start = a.start;
  n.accept = na + b.num_states;
  for (int s = 0; s < na; ++s) {
    for (int l = 0; l < kNumLetters; ++l)
      n.states[static_cast<std::size_t>(s)].edges.push_back({static_cast<LetterMask>(1u << l), a.step(s, l)});
    if (a.accept[static_cast<std::size_t>(s)]) n.states[static_cast<std::size_t>(s)].eps.push_back(na + b.start);
  }
  for (int s = 0; s < b.num_states; ++s) {
    for (int l = 0; l < kNumLetters; ++l)
      n.states[static_cast<std::size_t>(na + s)].edges.push_back({static_cast<LetterMask>(1u << l), na + b.step(s, l)});
    if (b.accept[static_cast<std::size_t>(s)]) n.states[static_cast<std::size_t>(na + s)].eps.push_back(n.accept);
  }
  Result<Dfa> d = determinize(n, limits);
  if (!d) return d.error();
  return minimize(*d);
}

Result<Dfa> dfa_reverse(const Dfa& a, const Limits& limits) {
  Result<Dfa> d = determinize(reversed_nfa(a), limits);
  if (!d) return d.error();
  return minimize(*d);
}

bool is_empty(const Dfa& a) { return !a.live()[static_cast<std::size_t>(a.start)]; }
bool is_subset(const Dfa& a, const Dfa& b) { return is_empty(dfa_difference(a, b)); }
bool is_equivalent(const Dfa& a, const Dfa& b) { return minimize(a) == minimize(b); }

bool is_finite(const Dfa& a) {
  // Infinite iff a cycle runs through states that are both reachable from the start and live.
  // Iterative three-colour DFS over that subgraph (hand-built DFAs may have unreachable states).
  std::vector<std::uint8_t> live = a.live();
  std::vector<std::uint8_t> reached(static_cast<std::size_t>(a.num_states), 0);
  std::vector<int> todo{a.start};
  reached[static_cast<std::size_t>(a.start)] = 1;
  while (!todo.empty()) {
    const int s = todo.back();
    todo.pop_back();
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = a.step(s, l);
      if (!reached[static_cast<std::size_t>(t)]) { reached[static_cast<std::size_t>(t)] = 1; todo.push_back(t); }
    }
  }
  for (std::size_t s = 0; s < live.size(); ++s) live[s] = static_cast<std::uint8_t>(live[s] && reached[s]);
  std::vector<std::uint8_t> colour(static_cast<std::size_t>(a.num_states), 0);  // 0 new, 1 open, 2 done
  for (int root = 0; root < a.num_states; ++root) {
    if (!live[static_cast<std::size_t>(root)] || colour[static_cast<std::size_t>(root)]) continue;
    std::vector<std::pair<int, int>> stack{{root, 0}};
    colour[static_cast<std::size_t>(root)] = 1;
    while (!stack.empty()) {
      auto& [s, l] = stack.back();
      if (l == kNumLetters) {
        colour[static_cast<std::size_t>(s)] = 2;
        stack.pop_back();
        continue;
      }
      const int t = a.step(s, l++);
      if (!live[static_cast<std::size_t>(t)]) continue;
      if (colour[static_cast<std::size_t>(t)] == 1) return false;
      if (colour[static_cast<std::size_t>(t)] == 0) {
        colour[static_cast<std::size_t>(t)] = 1;
        stack.push_back({t, 0});
      }
    }
  }
  return true;
}

std::optional<std::string> shortest_member(const Dfa& a) {
  const std::vector<int> dist = distance_to_accept(a);
  int s = a.start;
  if (dist[static_cast<std::size_t>(s)] < 0) return std::nullopt;
  std::string out;
  // Greedy: the smallest letter that keeps the remaining distance one shorter.
  while (dist[static_cast<std::size_t>(s)] > 0) {
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = a.step(s, l);
      if (dist[static_cast<std::size_t>(t)] == dist[static_cast<std::size_t>(s)] - 1) {
        out += letter_char(l);
        s = t;
        break;
      }
    }
  }
  return out;
}

std::vector<std::string> enumerate_members(const Dfa& a, int max_len, std::size_t max_count) {
  std::vector<std::string> out;
  if (max_len < 0 || max_count == 0) return out;
  // can[r][s]: some word of exactly r letters leads from s to acceptance.
  const std::size_t n = static_cast<std::size_t>(a.num_states);
  WorkBudget::charge((static_cast<std::size_t>(max_len) + 1) * n);
  std::vector<std::vector<std::uint8_t>> can(static_cast<std::size_t>(max_len) + 1, std::vector<std::uint8_t>(n, 0));
  for (std::size_t s = 0; s < n; ++s) can[0][s] = a.accept[s];
  for (int r = 1; r <= max_len; ++r)
    for (std::size_t s = 0; s < n; ++s)
      for (int l = 0; l < kNumLetters && !can[static_cast<std::size_t>(r)][s]; ++l)
        can[static_cast<std::size_t>(r)][s] = can[static_cast<std::size_t>(r) - 1][static_cast<std::size_t>(a.step(static_cast<int>(s), l))];
  // Depth-first in letter order within one length gives lexicographic order. The walk keeps its
  // own stack (a member can be as long as the automaton is large: no recursion on input size).
  std::string word;
  std::vector<std::pair<int, int>> stack;  // (state, next letter to try) per letter of `word`
  for (int len = 0; len <= max_len && out.size() < max_count; ++len) {
    if (!can[static_cast<std::size_t>(len)][static_cast<std::size_t>(a.start)]) continue;
    word.clear();
    stack.assign(1, {a.start, 0});
    while (!stack.empty() && out.size() < max_count) {
      auto& [s, l] = stack.back();
      const int remaining = len - static_cast<int>(word.size());
      if (remaining == 0) {
        out.push_back(word);
        stack.pop_back();
        if (!word.empty()) word.pop_back();
        continue;
      }
      if (l == kNumLetters) {
        stack.pop_back();
        if (!word.empty()) word.pop_back();
        continue;
      }
      const int letter = l++;
      const int t = a.step(s, letter);
      if (!can[static_cast<std::size_t>(remaining) - 1][static_cast<std::size_t>(t)]) continue;
      word.push_back(letter_char(letter));
      stack.push_back({t, 0});
    }
  }
  return out;
}

std::vector<BigUint> count_by_length(const Dfa& a, int max_len) {
  std::vector<BigUint> counts;
  if (max_len < 0) return counts;
  const std::size_t n = static_cast<std::size_t>(a.num_states);
  WorkBudget::charge((static_cast<std::size_t>(max_len) + 1) * n);
  // ways[s] = number of words of the current length leading from the start to s.
  std::vector<BigUint> ways(n), next(n);
  ways[static_cast<std::size_t>(a.start)] = BigUint(1);
  for (int len = 0; len <= max_len; ++len) {
    BigUint total;
    for (std::size_t s = 0; s < n; ++s)
      if (a.accept[s]) total += ways[s];
    counts.push_back(total);
    if (len == max_len) break;
    for (auto& w : next) w = BigUint();
    for (std::size_t s = 0; s < n; ++s) {
      if (ways[s].is_zero()) continue;
      for (int l = 0; l < kNumLetters; ++l) next[static_cast<std::size_t>(a.step(static_cast<int>(s), l))] += ways[s];
    }
    ways.swap(next);
  }
  return counts;
}

}  // namespace pathex
