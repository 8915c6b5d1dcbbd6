// Path-class histograms: where the light of a render went, string by string and class by class.
//
// The integrator hands every Monte Carlo contribution to a Histogram together with the full-path
// string that carried it, the strategy that sampled it and the batch of its sample. A
// *contribution* is what one sample adds to one pixel's sum before that sum is divided by the
// pixel's sample count (a camera sample's own pixel, or any pixel a light-tracing splat lands
// on). With N samples in all (pixels × spp), Σ contributions / N is then the image's mean pixel
// value, the estimate this file reports for the whole image, for each exact path string and for
// each user class (DESIGN §7 "Outputs", issue 4).
//
// Exactness, and why results do not depend on the thread count. Each contribution is rounded
// once, on entry, to a 128-bit two's-complement fixed-point grid with 64 fractional bits
// (resolution 2^-64 ≈ 5.4e-20) and summed as an integer. Integer addition (modulo 2^128) is
// associative and commutative, so every sum — per path, per batch, per strategy, and the class
// and total sums built from them — is the same bit pattern however the samples were split among
// threads, shards or processes and in whatever order the shards were merged; merge() is exact.
// The rounding of a contribution depends on nothing but the contribution. Floating point is used
// only afterwards, in make_report(), which is a pure function of the exact sums. A contribution
// that is not finite or whose magnitude reaches kMaxContribution (2^50 ≈ 1.1e15, far beyond any
// sane radiance) is counted in nonfinite() and never added; the magnitude guard then proves that
// no sum can leave the representable range (see Histogram::magnitude()).
//
// Batch means. Samples are grouped into B batches (default 32) by *pass*, the per-pixel sample
// index — the renderer deals passes to batches round-robin (pass mod B, trace/render.cpp), so
// that an interrupted render still spreads what it has over every batch — so that every batch
// covers the whole image and the batch estimates X_b = S_b / n_b are independent and identically
// distributed, whatever the strategy (splats from light tracing land anywhere, which rules out a
// per-pixel variance). batch_of_pass() below is the other possible dealing, contiguous ranges.
// With N = Σ n_b and X̄ = Σ S_b / N, the standard error of X̄ is estimated by
//
//     stderr² = Σ_b (S_b − n_b X̄)² / (N² − Σ_b n_b²),
//
// which is unbiased for independent samples and reduces to the textbook Σ (X_b − X̄)² / (B(B−1))
// when the batches are equal. It needs at least two batches holding samples; otherwise it is NaN.
//
// Memory: per distinct path string, B cells of 64 bytes plus 48 bytes per strategy (about 2.2 KiB
// for B = 32 and 4 strategies). A Histogram has one writer; each worker thread owns one (a
// "shard") and the shards are merged at the end.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "classify/classifier.h"
#include "core/error.h"

namespace pathex {

// --- exact fixed-point sums ---

// A sum in 128-bit two's complement: the value is (signed) ExactSum / 2^64. Unsigned, so that
// wrap-around is defined; intermediate wrap-around is harmless because the final sum is exact
// whenever it lies in range, which the magnitude guard checks.
__extension__ typedef unsigned __int128 ExactSum;
__extension__ typedef __int128 SignedExactSum;

using Rgb = std::array<double, 3>;
using ExactRgb = std::array<ExactSum, 3>;

inline constexpr int kFractionBits = 64;
inline constexpr double kMaxContribution = 0x1p50;  // |c| ≥ this counts as non-finite
inline constexpr int kDefaultBatches = 32;

// Rec. 709 luminance.
inline double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// y rounded to the nearest integer (ties to even, as nearbyint in the default rounding mode) as a
// 128-bit two's-complement value; |y| < 2^114. Adding and removing 2^52 rounds a smaller |y| in
// one step (a larger one is already an integer), without nearbyint's library call; below 2^63
// the integer converts directly, above it is split exactly at 2^64 (the floor of a scaled power
// of two is exact, and so is the remainder, a multiple of y's ulp below 2^64).
inline ExactSum round_to_fixed(double y) {
  double x = y;
  if (std::fabs(y) < 0x1p52) {
    const double magic = std::copysign(0x1p52, y);
    x = (y + magic) - magic;
  }
  if (std::fabs(x) < 0x1p63) return static_cast<ExactSum>(static_cast<SignedExactSum>(static_cast<std::int64_t>(x)));
  const double hi = std::floor(x * 0x1p-64);
  const double lo = x - hi * 0x1p64;
  return (static_cast<ExactSum>(static_cast<SignedExactSum>(static_cast<std::int64_t>(hi))) << 64) +
         static_cast<ExactSum>(static_cast<std::uint64_t>(lo));
}

// The contribution on the fixed-point grid (round to nearest), or nullopt if a component is not
// finite or too large. This is the only place where a contribution is rounded.
inline std::optional<ExactRgb> to_exact(const Rgb& c) {
  ExactRgb out;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(std::fabs(c[i]) < kMaxContribution)) return std::nullopt;  // also rejects NaN
    out[i] = round_to_fixed(c[i] * 0x1p64);
  }
  return out;
}
// The same into `out` (unchanged when false), for hot callers: the value is written where it is
// used, never copied into an optional, which GCC does with 16-byte loads of words just stored as
// 8-byte halves (a store-forwarding stall per channel).
inline bool to_exact(const Rgb& c, ExactRgb* out) {
  for (std::size_t i = 0; i < 3; ++i)
    if (!(std::fabs(c[i]) < kMaxContribution)) return false;
  for (std::size_t i = 0; i < 3; ++i) (*out)[i] = round_to_fixed(c[i] * 0x1p64);
  return true;
}
inline double to_double(ExactSum s) { return static_cast<double>(static_cast<SignedExactSum>(s)) * 0x1p-64; }
inline Rgb to_double(const ExactRgb& s) { return {to_double(s[0]), to_double(s[1]), to_double(s[2])}; }
inline void add_to(ExactRgb& acc, const ExactRgb& c) {
  acc[0] += c[0];
  acc[1] += c[1];
  acc[2] += c[2];
}
inline bool is_zero(const ExactRgb& c) { return c[0] == 0 && c[1] == 0 && c[2] == 0; }

// "0", or the signed hexadecimal integer "0x1f…" / "-0x1f…" (the raw fixed-point value), and back.
std::string exact_to_string(ExactSum s);
std::optional<ExactSum> exact_from_string(std::string_view s);

// The batch of the pass-th sample of every pixel when each pixel takes spp samples: contiguous
// ranges of passes, as equal as possible (spp < B leaves some batches empty, which is allowed).
inline int batch_of_pass(std::uint64_t pass, std::uint64_t spp, int num_batches) {
  return static_cast<int>(pass * static_cast<std::uint64_t>(num_batches) / spp);
}

// --- the accumulator ---

struct HistogramLayout {
  int num_batches = kDefaultBatches;    // B ≥ 1; at least 2 for a standard error
  std::vector<std::string> strategies;  // strategy id = index; shares are reported under these names
  bool operator==(const HistogramLayout&) const = default;
};

class Histogram {
 public:
  using PathId = int;
  static constexpr int kNoStrategy = -1;  // a contribution not attributed to any strategy

  struct Cell {
    ExactRgb sum{};                     // exact sum of the contributions of one path in one batch
    std::uint64_t contributions = 0;    // how many nonzero contributions went into it
  };

  // With a classifier, intern() also records each path's class-set id (for per-class images).
  explicit Histogram(HistogramLayout layout = {}, const Classifier* classifier = nullptr);

  const HistogramLayout& layout() const { return layout_; }
  int num_batches() const { return layout_.num_batches; }
  int num_strategies() const { return static_cast<int>(layout_.strategies.size()); }

  // --- paths ---
  // The id of `path` in this histogram, allocated on first sight. Ids are local to a histogram
  // (merge() matches paths by string), dense from 0, and stable.
  PathId intern(std::string_view path);
  std::optional<PathId> find(std::string_view path) const;
  // Makes room for at least `paths` paths in all (the path table and every batch's cells), growing
  // geometrically, so that adding that many costs no reallocation: for readers that know a bound
  // ahead (shard files).
  void reserve_paths(std::size_t paths);
  int num_paths() const { return static_cast<int>(paths_.size()); }
  const std::string& path(PathId id) const { return paths_[static_cast<std::size_t>(id)]; }
  // The classifier's class-set id of the path; 0 when the histogram has no classifier.
  std::uint32_t class_set(PathId id) const { return sets_[static_cast<std::size_t>(id)]; }

  // --- accumulation (not thread-safe: one writer per Histogram) ---
  // Adds a contribution of path `id` from a sample in `batch` (0 ≤ batch < B) sampled by
  // `strategy` (an index into the layout's strategies, or kNoStrategy); unchecked. Returns
  // false, counting it in nonfinite(), when it is not finite or too large (see to_exact()).
  bool add(PathId id, int batch, int strategy, const Rgb& c) {
    std::optional<ExactRgb> e = to_exact(c);
    if (!e) {
      ++nonfinite_;
      return false;
    }
    add_exact(id, batch, strategy, *e);
    return true;
  }
  // The same for a contribution already converted (so that it is rounded once for the histogram
  // and the images). An all-zero contribution is ignored.
  void add_exact(PathId id, int batch, int strategy, const ExactRgb& c);
  // Registers n finished samples of `batch`, whether they contributed or not: n_b above.
  void add_samples(int batch, std::uint64_t n) { batch_samples_[static_cast<std::size_t>(batch)] += n; }
  // Counts non-finite contributions that the caller rejected itself (e.g. after to_exact()).
  void add_nonfinite(std::uint64_t n = 1) { nonfinite_ += n; }

  // Adds everything `other` holds. Exact and order-independent. Fails (kUsage) if the layouts
  // differ.
  Result<bool> merge(const Histogram& other);

  // --- the exact state (for reports and serialisation) ---
  const Cell& cell(PathId id, int batch) const {
    return cells_[static_cast<std::size_t>(batch)][static_cast<std::size_t>(id)];
  }
  const ExactRgb& strategy_sum(PathId id, int strategy) const {
    return strategy_sums_[static_cast<std::size_t>(id) * layout_.strategies.size() +
                          static_cast<std::size_t>(strategy)];
  }
  std::uint64_t batch_samples(int batch) const { return batch_samples_[static_cast<std::size_t>(batch)]; }
  std::uint64_t total_samples() const;
  std::uint64_t nonfinite() const { return nonfinite_; }
  // Σ |channel| of every accepted contribution on the fixed-point grid, saturating at 2^127. While
  // it stays below 2^127 (a value of 2^63 ≈ 9.2e18) no partial or final sum can overflow.
  ExactSum magnitude() const { return magnitude_; }
  bool may_overflow() const { return magnitude_ >= kMagnitudeCap; }

  // --- restoring a serialised state: exact, like add() ---
  void add_cell(PathId id, int batch, const ExactRgb& sum, std::uint64_t contributions);
  void add_strategy_sum(PathId id, int strategy, const ExactRgb& sum);
  void add_magnitude(ExactSum m);

 private:
  static constexpr ExactSum kMagnitudeCap = static_cast<ExactSum>(1) << 127;

  struct StringHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  Cell& cell_of(PathId id, int batch) {
    return cells_[static_cast<std::size_t>(batch)][static_cast<std::size_t>(id)];
  }

  HistogramLayout layout_;
  const Classifier* classifier_ = nullptr;
  std::unordered_map<std::string, PathId, StringHash, std::equal_to<>> ids_;
  std::vector<std::string> paths_;
  std::vector<std::uint32_t> sets_;
  // Batch-major, [batch][id]: a render's passes go to batches round-robin, so the cells it adds
  // to at a time are a few batches' rows, not a line of every path's B cells.
  std::vector<std::vector<Cell>> cells_;
  std::vector<ExactRgb> strategy_sums_;  // id * S + strategy
  std::vector<std::uint64_t> batch_samples_;
  std::uint64_t nonfinite_ = 0;
  ExactSum magnitude_ = 0;
};

// --- statistics and the report ---

struct Estimate {
  Rgb rgb{};                   // mean pixel value over the image
  double luminance = 0;        // Rec. 709 luminance of rgb
  double std_error = std::numeric_limits<double>::quiet_NaN();  // of luminance, by batch means
  std::uint64_t samples = 0;   // nonzero contributions (a BDPT sample may contribute several)
};

// The estimate from exact per-batch sums and per-batch sample counts (the formula above).
Estimate batch_means(const std::vector<ExactRgb>& batch_sums, const std::vector<std::uint64_t>& batch_samples,
                     std::uint64_t contributions);

// What the render was; copied into the report as is. Only what the result is a function of: how
// long it took and on how many threads is not here (pathex trace writes that to run.json), so
// that the report of a render is the same bytes however it was split, interrupted or resumed.
struct RunInfo {
  std::string scene;
  std::string renderer;
  std::uint64_t spp = 0;
  std::uint64_t seed = 0;
  bool complete = true;  // false for an interrupted render that wrote what it had
  std::uint64_t spp_requested = 0;  // what was asked (spp is what was done; they differ when interrupted)
  bool operator==(const RunInfo&) const = default;
};

struct ClassInfo {
  std::string name;
  std::string expr;  // as written in the class file
};

struct ClassEstimate {
  std::string name;
  std::string expr;
  Estimate estimate;
  double share = 0;  // class luminance / total luminance (0 when the total is 0)
};

struct PathEstimate {
  std::string path;
  Estimate estimate;
  // Strategy name -> share of the path's luminance, for the strategies that contributed, in
  // layout order.
  std::vector<std::pair<std::string, double>> strategies;
};

struct HistogramReport {
  RunInfo run;
  std::uint64_t nonfinite_samples = 0;
  Estimate total;
  std::vector<ClassEstimate> classes;  // in classifier order
  std::vector<PathEstimate> paths;     // by luminance, largest first; ties by path string
  std::uint64_t distinct_paths = 0;    // every path sampled, listed in `paths` or summed in `other`
  std::optional<std::uint64_t> max_paths;  // the bound on `paths` in force, if any
  // The paths past the first max_paths, summed exactly into one row (path "other"), and how many.
  std::optional<PathEstimate> other;
  std::uint64_t other_paths = 0;
};

// Estimates for the total, each class of `classifier` (described by `classes`, one entry per
// classifier class, in order; the classifier may be null when `classes` is empty) and each path.
// With `max_paths`, only the largest max_paths paths get a row each and the rest are summed into
// `other` (the total and the classes always count every path).
// Fails with kUsage if contributions were recorded in a batch with no registered samples or if
// `classes` does not match the classifier, and with kLimit if the sums may have overflowed.
Result<HistogramReport> make_report(const Histogram& histogram, const RunInfo& run, const Classifier* classifier,
                                    const std::vector<ClassInfo>& classes,
                                    std::optional<std::uint64_t> max_paths = std::nullopt);

}  // namespace pathex
