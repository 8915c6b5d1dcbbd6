// The figure of `pathex converge`: per class, a log-log panel of error against CPU time with one
// line per renderer (its true error, solid with markers, and its reported standard error, dotted,
// in the same colour) and a grey dashed 1/√t guide. Drawn with cairo (Debian libcairo2-dev) and
// encoded in memory as SVG and PNG, so the caller writes each file whole (io/atomic_file.h).
#pragma once

#include <string>
#include <vector>

#include "core/error.h"

namespace pathex {

struct PlotSeries {
  std::string name;               // the renderer
  std::vector<double> time;       // CPU seconds per rung
  std::vector<double> error;      // |estimate − reference|; non-positive values are not drawn
  std::vector<double> std_error;  // reported; non-positive or NaN values are not drawn
};

struct PlotPanel {
  std::string title;  // the class
  std::vector<PlotSeries> series;
};

struct PlotFiles {
  std::string svg;
  std::string png;
};

// Both encodings of the figure (panels in a grid of at most two columns).
Result<PlotFiles> draw_convergence_plot(const std::vector<PlotPanel>& panels);

}  // namespace pathex
