// The accumulator (exact integer sums keyed by path string and batch) and the report built from
// it: batch means per path, per class (sums of the paths in the class) and for the total.
#include "classify/histogram.h"

#include <algorithm>

namespace pathex {

// --- exact sums as text ---

std::string exact_to_string(ExactSum s) {
  if (s == 0) return "0";
  const bool negative = static_cast<SignedExactSum>(s) < 0;
  ExactSum m = negative ? ExactSum{0} - s : s;  // |s|; 2^127 stays 2^127 as unsigned
  std::string digits;
  while (m != 0) {
    digits.push_back("0123456789abcdef"[static_cast<int>(m & 0xF)]);
    m >>= 4;
  }
  std::reverse(digits.begin(), digits.end());
  return (negative ? "-0x" : "0x") + digits;
}

std::optional<ExactSum> exact_from_string(std::string_view s) {
  if (s == "0") return ExactSum{0};
  bool negative = false;
  if (!s.empty() && s[0] == '-') {
    negative = true;
    s.remove_prefix(1);
  }
  if (s.size() < 3 || s.size() > 34 || s[0] != '0' || s[1] != 'x') return std::nullopt;
  ExactSum m = 0;
  for (char c : s.substr(2)) {
    int d;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else return std::nullopt;
    m = (m << 4) | static_cast<ExactSum>(d);
  }
  const ExactSum top = static_cast<ExactSum>(1) << 127;
  if (negative ? m > top : m >= top) return std::nullopt;  // outside the signed 128-bit range
  return negative ? ExactSum{0} - m : m;
}

// --- the accumulator ---

Histogram::Histogram(HistogramLayout layout, const Classifier* classifier)
    : layout_(std::move(layout)),
      classifier_(classifier),
      cells_(static_cast<std::size_t>(std::max(layout_.num_batches, 0))),
      batch_samples_(static_cast<std::size_t>(std::max(layout_.num_batches, 0)), 0) {}

Histogram::PathId Histogram::intern(std::string_view path) {
  auto it = ids_.find(path);
  if (it != ids_.end()) return it->second;
  const PathId id = static_cast<PathId>(paths_.size());
  paths_.emplace_back(path);
  ids_.emplace(paths_.back(), id);
  sets_.push_back(classifier_ != nullptr ? classifier_->classify(path) : 0);
  for (std::vector<Cell>& row : cells_) row.emplace_back();
  strategy_sums_.resize(strategy_sums_.size() + layout_.strategies.size(), ExactRgb{});
  return id;
}

void Histogram::reserve_paths(std::size_t paths) {
  if (paths <= paths_.capacity()) return;
  paths = std::max(paths, 2 * paths_.capacity());  // geometric, like the vectors' own growth
  paths_.reserve(paths);
  ids_.reserve(paths);
  sets_.reserve(paths);
  for (std::vector<Cell>& row : cells_) row.reserve(paths);
  strategy_sums_.reserve(paths * layout_.strategies.size());
}

std::optional<Histogram::PathId> Histogram::find(std::string_view path) const {
  auto it = ids_.find(path);
  if (it == ids_.end()) return std::nullopt;
  return it->second;
}

namespace {

ExactSum abs_exact(ExactSum v) { return static_cast<SignedExactSum>(v) < 0 ? ExactSum{0} - v : v; }

// a + b, saturating at cap (a, b ≤ cap). Saturation keeps the result order-independent: it is
// min(cap, Σ) whatever the order of the additions.
ExactSum add_saturating(ExactSum a, ExactSum b, ExactSum cap) { return b >= cap - a ? cap : a + b; }

}  // namespace

void Histogram::add_exact(PathId id, int batch, int strategy, const ExactRgb& c) {
  if (is_zero(c)) return;
  Cell& cell = cell_of(id, batch);
  add_to(cell.sum, c);
  ++cell.contributions;
  if (strategy != kNoStrategy)
    add_to(strategy_sums_[static_cast<std::size_t>(id) * layout_.strategies.size() +
                          static_cast<std::size_t>(strategy)],
           c);
  // Each |channel| < 2^114, so the sum of three cannot wrap before saturating.
  magnitude_ = add_saturating(magnitude_, abs_exact(c[0]) + abs_exact(c[1]) + abs_exact(c[2]), kMagnitudeCap);
}

void Histogram::add_cell(PathId id, int batch, const ExactRgb& sum, std::uint64_t contributions) {
  Cell& cell = cell_of(id, batch);
  add_to(cell.sum, sum);
  cell.contributions += contributions;
}

void Histogram::add_strategy_sum(PathId id, int strategy, const ExactRgb& sum) {
  add_to(strategy_sums_[static_cast<std::size_t>(id) * layout_.strategies.size() + static_cast<std::size_t>(strategy)],
         sum);
}

void Histogram::add_magnitude(ExactSum m) { magnitude_ = add_saturating(magnitude_, std::min(m, kMagnitudeCap), kMagnitudeCap); }

std::uint64_t Histogram::total_samples() const {
  std::uint64_t n = 0;
  for (std::uint64_t b : batch_samples_) n += b;
  return n;
}

Result<bool> Histogram::merge(const Histogram& other) {
  if (!(other.layout_ == layout_))
    return make_error(ErrorCode::kUsage,
                      "cannot merge histograms with different layouts (batch count or strategy list differ)");
  for (PathId o = 0; o < other.num_paths(); ++o) {
    const PathId id = intern(other.path(o));
    for (int b = 0; b < layout_.num_batches; ++b) {
      const Cell& src = other.cell(o, b);
      add_cell(id, b, src.sum, src.contributions);
    }
    for (int s = 0; s < num_strategies(); ++s) add_strategy_sum(id, s, other.strategy_sum(o, s));
  }
  for (std::size_t b = 0; b < batch_samples_.size(); ++b) batch_samples_[b] += other.batch_samples_[b];
  nonfinite_ += other.nonfinite_;
  add_magnitude(other.magnitude_);
  return true;
}

// --- statistics ---

Estimate batch_means(const std::vector<ExactRgb>& batch_sums, const std::vector<std::uint64_t>& batch_samples,
                     std::uint64_t contributions) {
  Estimate e;
  e.samples = contributions;
  ExactRgb total{};
  std::uint64_t n_total = 0;
  for (std::size_t b = 0; b < batch_sums.size(); ++b) {
    add_to(total, batch_sums[b]);
    n_total += batch_samples[b];
  }
  if (n_total == 0) return e;  // nothing rendered: zero estimate, unknown error
  const double n = static_cast<double>(n_total);
  const Rgb sum = to_double(total);
  e.rgb = {sum[0] / n, sum[1] / n, sum[2] / n};
  e.luminance = luminance(e.rgb);

  double squares = 0, n2 = 0;
  int nonempty = 0;
  for (std::size_t b = 0; b < batch_sums.size(); ++b) {
    if (batch_samples[b] == 0) continue;
    ++nonempty;
    const double nb = static_cast<double>(batch_samples[b]);
    const double d = luminance(to_double(batch_sums[b])) - nb * e.luminance;
    squares += d * d;
    n2 += nb * nb;
  }
  if (nonempty >= 2) e.std_error = std::sqrt(squares / (n * n - n2));
  return e;
}

namespace {

// One row of the path table: the estimate of `sums` (per batch) and each strategy's share of its
// luminance, for the strategies that contributed.
PathEstimate path_estimate(const Histogram& h, std::string name, const std::vector<ExactRgb>& sums,
                           const std::vector<std::uint64_t>& batch_samples, std::uint64_t contributions,
                           const std::vector<ExactRgb>& strategy_sums) {
  PathEstimate pe;
  pe.path = std::move(name);
  pe.estimate = batch_means(sums, batch_samples, contributions);
  ExactRgb total{};
  for (const ExactRgb& s : sums) add_to(total, s);
  const double lum = luminance(to_double(total));
  for (std::size_t s = 0; s < strategy_sums.size(); ++s) {
    if (is_zero(strategy_sums[s])) continue;
    pe.strategies.emplace_back(h.layout().strategies[s], lum != 0 ? luminance(to_double(strategy_sums[s])) / lum : 0.0);
  }
  return pe;
}

}  // namespace

Result<HistogramReport> make_report(const Histogram& h, const RunInfo& run, const Classifier* classifier,
                                    const std::vector<ClassInfo>& classes, std::optional<std::uint64_t> max_paths) {
  const int nb = h.num_batches();
  const std::size_t B = static_cast<std::size_t>(nb);
  if (!classes.empty() && (classifier == nullptr || classifier->num_classes() != static_cast<int>(classes.size())))
    return make_error(ErrorCode::kUsage, "the class list given to the report does not match the classifier");
  if (h.may_overflow())
    return make_error(ErrorCode::kLimit,
                      "the contributions are too large to be summed exactly (their magnitudes add up to more "
                      "than 2^63); the render is numerically broken");
  std::vector<std::uint64_t> n(B);
  for (int b = 0; b < nb; ++b) n[static_cast<std::size_t>(b)] = h.batch_samples(b);

  HistogramReport report;
  report.run = run;
  report.nonfinite_samples = h.nonfinite();

  std::vector<ExactRgb> total_sums(B, ExactRgb{});
  std::uint64_t total_count = 0;
  std::vector<std::vector<ExactRgb>> class_sums(classes.size(), std::vector<ExactRgb>(B, ExactRgb{}));
  std::vector<std::uint64_t> class_counts(classes.size(), 0);
  std::vector<ExactRgb> path_sums(B);

  for (Histogram::PathId p = 0; p < h.num_paths(); ++p) {
    std::uint64_t count = 0;
    for (int b = 0; b < nb; ++b) {
      const Histogram::Cell& c = h.cell(p, b);
      if (c.contributions != 0 && n[static_cast<std::size_t>(b)] == 0)
        return make_error(ErrorCode::kUsage, "batch " + std::to_string(b) +
                                                 " holds contributions but no samples were registered for it");
      path_sums[static_cast<std::size_t>(b)] = c.sum;
      add_to(total_sums[static_cast<std::size_t>(b)], c.sum);
      count += c.contributions;
    }
    total_count += count;
    if (!classes.empty()) {
      for (int k : classifier->members(classifier->classify(h.path(p)))) {
        const std::size_t ks = static_cast<std::size_t>(k);
        for (std::size_t b = 0; b < B; ++b) add_to(class_sums[ks][b], path_sums[b]);
        class_counts[ks] += count;
      }
    }
    std::vector<ExactRgb> strategy_sums(static_cast<std::size_t>(h.num_strategies()));
    for (int s = 0; s < h.num_strategies(); ++s) strategy_sums[static_cast<std::size_t>(s)] = h.strategy_sum(p, s);
    report.paths.push_back(path_estimate(h, h.path(p), path_sums, n, count, strategy_sums));
  }
  report.distinct_paths = report.paths.size();
  report.total = batch_means(total_sums, n, total_count);
  for (std::size_t k = 0; k < classes.size(); ++k) {
    ClassEstimate ce;
    ce.name = classes[k].name;
    ce.expr = classes[k].expr;
    ce.estimate = batch_means(class_sums[k], n, class_counts[k]);
    ce.share = report.total.luminance != 0 ? ce.estimate.luminance / report.total.luminance : 0.0;
    report.classes.push_back(std::move(ce));
  }
  // Rows by luminance, largest first. report.paths[i] is still path id i here, which is what
  // lets the rows past max_paths be summed from the exact cells.
  std::vector<Histogram::PathId> order(report.paths.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Histogram::PathId>(i);
  std::sort(order.begin(), order.end(), [&](Histogram::PathId a, Histogram::PathId b) {
    const PathEstimate& pa = report.paths[a];
    const PathEstimate& pb = report.paths[b];
    if (pa.estimate.luminance != pb.estimate.luminance) return pa.estimate.luminance > pb.estimate.luminance;
    return pa.path < pb.path;
  });
  report.max_paths = max_paths;
  const std::size_t listed = max_paths ? std::min<std::size_t>(order.size(), *max_paths) : order.size();
  if (listed < order.size()) {
    std::vector<ExactRgb> other_sums(B, ExactRgb{});
    std::vector<ExactRgb> other_strategy_sums(static_cast<std::size_t>(h.num_strategies()), ExactRgb{});
    std::uint64_t other_count = 0;
    for (std::size_t i = listed; i < order.size(); ++i) {
      const Histogram::PathId p = order[i];
      for (int b = 0; b < nb; ++b) {
        add_to(other_sums[static_cast<std::size_t>(b)], h.cell(p, b).sum);
        other_count += h.cell(p, b).contributions;
      }
      for (int s = 0; s < h.num_strategies(); ++s)
        add_to(other_strategy_sums[static_cast<std::size_t>(s)], h.strategy_sum(p, s));
    }
    report.other = path_estimate(h, "other", other_sums, n, other_count, other_strategy_sums);
    report.other_paths = order.size() - listed;
  }
  std::vector<PathEstimate> rows;
  rows.reserve(listed);
  for (std::size_t i = 0; i < listed; ++i) rows.push_back(std::move(report.paths[order[i]]));
  report.paths = std::move(rows);
  return report;
}

}  // namespace pathex
