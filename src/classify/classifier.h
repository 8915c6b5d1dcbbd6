// The multi-class classifier: one automaton for a whole class file.
//
// It is the product of the classes' minimal DFAs, minimised with respect to the *set* of classes
// accepted in each state, so classifying a path is one pass over its letters — one table load
// per letter — and the final state names every class the path belongs to. It is built twice,
// once for each reading direction: forward (L to E, as light subpaths grow) and backward (E to L,
// as eye subpaths grow; the product of the reversed languages). In either direction a state can
// be asked whether any class is still reachable (the tracer does not prune subpaths with it yet;
// it classifies each path string once, when the histogram first meets it).
//
// States are row offsets into the table (state index × 8), so stepping is a single load:
// `s = table[s + column(c)]`. Columns 0–3 are the letters D E L S; any other character goes to
// column 4, which leads to an absorbing sink that belongs to no class.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"

namespace pathex {

class Classifier {
 public:
  using State = std::uint32_t;
  static constexpr int kStride = 8;

  struct Direction {
    std::vector<State> table;             // table[s + column]
    State start = 0;
    std::vector<std::uint32_t> set_of;    // class-set id per state index (s / kStride)
    std::vector<std::uint8_t> alive;      // 1 if some class is still reachable from the state
    int num_states() const { return static_cast<int>(set_of.size()); }
  };

  // Builds both directions. Fails with kLimit if a product exceeds limits.max_states.
  static Result<Classifier> build(const std::vector<const PathClass*>& classes, const Limits& limits);

  int num_classes() const { return static_cast<int>(names_.size()); }
  const std::string& name(int i) const { return names_[static_cast<std::size_t>(i)]; }
  const Direction& forward() const { return fwd_; }
  const Direction& backward() const { return bwd_; }

  static int column(char c) { return kColumn[static_cast<unsigned char>(c)]; }
  static State step(const Direction& d, State s, char c) { return d.table[s + static_cast<State>(column(c))]; }
  static State step_letter(const Direction& d, State s, Letter l) { return d.table[s + l]; }

  // The class-set id of a whole path read forward; members() lists the classes in it.
  std::uint32_t classify(std::string_view path) const {
    State s = fwd_.start;
    for (char c : path) s = fwd_.table[s + static_cast<State>(column(c))];
    return fwd_.set_of[s / kStride];
  }
  // The same, reading the path backward from its last letter (must agree with classify()).
  std::uint32_t classify_backward(std::string_view path) const;
  std::uint32_t set_of(const Direction& d, State s) const { return d.set_of[s / kStride]; }
  bool alive(const Direction& d, State s) const { return d.alive[s / kStride] != 0; }
  const std::vector<int>& members(std::uint32_t set) const { return sets_[set]; }
  int num_sets() const { return static_cast<int>(sets_.size()); }

 private:
  static Result<Classifier> build_unbudgeted(const std::vector<const PathClass*>& classes, const Limits& limits);
  static const std::uint8_t kColumn[256];
  std::vector<std::string> names_;
  std::vector<std::vector<int>> sets_;  // class-set id -> sorted class indices; shared by both directions
  Direction fwd_, bwd_;
};

}  // namespace pathex
