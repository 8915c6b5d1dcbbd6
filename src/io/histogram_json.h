// histogram.json: the path-class histogram of a render (issue 4 "Outputs"), and back.
//
// The document is a function of what was rendered (scene, renderer, classes, seed, the passes
// taken) and nothing else: the wall time and thread count of the run go to run.json beside it, so
// that a sharded, merged, resumed or MPI render writes the same bytes as one process.
//
// Keys (stable; objects are written in this order):
//
//   scene              string   the scene file (or the embedded default's name)
//   renderer           string   the renderer profile's name
//   spp                integer  samples per pixel rendered
//   spp_requested      integer  samples per pixel asked for (more than spp when interrupted)
//   seed               integer
//   complete           bool     false when the render was interrupted and wrote what it had
//   nonfinite_samples  integer  contributions that were NaN, infinite or ≥ 2^50 (never added; must be 0)
//   distinct_paths     integer  distinct paths sampled (rows of `paths`, plus those summed in "other")
//   max_paths          integer  the bound on the rows of `paths` (--max-paths), or null for none
//   total    {estimate [r,g,b], luminance, stderr, samples}
//   classes  [{name, expr, estimate [r,g,b], luminance, stderr, samples, share, strategies}]
//            in class-file order
//   paths    [{path, estimate [r,g,b], luminance, stderr, samples, strategies}]
//            sorted by luminance, largest first; at most max_paths of them, then, when more paths
//            were sampled, one row {path: "other", paths: n, note, estimate, …} that sums the rest
//            exactly ("other" is never a full path: those begin with L)
//   raw      optional: the exact accumulator state, for merging (below)
//
// An estimate is the mean pixel value over the image (RGB, and its Rec. 709 luminance); stderr is
// the standard error of the luminance from the replicates' differences (stats/histogram.h,
// "Batches"; null without a degree of freedom: fewer than two replicates hold samples); samples counts nonzero contributions; a class's share is its luminance over the
// total's. `samples` in `total` is an addition to the keys listed in issue 4.
//
// `strategies` (of a path, of "other", of a class) says which sampling technique carries the
// estimate: {"<strategy> (s, chain, t)": {share, samples, variance_share, correlation}, …}, one key per
// technique that contributed — the profile strategy's name and its split: s vertices from the
// light, the chain (DD for a plain join, DSD for a connector), t vertices from the sensor.
// share is its luminance over the whole's, samples its nonzero contributions, variance_share its
// own variance over the sum of its row's techniques' (≥ 0; the shares of a row sum to
// 1, and so do its variance shares; null without a standard error), correlation that of its batch
// estimates with the rest of the row's (null when unknown) — TechniqueEstimate.
//
// The optional "raw" section carries the Histogram itself — per path and batch the exact
// fixed-point sums (as the signed hexadecimal strings of exact_to_string) and contribution
// counts, per path and technique its count and per-batch luminance sums, per batch the sample counts — so that the outputs
// of separate processes can be parsed back and merged exactly (Histogram::merge):
//
//   raw {format: 2, fraction_bits: 64, batches: B, replicates: R (absent: B), strategies: [names], batch_samples: [B ints],
//        nonfinite: n, magnitude: "0x…",
//        paths: [{path, contributions: [B ints], sums: [B × [r,g,b]],
//                 techniques: [{strategy, s, t, connector, contributions, sums: [B luminance sums]}]}]}
//   (format 1 had strategy_sums [S × [r,g,b]] instead of techniques; it is refused)
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "stats/histogram.h"
#include "core/error.h"

namespace pathex {

struct HistogramFile {
  HistogramReport report;
  std::optional<Histogram> raw;  // when the document has a "raw" section
};

// The document; with `raw`, also its "raw" section.
nlohmann::ordered_json to_json(const HistogramReport& report, const Histogram* raw = nullptr);
// The document as text, two-space indented, ending in a newline.
std::string histogram_json_text(const HistogramReport& report, const Histogram* raw = nullptr);

nlohmann::ordered_json raw_to_json(const Histogram& histogram);

// Parses a document written by to_json. Errors name `filename` and the JSON pointer of the
// offending value. Unknown keys are ignored (later versions may add keys).
Result<HistogramFile> histogram_from_json(const nlohmann::ordered_json& doc, const std::string& filename);
Result<HistogramFile> parse_histogram_json(const std::string& text, const std::string& filename);
// The "raw" section alone; `pointer` is where it sits in the document, for messages.
Result<Histogram> raw_from_json(const nlohmann::ordered_json& raw, const std::string& filename,
                                const std::string& pointer = "/raw");

}  // namespace pathex
