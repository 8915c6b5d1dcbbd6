// The counts of a split sample (trace/accel/first_vertex_split.h) and a render's map of them per
// pixel (`pathex trace --splits auto`, chosen by trace/accel/split_plan.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pathex::tracer {

// A sample's camera rays (M) and the runs after each one's first hit (N): M·N runs, each weighted 1/(M·N).
struct SplitCounts {
  int cameras = 1;
  int runs = 1;
  friend bool operator==(const SplitCounts&, const SplitCounts&) = default;
};

// Counts per pixel, row-major from the top row.
struct SplitMap {
  int width = 0, height = 0;
  std::vector<SplitCounts> counts;
  SplitCounts at(int x, int y) const {
    return counts[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)];
  }
};

}  // namespace pathex::tracer
