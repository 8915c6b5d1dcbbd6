// Reading an input file whole, with a size cap (Limits::max_file_bytes, --max-file-size): every
// file pathex reads (class files, profiles, check files, scenes, OBJ meshes) comes through here,
// so `/dev/zero` given as any of them stops at the cap with a message instead of growing until
// the machine runs out of memory.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "core/error.h"

namespace pathex {

// The bytes of `path`. Errors name the file: it cannot be opened, is a directory, or is larger
// than `max_bytes` (kLimit, naming --max-file-size).
Result<std::string> read_input_file(const std::string& path, std::size_t max_bytes);

// True when `bytes` start with the gzip magic (1f 8b).
bool is_gzip(std::string_view bytes);

// The inflated bytes of a gzip file (RFC 1952, through zlib; several members are concatenated, as
// gunzip does). Errors name `name`: a stream zlib refuses, one that ends early, bytes after the
// last member, or inflated bytes beyond `max_bytes` (kLimit, naming --max-file-size: the cap of a
// file read whole applies to what it inflates to, so a small bomb stops there).
Result<std::string> gunzip(std::string_view bytes, std::size_t max_bytes, const std::string& name);

// The inflated bytes of one zlib stream (RFC 1950: Mitsuba's serialized meshes), the bytes after
// its end not read; errors and the cap as gunzip's.
Result<std::string> inflate_zlib(std::string_view bytes, std::size_t max_bytes, const std::string& name);

}  // namespace pathex
