// Subset construction, minimisation and canonical numbering.
//
// determinize() is the textbook subset construction over ε-closed sets of NFA states, with a
// budget: past Limits::max_states DFA states it stops and says which option raises the budget
// (RE2's DFA gives up the same way when it runs out of memory). minimize() refines the partition
// {accepting, rejecting} with Hopcroft's algorithm (O(n log n): a 30,000-letter literal
// minimises in milliseconds), then numbers the states canonically.
#include "automata/dfa.h"

#include <algorithm>
#include <array>
#include <deque>
#include <unordered_map>

#include "core/budget.h"
#include "core/hash.h"

namespace pathex {
namespace {

// States reachable from the start, renumbered breadth-first in letter order. Applied to a minimal
// DFA this is the canonical numbering.
Dfa renumber_from_start(const Dfa& d) {
  std::vector<int> id(static_cast<std::size_t>(d.num_states), -1);
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(d.num_states));
  id[static_cast<std::size_t>(d.start)] = 0;
  order.push_back(d.start);
  for (std::size_t q = 0; q < order.size(); ++q) {
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = d.step(order[q], l);
      if (id[static_cast<std::size_t>(t)] < 0) {
        id[static_cast<std::size_t>(t)] = static_cast<int>(order.size());
        order.push_back(t);
      }
    }
  }
  Dfa out;
  out.num_states = static_cast<int>(order.size());
  out.start = 0;
  out.next.resize(order.size() * kNumLetters);
  out.accept.resize(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    out.accept[i] = d.accept[static_cast<std::size_t>(order[i])];
    for (int l = 0; l < kNumLetters; ++l)
      out.next[i * kNumLetters + static_cast<std::size_t>(l)] = id[static_cast<std::size_t>(d.step(order[i], l))];
  }
  return out;
}

}  // namespace

bool Dfa::accepts(std::string_view letters) const {
  int s = start;
  for (char c : letters) {
    const auto l = letter_from_char(c);
    if (!l) return false;
    s = step(s, *l);
  }
  return accept[static_cast<std::size_t>(s)] != 0;
}

std::vector<std::uint8_t> Dfa::live() const {
  // Backward reachability from accepting states.
  std::vector<std::vector<int>> preds(static_cast<std::size_t>(num_states));
  for (int s = 0; s < num_states; ++s)
    for (int l = 0; l < kNumLetters; ++l) preds[static_cast<std::size_t>(step(s, l))].push_back(s);
  std::vector<std::uint8_t> out(static_cast<std::size_t>(num_states), 0);
  std::vector<int> stack;
  for (int s = 0; s < num_states; ++s)
    if (accept[static_cast<std::size_t>(s)]) { out[static_cast<std::size_t>(s)] = 1; stack.push_back(s); }
  while (!stack.empty()) {
    const int s = stack.back();
    stack.pop_back();
    for (int p : preds[static_cast<std::size_t>(s)])
      if (!out[static_cast<std::size_t>(p)]) { out[static_cast<std::size_t>(p)] = 1; stack.push_back(p); }
  }
  return out;
}

int Dfa::live_count() const {
  int n = 0;
  for (auto b : live()) n += b;
  return n;
}

Result<Dfa> determinize(const Nfa& n, const Limits& limits) {
  std::vector<int> stamp(n.states.size(), -1);
  int epoch = 0;
  std::vector<int> stack;
  // ε-closure of `seeds`, sorted so it can key the map.
  auto closure = [&](std::vector<int>& set) {
    ++epoch;
    stack.clear();
    for (int s : set) {
      if (stamp[static_cast<std::size_t>(s)] != epoch) { stamp[static_cast<std::size_t>(s)] = epoch; stack.push_back(s); }
    }
    set.clear();
    while (!stack.empty()) {
      const int s = stack.back();
      stack.pop_back();
      set.push_back(s);
      for (int t : n.states[static_cast<std::size_t>(s)].eps)
        if (stamp[static_cast<std::size_t>(t)] != epoch) { stamp[static_cast<std::size_t>(t)] = epoch; stack.push_back(t); }
    }
    std::sort(set.begin(), set.end());
  };

  std::unordered_map<std::vector<int>, int, IntVectorHash> ids;
  std::vector<std::vector<int>> sets;
  Dfa d;
  auto intern = [&](std::vector<int>&& set) -> int {
    auto it = ids.find(set);
    if (it != ids.end()) return it->second;
    const int id = static_cast<int>(sets.size());
    WorkBudget::charge(4 * (set.size() + 1));  // sorting and hashing the subset cost more than a product pair
    bool acc = false;
    for (int s : set) acc = acc || s == n.accept;
    d.accept.push_back(acc ? 1 : 0);
    ids.emplace(set, id);
    sets.push_back(std::move(set));
    return id;
  };

  std::vector<int> init{n.start};
  closure(init);
  d.start = intern(std::move(init));
  std::array<std::vector<int>, kNumLetters> targets;
  for (std::size_t q = 0; q < sets.size(); ++q) {
    for (auto& t : targets) t.clear();
    for (int s : sets[q])
      for (const auto& [mask, t] : n.states[static_cast<std::size_t>(s)].edges)
        for (int l = 0; l < kNumLetters; ++l)
          if (mask & (1u << l)) targets[static_cast<std::size_t>(l)].push_back(t);
    for (int l = 0; l < kNumLetters; ++l) {
      std::vector<int> set = targets[static_cast<std::size_t>(l)];
      closure(set);
      const int id = intern(std::move(set));
      d.next.push_back(id);
      if (sets.size() > limits.max_states)
        return make_error(ErrorCode::kLimit, limit_message("the DFA", limits.max_states, "states", "--max-states"));
    }
  }
  d.num_states = static_cast<int>(sets.size());
  return d;
}

std::vector<int> refine_partition(const std::vector<std::int32_t>& next, const std::vector<int>& labels,
                                  int* blocks) {
  // Hopcroft's algorithm: a worklist of splitters (block B, letter l); each splits every block
  // into the states whose l-successor lies in B and the rest. Only the smaller half of a split
  // needs to become a splitter, so each state enters the worklist O(log n) times and the whole
  // refinement is O(n log n) (Moore's round-by-round refinement took n rounds on a literal).
  const std::size_t n = labels.size();
  WorkBudget::charge(n);  // the n log n of the splits is bounded by the state cap on n
  // Predecessors by letter, as one array per letter indexed by target (counting sort).
  std::vector<std::vector<int>> pred_begin(kNumLetters, std::vector<int>(n + 1, 0));
  std::vector<std::vector<int>> preds(kNumLetters, std::vector<int>(n));
  for (std::size_t l = 0; l < kNumLetters; ++l) {
    std::vector<int>& begin = pred_begin[l];
    for (std::size_t s = 0; s < n; ++s) ++begin[static_cast<std::size_t>(next[s * kNumLetters + l]) + 1];
    for (std::size_t t = 0; t < n; ++t) begin[t + 1] += begin[t];
    std::vector<int> fill(begin.begin(), begin.end() - 1);
    for (std::size_t s = 0; s < n; ++s)
      preds[l][static_cast<std::size_t>(fill[static_cast<std::size_t>(next[s * kNumLetters + l])]++)] = static_cast<int>(s);
  }
  // The partition: `elems` lists the states block by block; block b is elems[first[b], end[b]).
  std::vector<int> block(n), elems(n), pos(n), first, end, marked;
  {
    std::unordered_map<int, int> ids;
    for (std::size_t s = 0; s < n; ++s) {
      auto [it, inserted] = ids.emplace(labels[s], static_cast<int>(ids.size()));
      block[s] = it->second;
    }
    const std::size_t count = ids.size();
    first.assign(count, 0);
    end.assign(count, 0);
    marked.assign(count, 0);
    for (std::size_t s = 0; s < n; ++s) ++end[static_cast<std::size_t>(block[s])];
    int at = 0;
    for (std::size_t b = 0; b < count; ++b) {
      first[b] = at;
      at += end[b];
      end[b] = first[b];
    }
    for (std::size_t s = 0; s < n; ++s) {
      const std::size_t b = static_cast<std::size_t>(block[s]);
      pos[s] = end[b];
      elems[static_cast<std::size_t>(end[b]++)] = static_cast<int>(s);
    }
  }
  std::vector<std::pair<int, int>> work;               // (block, letter)
  std::vector<std::array<std::uint8_t, kNumLetters>> queued(first.size(), {1, 1, 1, 1});
  for (int b = 0; b < static_cast<int>(first.size()); ++b)
    for (int l = 0; l < kNumLetters; ++l) work.push_back({b, l});
  std::vector<int> xs, touched;
  while (!work.empty()) {
    const auto [b, l] = work.back();
    work.pop_back();
    queued[static_cast<std::size_t>(b)][static_cast<std::size_t>(l)] = 0;
    // The states whose l-successor is in block b (each state has one l-successor: no repeats).
    xs.clear();
    for (int i = first[static_cast<std::size_t>(b)]; i < end[static_cast<std::size_t>(b)]; ++i) {
      const std::size_t t = static_cast<std::size_t>(elems[static_cast<std::size_t>(i)]);
      for (int j = pred_begin[static_cast<std::size_t>(l)][t]; j < pred_begin[static_cast<std::size_t>(l)][t + 1]; ++j)
        xs.push_back(preds[static_cast<std::size_t>(l)][static_cast<std::size_t>(j)]);
    }
    // Move each to the front of its block.
    touched.clear();
    for (int s : xs) {
      const std::size_t c = static_cast<std::size_t>(block[static_cast<std::size_t>(s)]);
      const int to = first[c] + marked[c]++;
      if (marked[c] == 1) touched.push_back(static_cast<int>(c));
      const int other = elems[static_cast<std::size_t>(to)];
      std::swap(elems[static_cast<std::size_t>(to)], elems[static_cast<std::size_t>(pos[static_cast<std::size_t>(s)])]);
      pos[static_cast<std::size_t>(other)] = pos[static_cast<std::size_t>(s)];
      pos[static_cast<std::size_t>(s)] = to;
    }
    // Split every block that is only partly marked; the marked part becomes a new block.
    for (int ci : touched) {
      const std::size_t c = static_cast<std::size_t>(ci);
      const int m = marked[c];
      marked[c] = 0;
      if (m == end[c] - first[c]) continue;
      const int d = static_cast<int>(first.size());
      first.push_back(first[c]);
      end.push_back(first[c] + m);
      marked.push_back(0);
      queued.push_back({0, 0, 0, 0});
      first[c] += m;
      for (int i = first.back(); i < end.back(); ++i) block[static_cast<std::size_t>(elems[static_cast<std::size_t>(i)])] = d;
      const bool d_smaller = m <= end[c] - first[c];
      for (int a = 0; a < kNumLetters; ++a) {
        const std::size_t ai = static_cast<std::size_t>(a);
        const int add = queued[c][ai] || d_smaller ? d : ci;
        queued[static_cast<std::size_t>(add)][ai] = 1;
        work.push_back({add, a});
      }
    }
  }
  *blocks = static_cast<int>(first.size());
  return block;
}

Dfa minimize(const Dfa& in) {
  const Dfa d = renumber_from_start(in);  // drops unreachable states
  const std::size_t n = static_cast<std::size_t>(d.num_states);
  int count = 0;
  const std::vector<int> cls = refine_partition(d.next, std::vector<int>(d.accept.begin(), d.accept.end()), &count);
  Dfa q;
  q.num_states = count;
  q.start = cls[static_cast<std::size_t>(d.start)];
  q.next.assign(static_cast<std::size_t>(count) * kNumLetters, 0);
  q.accept.assign(static_cast<std::size_t>(count), 0);
  for (std::size_t s = 0; s < n; ++s) {
    const std::size_t c = static_cast<std::size_t>(cls[s]);
    q.accept[c] = d.accept[s];
    for (int l = 0; l < kNumLetters; ++l)
      q.next[c * kNumLetters + static_cast<std::size_t>(l)] = cls[static_cast<std::size_t>(d.next[s * kNumLetters + static_cast<std::size_t>(l)])];
  }
  return renumber_from_start(q);
}

Result<Dfa> compile(const Regex& r, const Limits& limits) {
  Result<Dfa> d = within_budget(limits, [&]() -> Result<Dfa> {
    Result<Nfa> n = build_nfa(r, limits);
    if (!n) return n.error();
    Result<Dfa> sub = determinize(*n, limits);
    if (!sub) return sub.error();
    return minimize(*sub);
  });
  if (!d && d.error().source.empty()) {
    // The subset construction and the work budget concern the whole expression.
    Error e = d.error();
    e.source = r.source;
    e.column = r.source.empty() ? 0 : 1;
    return e;
  }
  return d;
}

std::string to_dot(const Dfa& d, const std::string& title) {
  const std::vector<std::uint8_t> live = d.live();
  std::string out = "digraph pathex {\n  rankdir=LR;\n  label=\"";
  for (char c : title) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  out += "\";\n  node [shape=circle];\n  start [shape=point];\n";
  for (int s = 0; s < d.num_states; ++s) {
    if (!live[static_cast<std::size_t>(s)]) continue;
    out += "  q" + std::to_string(s) + " [label=\"" + std::to_string(s) + "\"" +
           (d.accept[static_cast<std::size_t>(s)] ? ", shape=doublecircle" : "") + "];\n";
  }
  if (live[static_cast<std::size_t>(d.start)]) out += "  start -> q" + std::to_string(d.start) + ";\n";
  for (int s = 0; s < d.num_states; ++s) {
    if (!live[static_cast<std::size_t>(s)]) continue;
    // One edge per target, labelled with all letters that lead there.
    std::vector<std::pair<int, std::string>> edges;
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = d.step(s, l);
      if (!live[static_cast<std::size_t>(t)]) continue;
      bool merged = false;
      for (auto& [to, label] : edges)
        if (to == t) { label += std::string(",") + letter_char(l); merged = true; }
      if (!merged) edges.push_back({t, std::string(1, letter_char(l))});
    }
    for (const auto& [to, label] : edges)
      out += "  q" + std::to_string(s) + " -> q" + std::to_string(to) + " [label=\"" + label + "\"];\n";
  }
  out += "}\n";
  return out;
}

}  // namespace pathex
