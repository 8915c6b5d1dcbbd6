// Class files: JSON documents that name path classes (schema: grammar/classes.schema.json).
//
//   {"classes": [{"name": "caustic", "expr": "L..S+D.*..E", "description": "…"},
//                {"name": "glass", "expr": "$caustic & L.*SS.*E"},
//                {"name": "mirror-classic", "expr": "LSDE", "notation": "heckbert"}]}
//
// "render": true on entries makes `pathex trace` and `converge` estimate only those classes (as
// --only does; DESIGN §11): the other classes are reported "not rendered".
//
// Entries are compiled in order; each may refer to the built-ins and to the entries before it.
// Errors name the file and the JSON pointer of the offending value.
#pragma once

#include <string>

#include "classify/pathclass.h"
#include "core/error.h"

namespace pathex {

// Parses `text` (the contents of `filename`) into `table`. `options` gives limits, notation and
// end types for entries that do not override them.
Result<bool> load_class_file(const std::string& text, const std::string& filename, const ClassOptions& options,
                             ClassTable* table);
// Reads the file (at most options.limits.max_file_bytes), then load_class_file.
Result<bool> read_class_file(const std::string& filename, const ClassOptions& options, ClassTable* table);

}  // namespace pathex
