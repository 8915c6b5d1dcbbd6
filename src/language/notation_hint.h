// A hint for Heckbert strings typed in full notation. `LSDE`, `LDSDE` and `LS+DE` are classic
// Heckbert classes, but in full notation (two letters for the light, two for the sensor) the first
// two match no path and the third only paths from a laser into an orthographic sensor. When a
// full-notation class is empty, or every member starts from a laser or ends in a spot meter (the
// types nobody means by accident), and the same text read as Heckbert notation is not empty, the
// user most likely meant Heckbert's notation: the CLI prints this one-line hint on stderr.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "classify/pathclass.h"

namespace pathex {

// The hint's text (without "pathex: hint: "), or nullopt when there is nothing to say.
std::optional<std::string> heckbert_hint(std::string_view text, const PathClass& cls, const ClassOptions& options,
                                         const ClassTable* names);

}  // namespace pathex
