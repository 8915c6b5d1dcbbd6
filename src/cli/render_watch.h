// What `trace` and `bias` show and catch while they render: the progress line on a terminal
// (io/progress.h: rate and time left, fitted to the terminal's width), Ctrl-C and SIGTERM (how
// mpirun stops the other ranks when one fails) and a time limit, which stop the render after the
// current chunk of passes so that what was rendered can still be written, marked incomplete.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

namespace pathex::cli {

class RenderWatch {
 public:
  // Shows progress on stderr when `show` and stderr is a terminal; catches SIGINT and SIGTERM;
  // stops the render after `time_limit` seconds (0: no limit).
  explicit RenderWatch(bool show, double time_limit = 0);
  // Clears the progress line and gives SIGINT and SIGTERM their defaults back.
  ~RenderWatch();
  RenderWatch(const RenderWatch&) = delete;
  RenderWatch& operator=(const RenderWatch&) = delete;

  // For RenderOptions::progress and RenderOptions::cancel. The flag outlives the watch (it tells
  // afterwards whether the render was stopped).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress() const;
  const std::atomic<bool>* cancel() const;

 private:
  bool show_ = false;
  double time_limit_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace pathex::cli
