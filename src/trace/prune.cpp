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

}  // namespace pathex
