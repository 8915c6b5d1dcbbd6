#include "core/error.h"

#include <cstdio>
#include <cstdlib>

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

void result_misuse(const char* what, const char* file, unsigned line) {
  if (line == 0 && file != nullptr && *file != '\0') std::fprintf(stderr, "pathex: internal error: %s: %s\n", what, file);
  else if (line == 0) std::fprintf(stderr, "pathex: internal error: %s (through operator* or ->)\n", what);
  else std::fprintf(stderr, "pathex: internal error: %s (%s:%u)\n", what, file, line);
  std::abort();
}

std::string excerpt(std::string_view text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return std::string(text);
  std::size_t cut = max_bytes;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // not inside a character
  return std::string(text.substr(0, cut)) + "…";
}

}  // namespace pathex
