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
// Batches, and the standard error (issues 36 and 39). Samples are grouped into B batches (default
// 32): batch b is replicate r = b mod R of pixel group g = b div R, with G = B / R groups
// (HistogramLayout::groups). The renderer puts the sample of pixel p and pass s in group p mod G
// and replicate s mod R (batch_of() below); under the `sobol` sampler each replicate
// of a pixel is an independently scrambled sequence whose point index is s div R (trace/rng.h), so
// a replicate of 16 spp / R points keeps the quasi-Monte Carlo gain of that many points. Pixels are
// independent of each other, and the R replicates of a group are independent and identically
// distributed, whatever the strategy (a light-tracing splat counts in the group of the sample
// that made it, wherever it lands). With S_gr the sum of a group's replicate, n_gr its sample
// count, n_g = Σ_r n_gr, X̄_g = S_g / n_g and N = Σ n_gr, the variance of the mean X̄ = Σ S / N is
// estimated by
//
//     stderr² = Σ_g c_g Σ_r (S_gr − n_gr X̄_g)² / N²,   c_g = n_g² / (n_g² − Σ_r n_gr²),
//
// unbiased for each group's own (unknown) variance: for R = 2 and equal counts it is
// Σ_g (S_g1 − S_g2)² / N², the per-pixel-set two-replicate estimate, with G(R − 1) degrees of
// freedom (groups with fewer than two replicates holding samples add none). With one group (G = 1,
// R = B) it is the textbook batch-means estimate Σ_b (S_b − n_b X̄)² / (N² − Σ_b n_b²), which
// needs the B batches to be independent: under `sobol` that spends the sequence over B replicates
// (1 point each per pixel at B = spp), which is what the groups avoid. VarianceDesign below is the
// one place this is computed: every estimate, technique share, degree of freedom and stability
// figure reads it. It needs one degree of freedom; otherwise the stderr is NaN.
//
// Memory: per distinct path string and per batch that holds a contribution of any path, a cell of
// 64 bytes, and per technique that sampled it 16 bytes per such batch (about 2 KiB + 0.5 KiB per
// technique for B = 32 batches in use). A batch's cells and row sums are laid out the first time
// something is added to it: a render of fewer passes than R fills only that many batches of each
// group (a one-pass shard G of them), and the others cost nothing, neither memory nor the page
// faults and copies that first touching it took. A Histogram has one writer; each
// worker thread owns one (a "shard") and the shards are merged at the end.
#pragma once

#include <algorithm>
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
#include "stats/batch_store.h"

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
inline constexpr int kDefaultBatches = 32;    // B, for every sampler (see "Batches" above)
inline constexpr int kDefaultReplicates = 2;  // R: B / R = 16 pixel groups of two replicates
// The default stderr's degrees of freedom, G (R − 1) = 16, for a render of at least R passes over
// at least G pixels (VarianceDesign::dof()).
inline constexpr int kDefaultDof = kDefaultBatches - kDefaultBatches / kDefaultReplicates;

// The replicates per pixel when none are asked for: kDefaultReplicates (B / 2 groups), unless the
// sensor has fewer pixels than that many groups. Then the groups beyond the pixel count would stay
// empty and the stderr would have as few degrees of freedom as the sensor has pixels — a spot
// meter's one, a stderr that is honest in expectation but useless for a z. So G is the largest
// divisor of B not above the pixel count and R = B / G: a spot meter gets one group of B
// replicates (B − 1 degrees of freedom, the textbook batch means). Under `sobol` the price is
// fewer points in each replicate's sequence (spp / R), the quasi-Monte Carlo gain of a shorter
// sequence (issue 36; measured in bench/README.md).
inline int default_replicates(int batches, std::uint64_t pixels) {
  int groups = batches / kDefaultReplicates;
  while (groups > 1 && (batches % groups != 0 || static_cast<std::uint64_t>(groups) > pixels)) --groups;
  return batches / std::max(groups, 1);
}

// The batch of pixel `pixel`'s pass `pass` (see "Batches" above): replicate pass mod R of pixel
// group pixel mod G, G = batches / replicates. Passes go to replicates round-robin, so an
// interrupted render still spreads what it has over all of them (and its error is defined);
// neighbouring pixels go to different groups, so every group covers the whole image. Replicates
// are independent: under `sobol` each is a sequence scrambled on its own (trace/rng.h, sobol_stream()).
inline int batch_of(std::uint64_t pixel, std::uint64_t pass, int batches, int replicates) {
  const auto R = static_cast<std::uint64_t>(replicates), G = static_cast<std::uint64_t>(batches / replicates);
  return static_cast<int>((pixel % G) * R + pass % R);
}

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
// A sum that fits 64 bits converts in one instruction instead of libgcc's 128-bit routine; both
// round to nearest, so the double is the same.
inline double to_double(ExactSum s) {
  const auto v = static_cast<SignedExactSum>(s);
  if (const auto low = static_cast<std::int64_t>(v); low == v) return static_cast<double>(low) * 0x1p-64;
  return static_cast<double>(v) * 0x1p-64;
}
inline Rgb to_double(const ExactRgb& s) { return {to_double(s[0]), to_double(s[1]), to_double(s[2])}; }
// The Rec. 709 luminance of a contribution already on the grid, rounded to the grid: a function of
// the contribution alone (what the per-technique sums add, see Histogram::TechniqueRow).
inline ExactSum luminance_exact(const ExactRgb& c) {
  // The same double as the 128-bit conversion (both round the same integer to nearest), through
  // the 64-bit one when the value fits, as most contributions do (|c| < 0.5): the 128-bit one is a
  // library call (__floattidf), three per recorded contribution.
  const auto v = [&](std::size_t i) {
    const auto s = static_cast<SignedExactSum>(c[i]);
    const auto low = static_cast<std::int64_t>(static_cast<std::uint64_t>(c[i]));
    return static_cast<SignedExactSum>(low) == s ? static_cast<double>(low) : static_cast<double>(s);
  };
  return round_to_fixed(0.2126 * v(0) + 0.7152 * v(1) + 0.0722 * v(2));
}
inline void add_to(ExactRgb& acc, const ExactRgb& c) {
  acc[0] += c[0];
  acc[1] += c[1];
  acc[2] += c[2];
}
inline bool is_zero(const ExactRgb& c) { return c[0] == 0 && c[1] == 0 && c[2] == 0; }

// "0", or the signed hexadecimal integer "0x1f…" / "-0x1f…" (the raw fixed-point value), and back.
std::string exact_to_string(ExactSum s);
std::optional<ExactSum> exact_from_string(std::string_view s);

// --- the accumulator ---

struct HistogramLayout {
  int num_batches = kDefaultBatches;    // B ≥ 1; at least 2 for a standard error
  std::vector<std::string> strategies;  // strategy id = index; techniques are named after these
  // G ≥ 1, dividing B: the pixel groups, each of R = B / G replicates (see "Batches" above). 1:
  // plain batch means (every batch a replicate of the whole image).
  int groups = 1;
  int replicates() const { return num_batches / groups; }
  bool operator==(const HistogramLayout&) const = default;
};

// The relative standard error of the variance of B batch means x of sample kurtosis κ:
// sqrt((κ − (B − 3)/(B − 1)) / B); NaN for fewer than 4 or when they are all equal.
double variance_relative_error(const std::vector<double>& batch_means);

// The standard error's estimate from per-batch sums (see "Batches" above), for a histogram's
// batch sample counts n_b and pixel groups. deviations() maps a quantity's B batch sums S_b to
// d_b = sqrt(c_g) (S_b − n_b X̄_g): its variance is Σ_b d_b² / N², and the covariance of two
// quantities Σ_b d_b d'_b / N² (d is linear in the sums), which the technique shares use.
class VarianceDesign {
 public:
  VarianceDesign(std::vector<std::uint64_t> batch_samples, int groups);
  int groups() const { return groups_; }
  int replicates() const { return static_cast<int>(n_.size()) / groups_; }
  // The degrees of freedom: Σ_g (its replicates holding samples − 1) over groups with two or more.
  int dof() const { return dof_; }
  // The same over the groups where a quantity with these sums is not 0 in every replicate: a rare
  // path's few hits inform only their groups (two hits of one value in a group's two replicates
  // give a variance of 0 with 1 degree of freedom, not 16). At most dof().
  int dof(const std::vector<double>& sums) const;
  double total_samples() const { return total_; }  // N
  // d_b for sums S_b (0 where a group has fewer than two replicates with samples).
  std::vector<double> deviations(const std::vector<double>& sums) const;
  // Σ d_b² / N² (NaN without a degree of freedom).
  double variance(const std::vector<double>& sums) const;
  // The variance estimate's own relative standard error (how far the next render's stderr may
  // stray): with groups, from the spread of the groups' terms Σ_r d_gr² (at least 4 groups with
  // a degree of freedom); with one group, from the batch means' kurtosis
  // (variance_relative_error(), stats/convergence.h). NaN when unknown.
  double variance_relative_error(const std::vector<double>& sums) const;

 private:
  std::vector<std::uint64_t> n_;
  int groups_ = 1;
  int dof_ = 0;
  double total_ = 0;
  std::vector<double> scale_;  // per group: sqrt(c_g), 0 without a degree of freedom
};

// A sampling technique: strategy `strategy` of the layout (a profile strategy) run at one split of
// a path, s vertices from the light, the strategy's chain, t vertices from the sensor (DESIGN §4:
// a plain join's chain is DD, a connector's DSD). The histogram keeps exact sums per path,
// technique and batch, so that a report can say which technique carries a path's estimate and
// its variance. code() packs it into one non-negative int (strategy, s, t, chain from the most
// significant bits down: 12, 8, 8 and 1 bits), so that codes sort by strategy, then s, then t;
// the accumulator and the shard file store codes.
struct Technique {
  int strategy = 0;
  int s = 0, t = 0;
  bool connector = false;  // the chain is a connector's DSD, not a plain join's DD
  static constexpr int kMaxStrategies = 1 << 12, kMaxSplit = 255;
  int code() const { return (strategy << 17) | (s << 9) | (t << 1) | (connector ? 1 : 0); }
  static Technique from_code(int code) {
    return {(code >> 17) & 0xfff, (code >> 9) & 0xff, (code >> 1) & 0xff, (code & 1) != 0};
  }
  // The chain it joined on `path`: DD for a plain join; for a connector the path's letters between
  // the s before it and the t after it (DESIGN §4: the strategy's language is
  // L [SD]{s} chain [SD]{t} E), such as DSSD; DS+D when the path is too short to hold one.
  std::string chain(std::string_view path) const;
  // "bdpt (2, DD, 1)", "manifold (1, DSSD, 4)": the strategy's name in the layout, then (s, chain, t).
  std::string name(const HistogramLayout& layout, const std::string& chain) const;
};

class Histogram {
 public:
  using PathId = int;
  static constexpr int kNoStrategy = -1;  // a contribution not attributed to any technique

  struct Cell {
    ExactRgb sum{};                     // exact sum of the contributions of one path in one batch
    std::uint64_t contributions = 0;    // how many nonzero contributions went into it
  };
  // The contributions of one path by one technique: their count and, in the histogram, the exact
  // sum per batch of their luminances (row_sum(): each contribution's Rec. 709 luminance rounded
  // once to the fixed-point grid). A path's rows form a list in order of first sight.
  struct TechniqueRow {
    PathId path = 0;
    int technique = 0;               // Technique::code()
    std::uint64_t contributions = 0;
    int next = -1;                   // the path's next row, or -1
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
  // Makes room for at least `paths` paths in all (the path table, and cells for paths met in few
  // batches), growing geometrically, so that adding that many costs no reallocation: for readers
  // that know a bound ahead (shard files).
  void reserve_paths(std::size_t paths);
  // The same for technique rows (the row table and their row sums).
  void reserve_rows(std::size_t rows);
  int num_paths() const { return static_cast<int>(paths_.size()); }
  const std::string& path(PathId id) const { return paths_[static_cast<std::size_t>(id)]; }
  // The classifier's class-set id of the path; 0 when the histogram has no classifier.
  std::uint32_t class_set(PathId id) const { return sets_[static_cast<std::size_t>(id)]; }

  // --- accumulation (not thread-safe: one writer per Histogram) ---
  // Adds a contribution of path `id` from a sample in `batch` (0 ≤ batch < B) sampled by
  // technique `strategy` (a Technique::code() whose strategy indexes the layout's strategies, or
  // kNoStrategy); unchecked. Returns
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
  // The same for technique row `row` of path `id` (technique_row(); not kNoStrategy), for callers
  // that keep rows themselves (trace/accel/path_ids.h) and count the row's contributions
  // themselves (add_technique() with null sums).
  void add_exact_at_row(PathId id, int row, int batch, const ExactRgb& c) {
    if (is_zero(c)) return;
    Cell& cell = cell_of(id, batch);
    add_to(cell.sum, c);
    ++cell.contributions;
    row_sum_of(row, batch) += luminance_exact(c);
    add_magnitude_of(c);
  }
  // The row of (path, technique code), added on first sight.
  int technique_row(PathId id, int technique);
  // Registers n finished samples of `batch`, whether they contributed or not: n_b above.
  void add_samples(int batch, std::uint64_t n) { batch_samples_[static_cast<std::size_t>(batch)] += n; }
  // Counts non-finite contributions that the caller rejected itself (e.g. after to_exact()).
  void add_nonfinite(std::uint64_t n = 1) { nonfinite_ += n; }

  // Adds everything `other` holds. Exact and order-independent. Fails (kUsage) if the layouts
  // differ.
  Result<bool> merge(const Histogram& other);

  // --- the exact state (for reports and serialisation) ---
  const Cell& cell(PathId id, int batch) const {
    const Cell* c = cells_.find(static_cast<std::size_t>(id), batch);
    return c != nullptr ? *c : kEmptyCell;
  }
  // Calls f(batch, cell) for the path's cells that may be nonzero, in batch order (every other
  // cell of it is zero): cheaper than cell() over all B batches for a path met in few.
  template <class F>
  void for_each_cell(PathId id, F&& f) const {
    cells_.for_each(static_cast<std::size_t>(id), std::forward<F>(f));
  }
  // The same for a technique row's batch sums.
  template <class F>
  void for_each_row_sum(int r, F&& f) const {
    row_sums_.for_each(static_cast<std::size_t>(r), std::forward<F>(f));
  }
  // The path's first technique row (-1: none); follow TechniqueRow::next for the others.
  int first_row(PathId id) const { return first_row_[static_cast<std::size_t>(id)]; }
  const TechniqueRow& row(int r) const { return rows_[static_cast<std::size_t>(r)]; }
  ExactSum row_sum(int r, int batch) const {
    const ExactSum* sum = row_sums_.find(static_cast<std::size_t>(r), batch);
    return sum != nullptr ? *sum : ExactSum{0};
  }
  // Whether anything was ever added to the batch's cells or row sums (the others are all zero).
  bool batch_in_use(int batch) const { return used_[static_cast<std::size_t>(batch)] != 0; }
  // The batches in use, ascending: a shard of fewer passes than replicates (one pass fills one
  // replicate of every group) leaves the others empty.
  std::vector<int> batches_in_use() const;
  int num_rows() const { return static_cast<int>(rows_.size()); }
  // The path's rows ordered by technique code (the order serialised forms use).
  std::vector<int> sorted_rows(PathId id) const;
  std::uint64_t batch_samples(int batch) const { return batch_samples_[static_cast<std::size_t>(batch)]; }
  std::uint64_t total_samples() const;
  // The standard error's estimate for this histogram's sample counts, and its degrees of freedom.
  VarianceDesign variance_design() const { return VarianceDesign(batch_samples_, layout_.groups); }
  int stderr_dof() const { return variance_design().dof(); }
  std::uint64_t nonfinite() const { return nonfinite_; }
  // Σ |channel| of every accepted contribution on the fixed-point grid, saturating at 2^127. While
  // it stays below 2^127 (a value of 2^63 ≈ 9.2e18) no partial or final sum can overflow.
  ExactSum magnitude() const { return magnitude_; }
  bool may_overflow() const { return magnitude_ >= kMagnitudeCap; }

  // --- restoring a serialised state: exact, like add() ---
  void add_cell(PathId id, int batch, const ExactRgb& sum, std::uint64_t contributions);
  // Adds `contributions` to the row of (path, technique) and, when `batch_sums` is not null, its
  // B per-batch luminance sums.
  void add_technique(PathId id, int technique, std::uint64_t contributions, const ExactSum* batch_sums);
  // Adds `sum` to row `r`'s luminance sum in `batch` (a row of technique_row()): for readers that
  // restore the row sums batch by batch (the MPI reduction, cli/mpi/).
  void add_row_sum(int r, int batch, ExactSum sum) {
    if (sum != 0) row_sum_of(r, batch) += sum;
  }
  void add_magnitude(ExactSum m);

 private:
  static constexpr ExactSum kMagnitudeCap = static_cast<ExactSum>(1) << 127;

  struct StringHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  static const Cell kEmptyCell;  // what cell() reads where nothing was added
  Cell& cell_of(PathId id, int batch) {
    used_[static_cast<std::size_t>(batch)] = 1;
    return cells_.at(static_cast<std::size_t>(id), batch);
  }
  ExactSum& row_sum_of(int r, int batch) { return row_sums_.at(static_cast<std::size_t>(r), batch); }

  HistogramLayout layout_;
  const Classifier* classifier_ = nullptr;
  std::unordered_map<std::string, PathId, StringHash, std::equal_to<>> ids_;
  std::vector<std::string> paths_;
  std::vector<std::uint32_t> sets_;
  // Per path and batch, sparse while a path has been met in few batches (stats/batch_store.h).
  BatchStore<Cell> cells_;
  std::vector<char> used_;  // per batch: whether a cell of it was ever added to
  // Each |channel| < 2^114, so the sum of three cannot wrap before saturating.
  void add_magnitude_of(const ExactRgb& c) {
    const auto abs = [](ExactSum v) { return static_cast<SignedExactSum>(v) < 0 ? ExactSum{0} - v : v; };
    const ExactSum m = abs(c[0]) + abs(c[1]) + abs(c[2]);
    magnitude_ = m >= kMagnitudeCap - magnitude_ ? kMagnitudeCap : magnitude_ + m;
  }
  std::vector<int> first_row_;           // per path
  std::vector<TechniqueRow> rows_;
  // Per technique row and batch, like cells_.
  BatchStore<ExactSum> row_sums_;
  std::vector<std::uint64_t> batch_samples_;
  std::uint64_t nonfinite_ = 0;
  ExactSum magnitude_ = 0;
};

// --- statistics and the report ---

struct Estimate {
  Rgb rgb{};                   // mean pixel value over the image
  double luminance = 0;        // Rec. 709 luminance of rgb
  double std_error = std::numeric_limits<double>::quiet_NaN();  // of luminance (VarianceDesign)
  int dof = 0;                 // std_error's degrees of freedom (VarianceDesign::dof(sums))
  std::uint64_t samples = 0;   // nonzero contributions (a BDPT sample may contribute several)
  // The relative error of std_error² (VarianceDesign::variance_relative_error()): about 0.35 for
  // well-behaved pixel groups, near 1 when one group holds nearly all of the variance (a rare
  // spike: the stderr may then be several times too small; kUnstableVariance below). NaN when
  // unknown (fewer than 4 groups with a variance).
  double stability = std::numeric_limits<double>::quiet_NaN();
};
// The stability at and above which a stderr is flagged as unstable: by converge for a ladder (the
// median over its rungs, stats/convergence.h), by pathex trace for one render's total or class.
// Normal pixel groups reach it in 3 renders of 10,000 (16 groups: ε ≈ 0.31 at the median).
inline constexpr double kUnstableVariance = 0.7;
// The relative error of single-precision transport: an error or a stderr below this fraction of
// its estimate is rounding, not noise (converge's checks, stats/convergence.h; trace's flag above).
inline constexpr double kRoundingFloor = 1e-6;

// The estimate from exact per-batch sums, its stderr by `design` (the formula above).
Estimate estimate_of(const std::vector<ExactRgb>& batch_sums, const VarianceDesign& design, std::uint64_t contributions);

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

// What one technique adds to a path's or a class's estimate.
struct TechniqueEstimate {
  std::string name;           // Technique::name()
  double share = 0;           // its luminance / the luminance of the whole (0 when that is 0)
  std::uint64_t samples = 0;  // its nonzero contributions
  // Its own share of the variance: v_t = Σ_b d_tb² (VarianceDesign), its own variance, over Σ_t v_t of the whole's techniques: ≥ 0, and the shares of a
  // whole sum to 1, like the luminance shares (issue 36: the covariance share it replaced read as
  // a negative share). NaN when the whole has no standard error.
  double variance_share = std::numeric_limits<double>::quiet_NaN();
  // Where covariance matters: the correlation, over the batches' deviations, of its estimates with the rest
  // of the whole's (the sum of the other techniques'): negative when their errors partly cancel
  // (the whole's variance is then below the sum of its techniques'), positive when they add up.
  // NaN when it alone carries the whole or either side has no variance.
  double correlation = std::numeric_limits<double>::quiet_NaN();
  // Equal values (two NaN values are equal: both unknown).
  bool operator==(const TechniqueEstimate& o) const {
    const auto same = [](double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); };
    return name == o.name && share == o.share && samples == o.samples && same(variance_share, o.variance_share) &&
           same(correlation, o.correlation);
  }
};

struct ClassEstimate {
  std::string name;
  std::string expr;
  Estimate estimate;
  double share = 0;  // class luminance / total luminance (0 when the total is 0)
  std::vector<TechniqueEstimate> strategies;  // the techniques of its paths, summed by technique
  // False for a class the render did not estimate (pathex trace --only asked for other classes):
  // its estimate is unknown, never 0, and histogram.json says "not rendered".
  bool rendered = true;
};

struct PathEstimate {
  std::string path;
  Estimate estimate;
  // The techniques that contributed, by strategy, then s, then t.
  std::vector<TechniqueEstimate> strategies;
};

struct HistogramReport {
  RunInfo run;
  // The requested classes' names when only they were rendered (pathex trace --only): then `total`
  // is the sum over their paths, not the image's.
  std::vector<std::string> only;
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
