// Output files are written whole or not at all: the bytes go to a temporary file beside the
// target, are flushed to disk, and the temporary is renamed over the target (rename is atomic
// within a directory). A failure at any step removes the temporary and reports the path.
#pragma once

#include <string>
#include <string_view>

#include "core/error.h"

namespace pathex {

Result<bool> write_file_atomic(const std::string& path, std::string_view bytes);

}  // namespace pathex
