// Output files are written whole or not at all: the bytes go to a temporary file beside the
// target, are flushed to disk, and the temporary is renamed over the target (rename is atomic
// within a directory). A failure at any step removes the temporary and reports the path.
//
// AtomicFile streams a file's bytes as they are made (the shard file, the EXR), so that a large
// output is never held in memory whole: a 512 × 512 render with twenty class layers held ~70 MB
// of EXR and ~40 MB of shard bytes, whose first touches and growth copies cost page faults.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace pathex {

Result<bool> write_file_atomic(const std::string& path, std::string_view bytes);

class AtomicFile {
 public:
  // Creates the temporary beside `path`; ok() says whether that worked.
  explicit AtomicFile(std::string path);
  ~AtomicFile();  // removes the temporary unless committed
  // Appended bytes wait in a buffer of up to 256 KiB; larger pieces are written at once.
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // The first error (creating, writing), if any; every call after it does nothing.
  bool ok() const { return !error_; }
  // Appends at the end (buffered).
  void append(std::string_view bytes);
  // Writes over bytes already appended, at `offset` (a header field known only at the end).
  // Pieces that continue one another are gathered into one write: OpenEXR writes its table of
  // line offsets eight bytes at a time (a 256-line image: 256 pwrite calls).
  void write_at(std::uint64_t offset, std::string_view bytes);
  std::uint64_t size() const { return size_; }
  // Flushes to disk and renames the temporary over the path, or returns the first error.
  Result<bool> commit();

 private:
  void flush();
  void flush_patch();
  void fail(const std::string& what);

  std::string path_, tmp_;
  int fd_ = -1;
  std::string buffer_;  // appended bytes not yet written
  std::string patch_;   // write_at bytes for the file not yet written, from patch_at_
  std::uint64_t patch_at_ = 0;
  std::uint64_t size_ = 0;
  std::optional<Error> error_;
};

// A folder whose files are flushed to disk together (io/output_set.h: a set is put in place only
// after every file of it is on disk). While a DeferredSync for `folder` lives, commit() of a file
// directly in that folder starts its write-back (sync_file_range) instead of waiting for it
// (fsync), then renames it; the owner calls sync_files() once every file is written. Each fsync
// waited for a journal commit of its own: a 256 x 256 render's twelve files spent 60-90 ms of wall
// time in them, one after the other; started as each file is done and waited for together at the
// end, the first commit carries them all (bench/README.md, issue 19). Folders may be deferred from
// several threads; each DeferredSync removes only its own.
class DeferredSync {
 public:
  explicit DeferredSync(std::string folder);
  ~DeferredSync();
  DeferredSync(const DeferredSync&) = delete;
  DeferredSync& operator=(const DeferredSync&) = delete;

 private:
  std::string folder_;
};

// Flushes each file `folder`/name to disk; the first failure names its file.
Result<bool> sync_files(const std::string& folder, const std::vector<std::string>& names);

}  // namespace pathex
