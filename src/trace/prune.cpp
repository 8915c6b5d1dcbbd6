// The tracer's side of --only (trace/prune.h): whether a sampled path is recorded, and whether a
// growing subpath can still complete to a requested class, read off the classifier's automata so
// that what is pruned is exactly what no requested class contains (DESIGN §11).
#include "trace/prune.h"

#include <algorithm>

namespace pathex {

Result<RequestedPaths> RequestedPaths::make(const std::vector<const PathClass*>& classes, const Limits& limits) {
  if (classes.empty()) return make_error(ErrorCode::kUsage, "no requested class");
  Result<Classifier> c = Classifier::build(classes, limits);
  if (!c) return c.error();
  RequestedPaths out;
  out.classifier_ = std::make_shared<const Classifier>(std::move(*c));
  // The lengths of the requested paths: the live states after L and n letters, breadth first.
  const Classifier& cl = *out.classifier_;
  const Classifier::Direction& d = cl.forward();
  std::vector<Classifier::State> now = {Classifier::step(d, d.start, 'L')}, next;
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(d.num_states()));
  for (int n = 0; n <= accel::kMaxPackedLetters; ++n) {
    bool any = false;
    for (const Classifier::State s : now) any = any || !cl.members(cl.set_of(d, Classifier::step(d, s, 'E'))).empty();
    out.lengths_.push_back(any ? 1 : 0);
    std::fill(seen.begin(), seen.end(), 0);
    next.clear();
    for (const Classifier::State s : now)
      for (const char letter : {'S', 'D'}) {
        const Classifier::State t = Classifier::step(d, s, letter);
        if (cl.alive(d, t) && seen[t / Classifier::kStride] == 0) {
          seen[t / Classifier::kStride] = 1;
          next.push_back(t);
        }
      }
    now.swap(next);
  }
  return out;
}

bool RequestedPaths::first_vertex_specular(char pos, char dir) const {
  const Classifier::Direction& d = classifier_->forward();
  Classifier::State s = Classifier::step(d, d.start, 'L');
  s = Classifier::step(d, s, pos);
  s = Classifier::step(d, s, dir);
  return !classifier_->alive(d, Classifier::step(d, s, 'D'));
}

void SubpathPrefix::start(const RequestedPaths& only, bool light, char pos, char dir) {
  const Classifier& c = only.classifier();
  d_ = light ? &c.forward() : &c.backward();
  s_ = Classifier::step(*d_, d_->start, light ? 'L' : 'E');
  s_ = Classifier::step(*d_, s_, pos);
  step(dir);
}

void SubpathPrefix::step(char letter) {
  s_ = Classifier::step(*d_, s_, letter);
  alive_ = d_->alive[s_ / Classifier::kStride] != 0;
}

}  // namespace pathex
