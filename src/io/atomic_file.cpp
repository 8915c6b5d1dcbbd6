#include "io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>

namespace pathex {
namespace {

// Bytes gathered per write(): enough to make the system calls cheap, small enough that its fresh
// pages (a first touch costs ~10 µs on the development VM) do not matter; allocated once.
constexpr std::size_t kBuffer = std::size_t{1} << 18;

// The folders of the live DeferredSyncs.
std::mutex g_deferred_mutex;
std::vector<std::string> g_deferred;

// Whether `path` names a file directly in a deferred folder.
bool deferred(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  if (slash == std::string::npos) return false;
  const std::string_view folder(path.data(), slash);
  const std::lock_guard<std::mutex> lock(g_deferred_mutex);
  return std::find(g_deferred.begin(), g_deferred.end(), folder) != g_deferred.end();
}

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
  if (in_file == 0) return;
  // The part in the file waits in patch_ while the next piece continues it (it lies below what
  // is written, so later appends do not touch it).
  if (!patch_.empty() && offset != patch_at_ + patch_.size()) flush_patch();
  if (patch_.empty()) patch_at_ = offset;
  patch_.append(bytes.data(), in_file);
}

void AtomicFile::flush_patch() {
  for (std::size_t done = 0; done < patch_.size() && !error_;) {
    const ssize_t n = ::pwrite(fd_, patch_.data() + done, patch_.size() - done, static_cast<off_t>(patch_at_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot write");
    done += static_cast<std::size_t>(n);
  }
  patch_.clear();
}

Result<bool> AtomicFile::commit() {
  if (!error_) flush_patch();
  if (!error_) flush();
  if (error_) return *error_;
  ::fchmod(fd_, 0644);
  const int fd = fd_;
  fd_ = -1;
  // In a deferred folder the write-back starts now and the owner waits for it (sync_files).
  const bool later = deferred(path_);
  if (later) ::sync_file_range(fd, 0, 0, SYNC_FILE_RANGE_WRITE);
  if ((!later && ::fsync(fd) != 0) || ::close(fd) != 0) {
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

DeferredSync::DeferredSync(std::string folder) : folder_(std::move(folder)) {
  const std::lock_guard<std::mutex> lock(g_deferred_mutex);
  g_deferred.push_back(folder_);
}

DeferredSync::~DeferredSync() {
  const std::lock_guard<std::mutex> lock(g_deferred_mutex);
  g_deferred.erase(std::find(g_deferred.begin(), g_deferred.end(), folder_));
}

Result<bool> sync_files(const std::string& folder, const std::vector<std::string>& names) {
  // One thread a file: waiting side by side, the flushes share the file system's journal commits
  // and the disk's cache flushes (one after the other, each waited for its own: 2-8 ms apiece).
  std::vector<std::optional<Error>> errors(names.size());
  std::vector<std::thread> threads;
  threads.reserve(names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
    threads.emplace_back([&, i] {
      const std::string path = folder + "/" + names[i];
      const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
      if (fd < 0 || ::fsync(fd) != 0) {
        errors[i] = make_error(ErrorCode::kBadFile, std::string("cannot flush: ") + std::strerror(errno));
        errors[i]->where = path;
      }
      if (fd >= 0) ::close(fd);
    });
  for (std::thread& t : threads) t.join();
  for (const std::optional<Error>& e : errors)
    if (e) return *e;
  return true;
}

Result<bool> write_file_atomic(const std::string& path, std::string_view bytes) {
  AtomicFile file(path);
  file.append(bytes);
  return file.commit();
}

}  // namespace pathex
