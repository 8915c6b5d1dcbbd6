#include "io/input_file.h"

#include <zlib.h>

#include <algorithm>
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

bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f && static_cast<unsigned char>(bytes[1]) == 0x8b;
}

namespace {

// One inflate loop for both wrappers zlib knows: gzip (RFC 1952; members may follow each other, as
// gunzip reads them) and zlib (RFC 1950; one stream, the bytes after it are not read).
Result<std::string> inflate_bytes(std::string_view bytes, std::size_t max_bytes, const std::string& name, bool gzip) {
  const std::string what = gzip ? "gzip" : "zlib";
  auto error = [&](ErrorCode code, std::string message) {
    Error e = make_error(code, std::move(message));
    e.where = name;
    return e;
  };
  struct Stream {
    z_stream z{};
    bool open = false;
    ~Stream() {
      if (open) inflateEnd(&z);
    }
  } s;
  if (inflateInit2(&s.z, gzip ? 16 + MAX_WBITS : MAX_WBITS) != Z_OK) return error(ErrorCode::kBadFile, "cannot start zlib's inflate");
  s.open = true;
  std::string out;
  char block[1 << 16];
  std::size_t fed = 0;  // bytes of `bytes` handed to zlib so far (zlib counts in 32 bits)
  for (;;) {
    if (s.z.avail_in == 0 && fed < bytes.size()) {
      const std::size_t n = std::min<std::size_t>(bytes.size() - fed, std::size_t{1} << 30);
      s.z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + fed));
      s.z.avail_in = static_cast<uInt>(n);
      fed += n;
    }
    s.z.next_out = reinterpret_cast<Bytef*>(block);
    s.z.avail_out = sizeof block;
    const int r = inflate(&s.z, Z_NO_FLUSH);
    const std::size_t got = sizeof block - s.z.avail_out;
    if (got > max_bytes - out.size())
      return error(ErrorCode::kLimit, limit_message("the inflated " + what + " " + (gzip ? "file" : "stream"), max_bytes, "bytes", "--max-file-size"));
    out.append(block, got);
    const std::size_t left = bytes.size() - fed + s.z.avail_in;  // input not consumed yet
    if (r == Z_STREAM_END) {
      if (left == 0 || !gzip) return out;
      if (!is_gzip(bytes.substr(bytes.size() - left)))
        return error(ErrorCode::kBadFile, std::to_string(left) + " bytes after the end of the gzip stream, expected another gzip member or the end of the file");
      if (inflateReset(&s.z) != Z_OK) return error(ErrorCode::kBadFile, "cannot restart zlib's inflate");
      continue;
    }
    if (r == Z_BUF_ERROR && left == 0) return error(ErrorCode::kBadFile, "the " + what + " stream ends early (a truncated file?)");
    if (r != Z_OK && r != Z_BUF_ERROR)
      return error(ErrorCode::kBadFile, "not a valid " + what + " stream: " + (s.z.msg != nullptr ? std::string(s.z.msg) : "zlib error " + std::to_string(r)));
  }
}

}  // namespace

Result<std::string> gunzip(std::string_view bytes, std::size_t max_bytes, const std::string& name) {
  return inflate_bytes(bytes, max_bytes, name, /*gzip=*/true);
}

Result<std::string> inflate_zlib(std::string_view bytes, std::size_t max_bytes, const std::string& name) {
  return inflate_bytes(bytes, max_bytes, name, /*gzip=*/false);
}

}  // namespace pathex
