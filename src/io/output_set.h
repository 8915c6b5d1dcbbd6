// An output folder written as one set, whole or not at all (DESIGN §12), for `pathex trace --out`.
//
// The set's files are written into a staging folder beside the output folder, then the two
// folders trade places in one step (renameat2 RENAME_EXCHANGE; two renames where the file system
// lacks it) and the previous set is deleted. Readers of the folder therefore see the old set or
// the new one, never a mix, and a failure at any step leaves the old set as it was.
//
// The folder belongs to pathex: it holds a manifest (`.pathex-manifest`, one file name a line)
// of what pathex wrote, so that a new set replaces exactly the files of the old one and no stale
// layer survives. A folder with anything the manifest does not list (or without a manifest) is
// refused, naming the first such file: pathex never deletes what it did not write.
//
// Signals: a SignalShield holds back SIGINT, SIGTERM, SIGHUP and SIGQUIT while the set is written
// and put in place; one that arrives then takes effect once the set is complete. Only SIGKILL (or a
// crash) can stop the write phase; it leaves the old set in place and a staging folder
// `.NAME.pathex-staging-PID-XXXXXX` beside it, which the next run for that folder removes.
#pragma once

#include <csignal>
#include <functional>
#include <string>

#include "core/error.h"

namespace pathex {

inline constexpr const char* kManifestName = ".pathex-manifest";

class OutputSet {
 public:
  // Before any work: checks that `dir` can receive a set (it is a folder pathex owns, or does not
  // exist and its parent is a writable folder) and removes stale staging folders of dead runs.
  // Creates nothing. Errors name `dir` and what to do.
  static Result<OutputSet> prepare(const std::string& dir);

  // Creates the staging folder, calls `write(staging_folder)` to write the set's files into it,
  // lists them in the manifest and puts the set in place of the folder's previous contents. On
  // an error from `write` or any step the staging folder is removed and the old set stays.
  Result<bool> write(const std::function<Result<bool>(const std::string& staging)>& write_files);

  const std::string& dir() const { return dir_; }

 private:
  OutputSet() = default;
  std::string dir_;     // as given
  std::string parent_;  // the folder that holds it
  std::string name_;    // its last component
};

// Holds back the signals that end a process by default (SIGINT, SIGTERM, SIGHUP, SIGQUIT) for its
// lifetime: a handler (process-wide, whichever thread receives the signal) records the first,
// and the destructor restores the previous dispositions and raises it again. Not nested.
class SignalShield {
 public:
  SignalShield();
  ~SignalShield();
  SignalShield(const SignalShield&) = delete;
  SignalShield& operator=(const SignalShield&) = delete;

 private:
  struct sigaction old_[4];
};

}  // namespace pathex
