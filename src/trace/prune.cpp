#include "trace/prune.h"

namespace pathex {

Result<RequestedPaths> RequestedPaths::make(const std::vector<const PathClass*>& classes, const Limits& limits) {
  if (classes.empty()) return make_error(ErrorCode::kUsage, "no requested class");
  Result<Classifier> c = Classifier::build(classes, limits);
  if (!c) return c.error();
  RequestedPaths out;
  out.classifier_ = std::make_shared<const Classifier>(std::move(*c));
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
