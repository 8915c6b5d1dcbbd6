// The progress line `pathex trace` redraws on a terminal: "[####      ]  42.0%  1.23 M samples/s
// 12 s left". It is redrawn in place with a carriage return, which works only while the line is
// narrower than the terminal: a line that wraps leaves a new line behind at every update. So the
// line is fitted to the width: the rate goes first, then the time left, then the bar shrinks,
// and on the narrowest terminals only the percentage remains.
#pragma once

#include <string>

namespace pathex {

struct Progress {
  double fraction = 0;         // 0..1 of the render done
  double samples_per_s = 0;
  double seconds_left = 0;
};

// At most `columns - 1` characters (the last column stays free, so the cursor never wraps), no
// control characters; empty when columns < 8.
std::string progress_line(const Progress& p, int columns);

// "12 s", "3 min 05 s".
std::string format_seconds(double s);

}  // namespace pathex
