#include "core/limits.h"

namespace pathex {

std::string limit_message(const std::string& what, std::size_t limit, const std::string& unit,
                          const std::string& option) {
  return what + " exceeds the limit of " + std::to_string(limit) + " " + unit + " (raise it with " + option + ")";
}

}  // namespace pathex
