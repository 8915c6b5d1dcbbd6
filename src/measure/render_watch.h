// What a command shows and catches while it renders (`trace`, `bias`, each rung of `converge`):
// the progress line on a terminal (io/progress.h: rate and time left, fitted to the terminal's
// width), Ctrl-C and SIGTERM (how mpirun stops the other ranks when one fails) and a time limit,
// which stop the render after the current chunk of passes so that what was rendered can still be
// written, marked incomplete. Also the one CPU clock that every command's "cpu s" is read from.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

namespace pathex {

// CPU seconds used by this process so far, all threads (CLOCK_PROCESS_CPUTIME_ID).
double process_cpu_seconds();

class RenderWatch {
 public:
  // Shows progress on stderr when `show` and stderr is a terminal; catches SIGINT and SIGTERM;
  // stops the render after `time_limit` seconds (0: no limit).
  explicit RenderWatch(bool show, double time_limit = 0);
  // Clears the progress line and gives SIGINT and SIGTERM their defaults back.
  ~RenderWatch();
  RenderWatch(const RenderWatch&) = delete;
  RenderWatch& operator=(const RenderWatch&) = delete;

  // The next render under the same watch (a ladder's next rung): its clock and `time_limit` (0: no
  // limit) start now; a signal caught before stops it at once.
  void restart(double time_limit);

  // For RenderOptions::progress and RenderOptions::cancel. The flag outlives the watch (it tells
  // afterwards whether the render was stopped).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress() const;
  const std::atomic<bool>* cancel() const;
  // Whether a signal (not the time limit) stopped the renders.
  bool interrupted() const;

 private:
  bool show_ = false;
  double time_limit_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace pathex
