// Rendering only the requested classes (pathex trace --only, DESIGN §11), as the tracer sees it:
// which sampled paths are recorded, and when a subpath stops growing because no requested class
// can be completed from it any more (a dead state of the classifier's forward automaton for light
// subpaths, of its backward automaton for eye subpaths). Separate from Russian roulette: a dead
// subpath's extensions belong to no requested class, so stopping it changes no requested
// estimate; it only saves their rays.
#pragma once

#include <memory>
#include <vector>

#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "trace/accel/path_ids.h"

namespace pathex {

class RequestedPaths {
 public:
  // The union of `classes` (at least one) is what is recorded.
  static Result<RequestedPaths> make(const std::vector<const PathClass*>& classes, const Limits& limits);

  // Whether a sampled path (packed full-path string) is in a requested class.
  bool records(accel::PathKey key) const {
    const Classifier::Direction& d = classifier_->forward();
    Classifier::State s = Classifier::step(d, d.start, 'L');
    const int n = accel::packed_length(key);
    for (int i = 0; i < n; ++i) s = Classifier::step(d, s, accel::packed_is_d(key, i) ? 'D' : 'S');
    s = Classifier::step(d, s, 'E');
    return !classifier_->members(classifier_->set_of(d, s)).empty();
  }

  // Whether every requested path that starts at a light with letters c0 c1 = `pos` `dir` has a
  // specular first vertex: after L c0 c1 the letter D (a diffuse first vertex, or the first letter
  // of a pinhole or a lens, the light seen directly) leaves no requested class to complete. Then a
  // light subpath's first ray matters only where it meets a shape with a specular component
  // (trace/emission_cones.h).
  bool first_vertex_specular(char pos, char dir) const;

  // Whether some requested path has `n` letters between L and E (c0 … c(k+2)): a join whose path
  // would have another length is not made (Integrator::connect). Lengths past the table: true.
  bool has_length(int n) const {
    return n < 0 || static_cast<std::size_t>(n) >= lengths_.size() || lengths_[static_cast<std::size_t>(n)] != 0;
  }

  const Classifier& classifier() const { return *classifier_; }

 private:
  std::shared_ptr<const Classifier> classifier_;
  std::vector<std::uint8_t> lengths_;  // lengths_[n]: has_length(n), for n up to a packed key's longest
};

// A subpath's letters so far, read from its end vertex (a light subpath forward from L c0 c1, an
// eye subpath backward from E c(k+2) c(k+1)), for the dead-state test. Without requested classes
// (null) every subpath is alive.
class SubpathPrefix {
 public:
  // `pos` and `dir`: the end vertex's two letters (c0 c1 of a light; c(k+2) c(k+1) of a sensor).
  // Inline, the walk pays a test of `only` here and one per vertex; the stepping is out of line,
  // so that the walk's own code (and what the compiler inlines into it) is as without --only.
  SubpathPrefix(const RequestedPaths* only, bool light, char pos, char dir) {
    if (only != nullptr) [[unlikely]] start(*only, light, pos, dir);
  }
  // Whether some requested class can still be completed from the letters read.
  bool alive() const { return alive_; }
  // Reads the letter of the subpath's newest vertex (the scattering event sampled there).
  void extend(char letter) {
    if (d_ != nullptr) [[unlikely]] step(letter);
  }

 private:
  void start(const RequestedPaths& only, bool light, char pos, char dir);
  void step(char letter);
  const Classifier::Direction* d_ = nullptr;
  Classifier::State s_ = 0;
  bool alive_ = true;
};

}  // namespace pathex
