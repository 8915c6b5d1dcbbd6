// What `trace` and `bias` show and catch while they render: the progress line on a terminal
// (io/progress.h: rate and time left, fitted to the terminal's width) and Ctrl-C, which stops the
// render after the current chunk of passes so that what was rendered can still be written.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>

namespace pathex::cli {

class RenderWatch {
 public:
  // Shows progress on stderr when `show` and stderr is a terminal; catches SIGINT.
  explicit RenderWatch(bool show);
  // Clears the progress line and gives SIGINT its default back.
  ~RenderWatch();
  RenderWatch(const RenderWatch&) = delete;
  RenderWatch& operator=(const RenderWatch&) = delete;

  // For RenderOptions::progress (empty when not shown) and RenderOptions::cancel.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress() const;
  const std::atomic<bool>* cancel() const;

 private:
  bool show_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace pathex::cli
