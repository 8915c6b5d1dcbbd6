#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pathex {
namespace {

// Bytes gathered per write(): enough to make the system calls cheap, small enough that its fresh
// pages (a first touch costs ~10 µs on the development VM) do not matter; allocated once.
constexpr std::size_t kBuffer = std::size_t{1} << 18;

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), tmp_(path_ + ".tmp-XXXXXX") {
  fd_ = ::mkstemp(tmp_.data());
  if (fd_ < 0) fail("cannot create a temporary file beside the output");
}

AtomicFile::~AtomicFile() {
  if (fd_ < 0) return;  // never created, or commit() closed it
  ::close(fd_);
  ::unlink(tmp_.c_str());
}

void AtomicFile::fail(const std::string& what) {
  if (error_) return;
  error_ = make_error(ErrorCode::kBadFile, what + ": " + std::strerror(errno));
  error_->where = path_;
}

void AtomicFile::append(std::string_view bytes) {
  if (error_) return;
  size_ += bytes.size();
  if (buffer_.size() + bytes.size() > kBuffer) flush();
  if (bytes.size() >= kBuffer) {  // large pieces go straight to the file
    for (std::size_t done = 0; done < bytes.size() && !error_;) {
      const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return fail("cannot write");
      done += static_cast<std::size_t>(n);
    }
    return;
  }
  if (buffer_.capacity() < kBuffer) buffer_.reserve(kBuffer);
  buffer_.append(bytes);
}

void AtomicFile::flush() {
  for (std::size_t done = 0; done < buffer_.size() && !error_;) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot write");
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void AtomicFile::write_at(std::uint64_t offset, std::string_view bytes) {
  if (error_) return;
  const std::uint64_t written = size_ - buffer_.size();  // bytes already in the file
  // The part that is still in the buffer is overwritten there.
  for (std::size_t i = 0; i < bytes.size(); ++i)
    if (offset + i >= written && offset + i < size_) buffer_[static_cast<std::size_t>(offset + i - written)] = bytes[i];
  const std::size_t in_file = static_cast<std::size_t>(std::min<std::uint64_t>(bytes.size(), written > offset ? written - offset : 0));
  for (std::size_t done = 0; done < in_file && !error_;) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, in_file - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot write");
    done += static_cast<std::size_t>(n);
  }
}

Result<bool> AtomicFile::commit() {
  if (!error_) flush();
  if (error_) return *error_;
  ::fchmod(fd_, 0644);
  const int fd = fd_;
  fd_ = -1;
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    fail("cannot flush");
    ::unlink(tmp_.c_str());
    return *error_;
  }
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) {
    fail("cannot rename the temporary file into place");
    ::unlink(tmp_.c_str());
    return *error_;
  }
  return true;
}

Result<bool> write_file_atomic(const std::string& path, std::string_view bytes) {
  AtomicFile file(path);
  file.append(bytes);
  return file.commit();
}

}  // namespace pathex
