#include "io/input_file.h"

#include <filesystem>
#include <fstream>

#include "core/limits.h"

namespace pathex {

Result<std::string> read_input_file(const std::string& path, std::size_t max_bytes) {
  auto error = [&](ErrorCode code, std::string message) {
    Error e = make_error(code, std::move(message));
    e.where = path;
    return e;
  };
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return error(ErrorCode::kBadFile, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return error(ErrorCode::kBadFile, "cannot open the file for reading");
  // Read in blocks rather than trusting the size the file system reports: devices and pipes
  // report none.
  std::string out;
  char block[1 << 16];
  while (in) {
    in.read(block, sizeof block);
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got > max_bytes - out.size())
      return error(ErrorCode::kLimit, limit_message("the file", max_bytes, "bytes", "--max-file-size"));
    out.append(block, got);
  }
  if (in.bad()) return error(ErrorCode::kBadFile, "cannot read the file");
  return out;
}

}  // namespace pathex
