// Reading an input file whole, with a size cap (Limits::max_file_bytes, --max-file-size): every
// file pathex reads (class files, profiles, check files, scenes, OBJ meshes) comes through here,
// so `/dev/zero` given as any of them stops at the cap with a message instead of growing until
// the machine runs out of memory.
#pragma once

#include <cstddef>
#include <string>

#include "core/error.h"

namespace pathex {

// The bytes of `path`. Errors name the file: it cannot be opened, is a directory, or is larger
// than `max_bytes` (kLimit, naming --max-file-size).
Result<std::string> read_input_file(const std::string& path, std::size_t max_bytes);

}  // namespace pathex
