#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pathex {

Result<bool> write_file_atomic(const std::string& path, std::string_view bytes) {
  auto fail = [&](const std::string& what) {
    Error e = make_error(ErrorCode::kBadFile, what + ": " + std::strerror(errno));
    e.where = path;
    return e;
  };
  std::string tmp = path + ".tmp-XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) return fail("cannot create a temporary file beside the output");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      Error e = fail("cannot write");
      ::close(fd);
      ::unlink(tmp.c_str());
      return e;
    }
    done += static_cast<std::size_t>(n);
  }
  ::fchmod(fd, 0644);
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    Error e = fail("cannot flush");
    ::unlink(tmp.c_str());
    return e;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    Error e = fail("cannot rename the temporary file into place");
    ::unlink(tmp.c_str());
    return e;
  }
  return true;
}

}  // namespace pathex
