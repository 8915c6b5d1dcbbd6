// The accumulator (exact integer sums keyed by path string and batch) and the report built from
// it: batch means per path, per class (sums of the paths in the class) and for the total.
#include "classify/histogram.h"

#include <algorithm>
#include <map>

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

const Histogram::Cell Histogram::kEmptyCell{};

Histogram::Histogram(HistogramLayout layout, const Classifier* classifier)
    : layout_(std::move(layout)),
      classifier_(classifier),
      cells_(static_cast<std::size_t>(std::max(layout_.num_batches, 0))),
      row_sums_(static_cast<std::size_t>(std::max(layout_.num_batches, 0))),
      batch_samples_(static_cast<std::size_t>(std::max(layout_.num_batches, 0)), 0) {}

Histogram::PathId Histogram::intern(std::string_view path) {
  auto it = ids_.find(path);
  if (it != ids_.end()) return it->second;
  const PathId id = static_cast<PathId>(paths_.size());
  paths_.emplace_back(path);
  ids_.emplace(paths_.back(), id);
  sets_.push_back(classifier_ != nullptr ? classifier_->classify(path) : 0);
  first_row_.push_back(-1);
  return id;
}

void Histogram::reserve_paths(std::size_t paths) {
  if (paths <= paths_.capacity()) return;
  paths = std::max(paths, 2 * paths_.capacity());  // geometric, like the vectors' own growth
  paths_.reserve(paths);
  ids_.reserve(paths);
  sets_.reserve(paths);
  for (std::vector<Cell>& row : cells_) row.reserve(paths);
  first_row_.reserve(paths);
}

void Histogram::reserve_rows(std::size_t rows) {
  if (rows <= rows_.capacity()) return;
  rows = std::max(rows, 2 * rows_.capacity());
  rows_.reserve(rows);
  for (std::vector<ExactSum>& sums : row_sums_) sums.reserve(rows);
}

std::optional<Histogram::PathId> Histogram::find(std::string_view path) const {
  auto it = ids_.find(path);
  if (it == ids_.end()) return std::nullopt;
  return it->second;
}

namespace {


// a + b, saturating at cap (a, b ≤ cap). Saturation keeps the result order-independent: it is
// min(cap, Σ) whatever the order of the additions.
ExactSum add_saturating(ExactSum a, ExactSum b, ExactSum cap) { return b >= cap - a ? cap : a + b; }

}  // namespace

void Histogram::add_exact(PathId id, int batch, int strategy, const ExactRgb& c) {
  if (is_zero(c)) return;
  Cell& cell = cell_of(id, batch);
  add_to(cell.sum, c);
  ++cell.contributions;
  if (strategy != kNoStrategy) {
    const int r = technique_row(id, strategy);
    ++rows_[static_cast<std::size_t>(r)].contributions;
    row_sum_of(r, batch) += luminance_exact(c);
  }
  add_magnitude_of(c);
}

void Histogram::add_cell(PathId id, int batch, const ExactRgb& sum, std::uint64_t contributions) {
  if (contributions == 0 && is_zero(sum)) return;  // leaves an unused batch unused
  Cell& cell = cell_of(id, batch);
  add_to(cell.sum, sum);
  cell.contributions += contributions;
}

int Histogram::technique_row(PathId id, int technique) {
  int last = -1;
  for (int r = first_row_[static_cast<std::size_t>(id)]; r >= 0; r = rows_[static_cast<std::size_t>(r)].next) {
    if (rows_[static_cast<std::size_t>(r)].technique == technique) return r;
    last = r;
  }
  const int r = static_cast<int>(rows_.size());
  rows_.push_back(TechniqueRow{id, technique, 0, -1});
  (last < 0 ? first_row_[static_cast<std::size_t>(id)] : rows_[static_cast<std::size_t>(last)].next) = r;
  return r;
}

std::vector<int> Histogram::sorted_rows(PathId id) const {
  std::vector<int> out;
  for (int r = first_row(id); r >= 0; r = row(r).next) out.push_back(r);
  std::sort(out.begin(), out.end(), [&](int a, int b) { return row(a).technique < row(b).technique; });
  return out;
}

void Histogram::add_technique(PathId id, int technique, std::uint64_t contributions, const ExactSum* batch_sums) {
  const int r = technique_row(id, technique);
  rows_[static_cast<std::size_t>(r)].contributions += contributions;
  if (batch_sums == nullptr) return;
  for (int b = 0; b < num_batches(); ++b)
    if (batch_sums[b] != 0) row_sum_of(r, b) += batch_sums[b];
}

std::string Technique::chain(std::string_view path) const {
  if (!connector) return "DD";
  const std::size_t before = 1 + static_cast<std::size_t>(s), after = 1 + static_cast<std::size_t>(t);
  if (path.size() < before + after + 3) return "DS+D";
  return std::string(path.substr(before, path.size() - before - after));
}

std::string Technique::name(const HistogramLayout& layout, const std::string& chain) const {
  const std::string base = static_cast<std::size_t>(strategy) < layout.strategies.size()
                               ? layout.strategies[static_cast<std::size_t>(strategy)]
                               : "strategy " + std::to_string(strategy);
  return base + " (" + std::to_string(s) + ", " + chain + ", " + std::to_string(t) + ")";
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
      if (!other.batch_in_use(b)) continue;
      const Cell& src = other.cell(o, b);
      add_cell(id, b, src.sum, src.contributions);
    }
    std::vector<ExactSum> sums(static_cast<std::size_t>(layout_.num_batches));
    for (int r : other.sorted_rows(o)) {
      for (int b = 0; b < layout_.num_batches; ++b) sums[static_cast<std::size_t>(b)] = other.row_sum(r, b);
      add_technique(id, other.row(r).technique, other.row(r).contributions, sums.data());
    }
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

// S_b − n_b X̄ per batch for luminance sums S_b (0 for a batch without samples), X̄ = Σ S_b / N: a
// function of the sums alone, so that a sum compared with itself gives bit-identical deviations.
std::vector<double> batch_deviations(const std::vector<ExactSum>& sums, const std::vector<std::uint64_t>& n) {
  ExactSum total = 0;
  std::uint64_t n_total = 0;
  for (std::size_t b = 0; b < sums.size(); ++b) {
    total += sums[b];
    n_total += n[b];
  }
  std::vector<double> d(sums.size(), 0.0);
  if (n_total == 0) return d;
  const double mean = to_double(total) / static_cast<double>(n_total);
  for (std::size_t b = 0; b < sums.size(); ++b)
    if (n[b] != 0) d[b] = to_double(sums[b]) - static_cast<double>(n[b]) * mean;
  return d;
}

// The exact luminance sums of one technique within a path, a class or the "other" row.
struct TechniqueSums {
  std::vector<ExactSum> sums;  // per batch
  std::uint64_t contributions = 0;
};
// By Technique::code(), then the chain joined (a connector's chain has the path's length).
using TechniqueTable = std::map<std::pair<int, std::string>, TechniqueSums>;

void add_rows(const Histogram& h, Histogram::PathId p, TechniqueTable* table) {
  const std::size_t B = static_cast<std::size_t>(h.num_batches());
  for (int r = h.first_row(p); r >= 0; r = h.row(r).next) {
    const int code = h.row(r).technique;
    TechniqueSums& t = (*table)[{code, Technique::from_code(code).chain(h.path(p))}];
    t.sums.resize(B, 0);
    for (std::size_t b = 0; b < B; ++b) t.sums[b] += h.row_sum(r, static_cast<int>(b));
    t.contributions += h.row(r).contributions;
  }
}

// Each technique's share of the whole (the sum of the table's techniques), its samples and its
// part of the whole's batch-means variance (TechniqueEstimate), all from luminance sums.
std::vector<TechniqueEstimate> technique_estimates(const HistogramLayout& layout, const TechniqueTable& table,
                                                   const std::vector<std::uint64_t>& n) {
  std::vector<ExactSum> whole(n.size(), 0);
  for (const auto& [key, t] : table)
    for (std::size_t b = 0; b < whole.size(); ++b) whole[b] += t.sums[b];
  ExactSum total = 0;
  for (ExactSum s : whole) total += s;
  const double lum = to_double(total);
  const std::vector<double> dw = batch_deviations(whole, n);
  double variance = 0;
  int nonempty = 0;
  for (std::size_t b = 0; b < dw.size(); ++b) {
    variance += dw[b] * dw[b];
    nonempty += n[b] != 0 ? 1 : 0;
  }
  std::vector<TechniqueEstimate> out;
  for (const auto& [key, t] : table) {
    ExactSum sum = 0;
    for (ExactSum s : t.sums) sum += s;
    TechniqueEstimate te;
    te.name = Technique::from_code(key.first).name(layout, key.second);
    te.share = lum != 0 ? to_double(sum) / lum : 0.0;
    te.samples = t.contributions;
    if (nonempty >= 2 && variance > 0) {
      const std::vector<double> dt = batch_deviations(t.sums, n);
      double covariance = 0;
      for (std::size_t b = 0; b < dt.size(); ++b) covariance += dt[b] * dw[b];
      te.variance_share = covariance / variance;
    }
    out.push_back(std::move(te));
  }
  return out;
}

// One row of the path table: the estimate of `sums` (per batch) and what each technique adds.
PathEstimate path_estimate(const Histogram& h, std::string name, const std::vector<ExactRgb>& sums,
                           const std::vector<std::uint64_t>& batch_samples, std::uint64_t contributions,
                           const TechniqueTable& techniques) {
  PathEstimate pe;
  pe.path = std::move(name);
  pe.estimate = batch_means(sums, batch_samples, contributions);
  pe.strategies = technique_estimates(h.layout(), techniques, batch_samples);
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
  std::vector<TechniqueTable> class_techniques(classes.size());
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
        add_rows(h, p, &class_techniques[ks]);
      }
    }
    // The row's techniques are worked out below, for the rows listed only.
    PathEstimate pe;
    pe.path = h.path(p);
    pe.estimate = batch_means(path_sums, n, count);
    report.paths.push_back(std::move(pe));
  }
  report.distinct_paths = report.paths.size();
  report.total = batch_means(total_sums, n, total_count);
  for (std::size_t k = 0; k < classes.size(); ++k) {
    ClassEstimate ce;
    ce.name = classes[k].name;
    ce.expr = classes[k].expr;
    ce.estimate = batch_means(class_sums[k], n, class_counts[k]);
    ce.share = report.total.luminance != 0 ? ce.estimate.luminance / report.total.luminance : 0.0;
    ce.strategies = technique_estimates(h.layout(), class_techniques[k], n);
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
    TechniqueTable other_techniques;
    std::uint64_t other_count = 0;
    for (std::size_t i = listed; i < order.size(); ++i) {
      const Histogram::PathId p = order[i];
      for (int b = 0; b < nb; ++b) {
        add_to(other_sums[static_cast<std::size_t>(b)], h.cell(p, b).sum);
        other_count += h.cell(p, b).contributions;
      }
      add_rows(h, p, &other_techniques);
    }
    report.other = path_estimate(h, "other", other_sums, n, other_count, other_techniques);
    report.other_paths = order.size() - listed;
  }
  std::vector<PathEstimate> rows;
  rows.reserve(listed);
  for (std::size_t i = 0; i < listed; ++i) {
    rows.push_back(std::move(report.paths[order[i]]));
    TechniqueTable techniques;
    add_rows(h, order[i], &techniques);
    rows.back().strategies = technique_estimates(h.layout(), techniques, n);
  }
  report.paths = std::move(rows);
  return report;
}

}  // namespace pathex
