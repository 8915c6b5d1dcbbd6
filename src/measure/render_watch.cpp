#include "measure/render_watch.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <ctime>

#include "io/progress.h"

namespace pathex {
namespace {

std::atomic<bool> g_cancel{false};     // what render() polls: a signal or the time limit
std::atomic<bool> g_signalled{false};  // a signal alone
extern "C" void on_stop(int) {
  g_signalled.store(true);
  g_cancel.store(true);
}

// The terminal's width in columns (stderr's), or 80 when it does not say.
int terminal_columns() {
  winsize w{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0) return w.ws_col;
  return 80;
}

}  // namespace

double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

RenderWatch::RenderWatch(bool show, double time_limit)
    : show_(show && ::isatty(STDERR_FILENO)), time_limit_(time_limit), start_(std::chrono::steady_clock::now()) {
  g_cancel.store(false);
  g_signalled.store(false);
  std::signal(SIGINT, on_stop);
  std::signal(SIGTERM, on_stop);
}

RenderWatch::~RenderWatch() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (show_) std::fprintf(stderr, "\r%*s\r", std::max(terminal_columns() - 1, 0), "");
}

std::function<void(std::uint64_t, std::uint64_t)> RenderWatch::progress() const {
  if (!show_ && time_limit_ <= 0) return {};
  return [start = start_, show = show_, limit = time_limit_](std::uint64_t done, std::uint64_t total) {
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (limit > 0 && el >= limit) g_cancel.store(true);
    if (!show) return;
    Progress p;
    p.fraction = total ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
    p.samples_per_s = el > 0 ? static_cast<double>(done) / el : 0.0;
    p.seconds_left = p.fraction > 0 ? el / p.fraction - el : 0;
    // Padded to the width it was fitted to, so a shorter line covers a longer one.
    const int columns = terminal_columns();
    std::fprintf(stderr, "\r%-*s", std::max(columns - 1, 0), progress_line(p, columns).c_str());
    std::fflush(stderr);
  };
}

void RenderWatch::restart(double time_limit) {
  time_limit_ = time_limit;
  start_ = std::chrono::steady_clock::now();
  g_cancel.store(g_signalled.load());
}

const std::atomic<bool>* RenderWatch::cancel() const { return &g_cancel; }

bool RenderWatch::interrupted() const { return g_signalled.load(); }

}  // namespace pathex
