// The output folder as one set (see output_set.h): ownership check, staging, the exchange, and
// the signal shield.
#include "io/output_set.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "io/atomic_file.h"

namespace pathex {
namespace fs = std::filesystem;

namespace {

Error out_error(const std::string& dir, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = "--out " + dir;
  return e;
}

std::string errno_text() { return std::strerror(errno); }

std::string staging_prefix(const std::string& name) { return "." + name + ".pathex-staging-"; }

// The names a folder's manifest lists; nullopt without a manifest; an error for a manifest that
// names anything but plain file names.
Result<std::optional<std::set<std::string>>> read_manifest(const std::string& dir, const fs::path& folder) {
  std::ifstream in(folder / kManifestName);
  if (!in) return std::optional<std::set<std::string>>();
  std::set<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line == "." || line == ".." || line == kManifestName || line.find('/') != std::string::npos)
      return out_error(dir, "its manifest " + std::string(kManifestName) + " names '" + line +
                                "', which is not a file pathex writes; remove the folder or choose another --out");
    names.insert(line);
  }
  return std::optional<std::set<std::string>>(std::move(names));
}

// Whether `folder` holds only what its manifest lists (an empty folder qualifies): the files of
// the previous set, which a new set replaces; an error names the first file that is not.
Result<std::set<std::string>> owned_files(const std::string& dir, const fs::path& folder) {
  Result<std::optional<std::set<std::string>>> found = read_manifest(dir, folder);
  if (!found) return found.error();
  const std::optional<std::set<std::string>>& manifest = *found;
  std::set<std::string> listed = manifest ? *manifest : std::set<std::string>();
  std::error_code ec;
  std::vector<std::string> entries;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) entries.push_back(it->path().filename().string());
  if (ec) return out_error(dir, "cannot list the folder: " + ec.message());
  std::sort(entries.begin(), entries.end());
  for (const std::string& e : entries) {
    if (e == kManifestName) continue;
    const bool file = fs::is_regular_file(fs::symlink_status(folder / e, ec));
    if (!listed.count(e) || !file)
      return out_error(dir, "the folder holds '" + e + "', which pathex did not write there (" +
                                (manifest ? "it is not in the folder's " + std::string(kManifestName)
                                          : "the folder has no " + std::string(kManifestName)) +
                                "); pathex replaces only its own outputs: choose another --out folder, or empty this one");
  }
  return listed;
}

// Flushes a folder's entries (renames, new files) to disk.
void sync_dir(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

// Removes the files of a set (its manifest's and the manifest), then the folder. One thread a
// file: each unlink of a file written moments ago waited 3-5 ms for the file system's journal
// (ext4 here), 40-50 ms for a default render's eleven files one after the other; side by side
// they wait together (bench/README.md, issue 19, seventh session).
bool remove_set(const fs::path& folder, const std::set<std::string>& names) {
  std::vector<std::thread> threads;
  threads.reserve(names.size() + 1);
  for (const std::string& n : names) threads.emplace_back([path = folder / n] { ::unlink(path.c_str()); });
  threads.emplace_back([path = folder / kManifestName] { ::unlink(path.c_str()); });
  for (std::thread& t : threads) t.join();
  std::error_code ec;
  return fs::remove(folder, ec) && !ec;
}

// The two folders trade places: renameat2(RENAME_EXCHANGE) where the file system has it.
bool swap_folders(const fs::path& a, const fs::path& b) {
  return ::renameat2(AT_FDCWD, a.c_str(), AT_FDCWD, b.c_str(), RENAME_EXCHANGE) == 0;
}

}  // namespace

Result<OutputSet> OutputSet::prepare(const std::string& dir) {
  if (dir.empty()) return out_error(dir, "the output folder name is empty");
  std::error_code ec;
  fs::path abs = fs::absolute(dir, ec).lexically_normal();
  if (abs.has_parent_path() && abs.filename().empty()) abs = abs.parent_path();  // "out/" -> "out"
  const std::string name = abs.filename().string();
  if (name.empty() || name == "." || name == ".." || !abs.has_parent_path() || abs == abs.root_path())
    return out_error(dir, "cannot be a file system root; name a folder for the outputs");
  const fs::path cwd = fs::current_path(ec);
  if (!ec) {
    const fs::path rel = fs::weakly_canonical(cwd, ec).lexically_relative(fs::weakly_canonical(abs, ec));
    if (!rel.empty() && *rel.begin() != "..")
      return out_error(dir, "contains the current folder, which pathex would replace; name a folder of its own for the outputs");
  }
  OutputSet set;
  set.dir_ = dir;
  set.parent_ = abs.parent_path().string();
  set.name_ = name;

  const fs::file_status st = fs::status(abs, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) return out_error(dir, "exists and is not a folder");
    if (::access(abs.c_str(), W_OK | X_OK) != 0) return out_error(dir, "the folder is not writable: " + errno_text());
    if (Result<std::set<std::string>> owned = owned_files(dir, abs); !owned) return owned.error();
  }
  // The staging folder goes beside the output folder: its first existing ancestor must take a new
  // folder (probed by making one: permissions alone do not tell, e.g. under /proc).
  fs::path probe_in = abs.parent_path();
  while (!fs::exists(probe_in, ec) && probe_in.has_parent_path() && probe_in != probe_in.parent_path()) probe_in = probe_in.parent_path();
  if (!fs::is_directory(probe_in, ec)) return out_error(dir, probe_in.string() + " is not a folder");
  // Named like a staging folder, so that a probe left by SIGKILL is cleared like one.
  {
    const SignalShield shield;
    std::string probe = (probe_in / (staging_prefix(name) + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (::mkdtemp(probe.data()) == nullptr)
      return out_error(dir, "cannot create the output folder in " + probe_in.string() + ": " + errno_text());
    ::rmdir(probe.c_str());
  }

  // Staging folders of runs that were killed while writing (their process is gone).
  const std::string prefix = staging_prefix(name);
  for (fs::directory_iterator it(abs.parent_path(), ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(entry.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
  return set;
}

Result<bool> OutputSet::write(const std::function<Result<bool>(const std::string& staging)>& write_files) {
  const fs::path parent(parent_), target = fs::path(parent_) / name_;
  std::error_code ec;
  // Checked again: the folder may have changed during the render.
  std::set<std::string> previous;
  const bool replacing = fs::exists(target, ec);
  if (replacing) {
    if (!fs::is_directory(target, ec)) return out_error(dir_, "exists and is not a folder");
    Result<std::set<std::string>> owned = owned_files(dir_, target);
    if (!owned) return owned.error();
    previous = std::move(*owned);
  }
  fs::create_directories(parent, ec);
  if (ec) return out_error(dir_, "cannot create the folder " + parent_ + ": " + ec.message());

  std::string staging = (parent / (staging_prefix(name_) + std::to_string(::getpid()) + "-XXXXXX")).string();
  if (::mkdtemp(staging.data()) == nullptr) return out_error(dir_, "cannot create a staging folder in " + parent_ + ": " + errno_text());
  ::chmod(staging.c_str(), 0755);
  auto abandon = [&](Error e) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    return e;
  };
  {
    // The files are flushed to disk together, once all are written (io/atomic_file.h).
    const DeferredSync together(staging);
    if (Result<bool> w = write_files(staging); !w) return abandon(w.error());

    // --- the manifest: every file staged ---
    std::vector<std::string> names;
    for (fs::directory_iterator it(staging, ec), end; !ec && it != end; it.increment(ec)) names.push_back(it->path().filename().string());
    if (ec) return abandon(out_error(dir_, "cannot list the staging folder: " + ec.message()));
    std::sort(names.begin(), names.end());
    std::string manifest = "# pathex output set: the files pathex wrote here. A new run replaces exactly these.\n";
    for (const std::string& n : names) manifest += n + "\n";
    if (Result<bool> w = write_file_atomic(staging + "/" + kManifestName, manifest); !w) return abandon(w.error());
    names.push_back(kManifestName);
    if (Result<bool> s = sync_files(staging, names); !s) return abandon(s.error());
  }
  sync_dir(staging);

  // --- in place, in one step ---
  if (!replacing) {
    if (std::rename(staging.c_str(), target.c_str()) != 0)
      return abandon(out_error(dir_, "cannot move the staging folder into place: " + errno_text()));
    sync_dir(parent);
    return true;
  }
  fs::path old = staging;  // after the exchange the staging name holds the previous set
  if (!swap_folders(staging, target)) {
    if (errno != EINVAL && errno != ENOSYS) return abandon(out_error(dir_, "cannot put the new outputs in place: " + errno_text()));
    // No RENAME_EXCHANGE here: the previous set moves aside first (onto an empty folder, which
    // rename replaces), then the new one into place.
    std::string aside = (parent / ("." + name_ + ".pathex-old-" + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (::mkdtemp(aside.data()) == nullptr || std::rename(target.c_str(), aside.c_str()) != 0)
      return abandon(out_error(dir_, "cannot move the previous outputs aside: " + errno_text()));
    if (std::rename(staging.c_str(), target.c_str()) != 0) {
      const Error e = out_error(dir_, "cannot move the staging folder into place: " + errno_text());
      std::rename(aside.c_str(), target.c_str());
      return abandon(e);
    }
    old = aside;
  }
  sync_dir(parent);
  if (!remove_set(old, previous))
    return out_error(dir_, "the new outputs are in place, but the previous set could not be removed from " + old.string());
  return true;
}

// --- signals ---

namespace {
constexpr std::array<int, 4> kShielded = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
std::atomic<int> g_held_signal{0};
extern "C" void hold_signal(int sig) {
  int none = 0;
  g_held_signal.compare_exchange_strong(none, sig);
}
}  // namespace

SignalShield::SignalShield() {
  g_held_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = hold_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (std::size_t i = 0; i < kShielded.size(); ++i) sigaction(kShielded[i], &sa, &old_[i]);
}

SignalShield::~SignalShield() {
  for (std::size_t i = 0; i < kShielded.size(); ++i) sigaction(kShielded[i], &old_[i], nullptr);
  if (const int sig = g_held_signal.exchange(0); sig != 0) ::raise(sig);
}

}  // namespace pathex
