#include "io/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pathex {

std::string format_seconds(double s) {
  char buf[48];
  if (!std::isfinite(s) || s < 0) s = 0;
  if (s < 60) std::snprintf(buf, sizeof buf, "%.0f s", s);
  else std::snprintf(buf, sizeof buf, "%.0f min %02.0f s", std::floor(s / 60), std::fmod(s, 60));
  return buf;
}

std::string progress_line(const Progress& p, int columns) {
  const int room = columns - 1;
  if (room < 7) return "";
  const double f = std::clamp(std::isfinite(p.fraction) ? p.fraction : 0.0, 0.0, 1.0);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%5.1f%%", 100 * f);
  const std::string percent = buf;
  std::snprintf(buf, sizeof buf, "  %.2f M samples/s", std::isfinite(p.samples_per_s) ? p.samples_per_s * 1e-6 : 0.0);
  const std::string rate = buf;
  const std::string left = "  " + format_seconds(p.seconds_left) + " left";
  auto bar = [&](int inner) {
    const int filled = static_cast<int>(f * inner);
    return "[" + std::string(static_cast<std::size_t>(filled), '#') + std::string(static_cast<std::size_t>(inner - filled), ' ') + "] ";
  };
  constexpr int kFullBar = 30, kSmallestBar = 10;
  // From the richest line to the barest: drop the rate, then the time left, then shrink the bar.
  for (const std::string& tail : {rate + left, left, std::string()}) {
    const int fixed = static_cast<int>(percent.size() + tail.size()) + 3;  // "[", "] "
    const int inner = std::min(kFullBar, room - fixed);
    if (inner >= kSmallestBar) return bar(inner) + percent + tail;
  }
  return percent;
}

}  // namespace pathex
