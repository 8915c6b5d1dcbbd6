#include "core/error.h"

namespace pathex {

std::string Error::render() const {
  std::string out;
  if (!where.empty()) out += where + ": ";
  if (column > 0) out += "column " + std::to_string(column) + ": ";
  out += message;
  if (!source.empty()) {
    out += "\n  " + source + "\n  ";
    // The caret sits under the offending character; columns past the end point just after it.
    for (int i = 1; i < column; ++i) out += (i - 1 < static_cast<int>(source.size()) && source[i - 1] == '\t') ? '\t' : ' ';
    out += '^';
  }
  return out;
}

}  // namespace pathex
