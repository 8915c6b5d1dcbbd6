// Product construction over N class DFAs with a set-valued output, then minimisation by the
// shared partition refinement with the class-set id as the initial label.
#include "classify/classifier.h"

#include <map>
#include <unordered_map>

#include "automata/ops.h"
#include "core/budget.h"
#include "core/hash.h"

namespace pathex {

const std::uint8_t Classifier::kColumn[256] = {
#define X4 4, 4, 4, 4
#define X16 X4, X4, X4, X4
    X16, X16, X16, X16,                      // 0x00-0x3f
    4, 4, 4, 4, kD, kE, 4, 4, 4, 4, 4, 4, kL, 4, 4, 4,   // 0x40-0x4f: D=0x44 E=0x45 L=0x4c
    4, 4, 4, kS, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4,     // 0x50-0x5f: S=0x53
    X16, X16, X16, X16, X16, X16, X16, X16, X16, X16,    // 0x60-0xff
#undef X16
#undef X4
};

namespace {

// One direction: product of `dfas`, outputs interned into `sets`.
Result<Classifier::Direction> build_direction(const std::vector<Dfa>& dfas, std::vector<std::vector<int>>& sets,
                                              std::map<std::vector<int>, std::uint32_t>& set_ids,
                                              const Limits& limits) {
  const std::size_t n = dfas.size();
  std::unordered_map<std::vector<int>, int, IntVectorHash> ids;
  std::vector<std::vector<int>> tuples;
  std::vector<std::int32_t> next;
  std::vector<int> labels;
  auto intern_set = [&](const std::vector<int>& members) {
    auto [it, inserted] = set_ids.emplace(members, static_cast<std::uint32_t>(sets.size()));
    if (inserted) sets.push_back(members);
    return it->second;
  };
  auto intern = [&](std::vector<int>&& t) {
    auto it = ids.find(t);
    if (it != ids.end()) return it->second;
    const int id = static_cast<int>(tuples.size());
    std::vector<int> members;
    for (std::size_t i = 0; i < n; ++i)
      if (dfas[i].accept[static_cast<std::size_t>(t[i])]) members.push_back(static_cast<int>(i));
    WorkBudget::charge(n + 1);
    labels.push_back(static_cast<int>(intern_set(members)));
    ids.emplace(t, id);
    tuples.push_back(std::move(t));
    return id;
  };
  std::vector<int> init(n);
  for (std::size_t i = 0; i < n; ++i) init[i] = dfas[i].start;
  const int start = intern(std::move(init));
  for (std::size_t q = 0; q < tuples.size(); ++q) {
    for (int l = 0; l < kNumLetters; ++l) {
      std::vector<int> t(n);
      for (std::size_t i = 0; i < n; ++i) t[i] = dfas[i].step(tuples[q][i], l);
      next.push_back(intern(std::move(t)));
      if (tuples.size() > limits.max_states)
        return make_error(ErrorCode::kLimit, limit_message("the classifier automaton", limits.max_states, "states", "--max-states"));
    }
  }
  int blocks = 0;
  const std::vector<int> block = refine_partition(next, labels, &blocks);
  // Quotient, with block of the start first and a sink appended for characters outside D E L S.
  const int sink = blocks;
  const int total = blocks + 1;
  Classifier::Direction d;
  d.table.assign(static_cast<std::size_t>(total) * Classifier::kStride, static_cast<Classifier::State>(sink * Classifier::kStride));
  d.set_of.assign(static_cast<std::size_t>(total), intern_set({}));
  for (std::size_t s = 0; s < tuples.size(); ++s) {
    const std::size_t b = static_cast<std::size_t>(block[s]);
    d.set_of[b] = static_cast<std::uint32_t>(labels[s]);
    for (std::size_t l = 0; l < kNumLetters; ++l)
      d.table[b * Classifier::kStride + l] =
          static_cast<Classifier::State>(block[static_cast<std::size_t>(next[s * kNumLetters + l])] * Classifier::kStride);
  }
  d.start = static_cast<Classifier::State>(block[static_cast<std::size_t>(start)] * Classifier::kStride);
  // Alive: backward reachability from states whose set is non-empty.
  std::vector<std::vector<int>> preds(static_cast<std::size_t>(total));
  for (int s = 0; s < total; ++s)
    for (int l = 0; l < kNumLetters; ++l)
      preds[d.table[static_cast<std::size_t>(s) * Classifier::kStride + static_cast<std::size_t>(l)] / Classifier::kStride].push_back(s);
  d.alive.assign(static_cast<std::size_t>(total), 0);
  std::vector<int> stack;
  for (int s = 0; s < total; ++s)
    if (!sets[d.set_of[static_cast<std::size_t>(s)]].empty()) { d.alive[static_cast<std::size_t>(s)] = 1; stack.push_back(s); }
  while (!stack.empty()) {
    const int s = stack.back();
    stack.pop_back();
    for (int p : preds[static_cast<std::size_t>(s)])
      if (!d.alive[static_cast<std::size_t>(p)]) { d.alive[static_cast<std::size_t>(p)] = 1; stack.push_back(p); }
  }
  return d;
}

}  // namespace

Result<Classifier> Classifier::build(const std::vector<const PathClass*>& classes, const Limits& limits) {
  return within_budget(limits, [&]() -> Result<Classifier> { return build_unbudgeted(classes, limits); });
}

Result<Classifier> Classifier::build_unbudgeted(const std::vector<const PathClass*>& classes, const Limits& limits) {
  Classifier c;
  std::vector<Dfa> fwd, bwd;
  for (const PathClass* pc : classes) {
    c.names_.push_back(pc->name.empty() ? pc->text : pc->name);
    fwd.push_back(pc->dfa);
    Result<Dfa> r = dfa_reverse(pc->dfa, limits);
    if (!r) return r.error();
    bwd.push_back(std::move(*r));
  }
  std::map<std::vector<int>, std::uint32_t> set_ids;
  Result<Direction> f = build_direction(fwd, c.sets_, set_ids, limits);
  if (!f) return f.error();
  c.fwd_ = std::move(*f);
  Result<Direction> b = build_direction(bwd, c.sets_, set_ids, limits);
  if (!b) return b.error();
  c.bwd_ = std::move(*b);
  return c;
}

std::uint32_t Classifier::classify_backward(std::string_view path) const {
  State s = bwd_.start;
  for (std::size_t i = path.size(); i-- > 0;) s = bwd_.table[s + static_cast<State>(column(path[i]))];
  return bwd_.set_of[s / kStride];
}

}  // namespace pathex
