// The accumulator (exact integer sums keyed by path string and batch) and the report built from
// it: estimates and their stderrs (VarianceDesign) per path, per class (sums of the paths in the
// class) and for the total.
#include "stats/histogram.h"

#include <algorithm>
#include <map>
#include <unordered_map>

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
      cells_(layout_.num_batches),
      used_(static_cast<std::size_t>(std::max(layout_.num_batches, 0)), 0),
      row_sums_(layout_.num_batches),
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
  cells_.reserve(paths);
  first_row_.reserve(paths);
}

void Histogram::reserve_rows(std::size_t rows) {
  if (rows <= rows_.capacity()) return;
  rows = std::max(rows, 2 * rows_.capacity());
  rows_.reserve(rows);
  row_sums_.reserve(rows);
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

std::vector<int> Histogram::batches_in_use() const {
  std::vector<int> used;
  for (int b = 0; b < num_batches(); ++b)
    if (batch_in_use(b)) used.push_back(b);
  return used;
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
                      "cannot merge histograms with different layouts (batch count, groups or strategy list differ)");
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

VarianceDesign::VarianceDesign(std::vector<std::uint64_t> batch_samples, int groups)
    : n_(std::move(batch_samples)), groups_(std::max(groups, 1)), scale_(static_cast<std::size_t>(groups_), 0.0) {
  const std::size_t R = n_.size() / static_cast<std::size_t>(groups_);
  for (std::size_t g = 0; g < static_cast<std::size_t>(groups_); ++g) {
    double ng = 0, squares = 0;
    int used = 0;
    for (std::size_t r = 0; r < R; ++r) {
      const double n = static_cast<double>(n_[g * R + r]);
      ng += n;
      squares += n * n;
      used += n > 0 ? 1 : 0;
    }
    total_ += ng;
    if (used < 2) continue;
    dof_ += used - 1;
    scale_[g] = std::sqrt(ng * ng / (ng * ng - squares));
  }
}

std::vector<double> VarianceDesign::deviations(const std::vector<double>& sums) const {
  const std::size_t R = n_.size() / static_cast<std::size_t>(groups_);
  std::vector<double> d(n_.size(), 0.0);
  for (std::size_t g = 0; g < static_cast<std::size_t>(groups_); ++g) {
    if (scale_[g] == 0) continue;
    double sum = 0, ng = 0;
    for (std::size_t r = 0; r < R; ++r) {
      sum += sums[g * R + r];
      ng += static_cast<double>(n_[g * R + r]);
    }
    const double mean = sum / ng;
    for (std::size_t r = 0; r < R; ++r)
      if (n_[g * R + r] != 0) d[g * R + r] = scale_[g] * (sums[g * R + r] - static_cast<double>(n_[g * R + r]) * mean);
  }
  return d;
}

int VarianceDesign::dof(const std::vector<double>& sums) const {
  const std::size_t R = n_.size() / static_cast<std::size_t>(groups_);
  int dof = 0;
  for (std::size_t g = 0; g < static_cast<std::size_t>(groups_); ++g) {
    if (scale_[g] == 0) continue;
    int used = 0;
    bool nonzero = false;
    for (std::size_t r = 0; r < R; ++r) {
      used += n_[g * R + r] != 0 ? 1 : 0;
      nonzero = nonzero || sums[g * R + r] != 0;
    }
    if (nonzero) dof += used - 1;
  }
  return dof;
}

double VarianceDesign::variance(const std::vector<double>& sums) const {
  if (dof_ < 1) return std::numeric_limits<double>::quiet_NaN();
  double squares = 0;
  for (double d : deviations(sums)) squares += d * d;
  return squares / (total_ * total_);
}

double VarianceDesign::variance_relative_error(const std::vector<double>& sums) const {
  if (groups_ == 1) {
    std::vector<double> means;
    for (std::size_t b = 0; b < n_.size(); ++b)
      if (n_[b] != 0) means.push_back(sums[b] / static_cast<double>(n_[b]));
    return pathex::variance_relative_error(means);
  }
  // The groups' terms v_g are independent estimates of their groups' parts of the variance: the
  // relative error of their sum is sqrt(G · var(v)) / Σ v, var(v) from their spread.
  const std::size_t R = n_.size() / static_cast<std::size_t>(groups_);
  const std::vector<double> d = deviations(sums);
  std::vector<double> v;
  for (std::size_t g = 0; g < static_cast<std::size_t>(groups_); ++g) {
    if (scale_[g] == 0) continue;
    double t = 0;
    for (std::size_t r = 0; r < R; ++r) t += d[g * R + r] * d[g * R + r];
    v.push_back(t);
  }
  const double G = static_cast<double>(v.size());
  if (v.size() < 4) return std::numeric_limits<double>::quiet_NaN();
  double mean = 0;
  for (double t : v) mean += t;
  mean /= G;
  if (!(mean > 0)) return std::numeric_limits<double>::quiet_NaN();
  double spread = 0;
  for (double t : v) spread += (t - mean) * (t - mean);
  return std::sqrt(spread / (G - 1) / G) / mean;
}

double variance_relative_error(const std::vector<double>& x) {
  const std::size_t n = x.size();
  if (n < 4) return std::numeric_limits<double>::quiet_NaN();
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double m2 = 0.0, m4 = 0.0;
  for (double v : x) {
    const double d2 = (v - mean) * (v - mean);
    m2 += d2;
    m4 += d2 * d2;
  }
  m2 /= static_cast<double>(n);
  m4 /= static_cast<double>(n);
  if (!(m2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double b = static_cast<double>(n);
  const double kurtosis = m4 / (m2 * m2);
  return std::sqrt(std::max(0.0, (kurtosis - (b - 3.0) / (b - 1.0)) / b));
}

Estimate estimate_of(const std::vector<ExactRgb>& batch_sums, const VarianceDesign& design, std::uint64_t contributions) {
  Estimate e;
  e.samples = contributions;
  ExactRgb total{};
  for (const ExactRgb& s : batch_sums) add_to(total, s);
  if (design.total_samples() == 0) return e;  // nothing rendered: zero estimate, unknown error
  const double n = design.total_samples();
  const Rgb sum = to_double(total);
  e.rgb = {sum[0] / n, sum[1] / n, sum[2] / n};
  e.luminance = luminance(e.rgb);
  std::vector<double> lum(batch_sums.size());
  for (std::size_t b = 0; b < batch_sums.size(); ++b) lum[b] = luminance(to_double(batch_sums[b]));
  e.std_error = std::sqrt(design.variance(lum));
  e.dof = design.dof(lum);
  e.stability = design.variance_relative_error(lum);
  return e;
}

namespace {

// The deviations of luminance sums on the grid (VarianceDesign::deviations()): a function of the
// sums alone, so that a sum compared with itself gives bit-identical deviations.
std::vector<double> batch_deviations(const std::vector<ExactSum>& sums, const VarianceDesign& design) {
  std::vector<double> d(sums.size());
  for (std::size_t b = 0; b < sums.size(); ++b) d[b] = to_double(sums[b]);
  return design.deviations(d);
}

// The techniques of a report's tables (each class, each listed path, "other"), keyed by
// Technique::code() and the chain joined (a connector's chain has the path's length), and their
// exact luminance sums. A row of the histogram adds into the entries of its key in the tables of
// its path's classes and in its path's own table (or "other"). The sums are added batch by batch
// along the histogram's batch-major row sums, in one pass: looking each row's 32 batch sums up
// for every table it belongs to was most of a 256 x 256, 16-spp report's CPU time (bench/README.md,
// issue 19). Integer sums: the order of the additions does not change them.
struct TechniqueKey {
  int code;
  std::string chain;
  bool operator<(const TechniqueKey& o) const { return code != o.code ? code < o.code : chain < o.chain; }
};

class TechniqueTables {
 public:
  TechniqueTables(const Histogram& h, std::size_t tables) : h_(h), slots_(tables), entries_(tables) {}

  // The key of each row, interned: ids dense from 0 (a plain join's chain is DD, a connector's
  // the path's letters between its ends).
  void intern_rows() {
    std::unordered_map<int, int> plain;
    std::map<TechniqueKey, int> connector;
    key_of_row_.resize(static_cast<std::size_t>(h_.num_rows()));
    for (int r = 0; r < h_.num_rows(); ++r) {
      const int code = h_.row(r).technique;
      const Technique t = Technique::from_code(code);
      int id;
      if (!t.connector) {
        const auto [it, added] = plain.try_emplace(code, static_cast<int>(keys_.size()));
        if (added) keys_.push_back({code, t.chain(h_.path(h_.row(r).path))});
        id = it->second;
      } else {
        TechniqueKey k{code, t.chain(h_.path(h_.row(r).path))};
        const auto [it, added] = connector.try_emplace(k, static_cast<int>(keys_.size()));
        if (added) keys_.push_back(std::move(k));
        id = it->second;
      }
      key_of_row_[static_cast<std::size_t>(r)] = id;
    }
  }

  // Row r adds into table `table`'s entry of its key. Rows are added in order (r never decreases),
  // a row's tables one after the other.
  void add(int r, std::size_t table) {
    const int key = key_of_row_[static_cast<std::size_t>(r)];
    std::vector<int>& slots = slots_[table];
    if (slots.empty()) slots.assign(keys_.size(), -1);
    int& e = slots[static_cast<std::size_t>(key)];
    if (e < 0) e = new_entry(key, table);
    add_to_entry(r, e);
  }
  // The same for a table whose rows all have distinct keys (one path's rows): no key is looked up.
  void add_distinct(int r, std::size_t table) {
    add_to_entry(r, new_entry(key_of_row_[static_cast<std::size_t>(r)], table));
  }

  // The sums, batch by batch (a batch nothing was added to holds zeros only), along the row sums:
  // a row adds its sum to its entries where the sum is not zero.
  void sum() {
    const std::size_t B = static_cast<std::size_t>(h_.num_batches()), E = entry_key_.size();
    const std::size_t rows = static_cast<std::size_t>(h_.num_rows());
    std::vector<std::size_t> first(rows + 1, 0);  // row r's entries: dests_[first[r], first[r + 1])
    for (const Dest& d : dests_) ++first[static_cast<std::size_t>(d.row) + 1];
    for (std::size_t r = 0; r < rows; ++r) first[r + 1] += first[r];
    sums_.assign(B * E, 0);
    for (std::size_t r = 0; r < rows; ++r)
      h_.for_each_row_sum(static_cast<int>(r), [&](int b, ExactSum s) {
        if (s == 0) return;
        ExactSum* out = sums_.data() + static_cast<std::size_t>(b) * E;
        for (std::size_t i = first[r]; i < first[r + 1]; ++i) out[static_cast<std::size_t>(dests_[i].entry)] += s;
      });
  }

  // Each technique's share of the table's whole, its samples and its part of the whole's
  // variance (TechniqueEstimate, VarianceDesign), from luminance sums, in the order of the keys.
  std::vector<TechniqueEstimate> estimates(std::size_t table, const VarianceDesign& design) const {
    const std::size_t B = static_cast<std::size_t>(h_.num_batches()), E = entry_key_.size();
    std::vector<int> entries = entries_[table];
    std::sort(entries.begin(), entries.end(), [&](int a, int b) {
      return keys_[static_cast<std::size_t>(entry_key_[static_cast<std::size_t>(a)])] <
             keys_[static_cast<std::size_t>(entry_key_[static_cast<std::size_t>(b)])];
    });
    const auto batch_sums = [&](int e) {
      std::vector<ExactSum> v(B);
      for (std::size_t b = 0; b < B; ++b) v[b] = sums_[b * E + static_cast<std::size_t>(e)];
      return v;
    };
    std::vector<ExactSum> whole(B, 0);
    for (int e : entries)
      for (std::size_t b = 0; b < B; ++b) whole[b] += sums_[b * E + static_cast<std::size_t>(e)];
    ExactSum total = 0;
    for (ExactSum s : whole) total += s;
    const double lum = to_double(total);
    const std::vector<double> dw = batch_deviations(whole, design);
    double variance = 0;
    for (double d : dw) variance += d * d;
    std::vector<TechniqueEstimate> out;
    out.reserve(entries.size());
    // Each technique's own variance, and the sum of them all.
    std::vector<std::vector<double>> deviations;
    std::vector<double> own;
    double own_sum = 0;
    for (int e : entries) {
      deviations.push_back(batch_deviations(batch_sums(e), design));
      double v = 0;
      for (double d : deviations.back()) v += d * d;
      own.push_back(v);
      own_sum += v;
    }
    std::size_t k = 0;
    for (int e : entries) {
      const std::vector<ExactSum> sums = batch_sums(e);
      ExactSum sum = 0;
      for (ExactSum s : sums) sum += s;
      const TechniqueKey& key = keys_[static_cast<std::size_t>(entry_key_[static_cast<std::size_t>(e)])];
      TechniqueEstimate te;
      te.name = Technique::from_code(key.code).name(h_.layout(), key.chain);
      te.share = lum != 0 ? to_double(sum) / lum : 0.0;
      te.samples = contributions_[static_cast<std::size_t>(e)];
      if (design.dof() >= 1 && variance > 0 && own_sum > 0) {
        const std::vector<double>& dt = deviations[k];
        te.variance_share = own[k] / own_sum;
        double covariance = 0, rest = 0;  // with the rest of the whole: dw − dt
        for (std::size_t b = 0; b < dt.size(); ++b) {
          covariance += dt[b] * (dw[b] - dt[b]);
          rest += (dw[b] - dt[b]) * (dw[b] - dt[b]);
        }
        if (own[k] > 0 && rest > 0) te.correlation = std::clamp(covariance / std::sqrt(own[k] * rest), -1.0, 1.0);
      }
      ++k;
      out.push_back(std::move(te));
    }
    return out;
  }

 private:
  struct Dest {
    int row, entry;
  };
  int new_entry(int key, std::size_t table) {
    const int e = static_cast<int>(entry_key_.size());
    entry_key_.push_back(key);
    contributions_.push_back(0);
    entries_[table].push_back(e);
    return e;
  }
  void add_to_entry(int r, int e) {
    dests_.push_back({r, e});
    contributions_[static_cast<std::size_t>(e)] += h_.row(r).contributions;
  }
  const Histogram& h_;
  std::vector<TechniqueKey> keys_;
  std::vector<int> key_of_row_;
  std::vector<std::vector<int>> slots_;    // per table: the entry of each key, -1 for none (add())
  std::vector<std::vector<int>> entries_;  // per table: its entries
  std::vector<int> entry_key_;
  std::vector<std::uint64_t> contributions_;
  std::vector<Dest> dests_;
  std::vector<ExactSum> sums_;  // batch-major: sums_[b * entries + e]
};

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
  const VarianceDesign design = h.variance_design();

  HistogramReport report;
  report.run = run;
  report.nonfinite_samples = h.nonfinite();

  std::vector<ExactRgb> total_sums(B, ExactRgb{});
  std::uint64_t total_count = 0;
  std::vector<std::vector<ExactRgb>> class_sums(classes.size(), std::vector<ExactRgb>(B, ExactRgb{}));
  std::vector<std::uint64_t> class_counts(classes.size(), 0);
  std::vector<std::uint32_t> path_set(classes.empty() ? 0 : static_cast<std::size_t>(h.num_paths()));
  std::vector<ExactRgb> path_sums(B);

  // The batches anything was added to: the others hold no cell of any path, so their sums stay
  // zero without being read.
  const std::vector<int> used = h.batches_in_use();
  for (Histogram::PathId p = 0; p < h.num_paths(); ++p) {
    std::uint64_t count = 0;
    std::fill(path_sums.begin(), path_sums.end(), ExactRgb{});
    int unregistered = -1;  // a batch that holds contributions but no samples
    h.for_each_cell(p, [&](int b, const Histogram::Cell& c) {
      if (c.contributions != 0 && n[static_cast<std::size_t>(b)] == 0 && unregistered < 0) unregistered = b;
      path_sums[static_cast<std::size_t>(b)] = c.sum;
      add_to(total_sums[static_cast<std::size_t>(b)], c.sum);
      count += c.contributions;
    });
    if (unregistered >= 0)
      return make_error(ErrorCode::kUsage, "batch " + std::to_string(unregistered) +
                                               " holds contributions but no samples were registered for it");
    total_count += count;
    if (!classes.empty()) {
      const std::uint32_t set = classifier->classify(h.path(p));
      path_set[static_cast<std::size_t>(p)] = set;
      for (int k : classifier->members(set)) {
        const std::size_t ks = static_cast<std::size_t>(k);
        for (int b : used) add_to(class_sums[ks][static_cast<std::size_t>(b)], path_sums[static_cast<std::size_t>(b)]);
        class_counts[ks] += count;
      }
    }
    // The row's techniques are worked out below, for the rows listed only.
    PathEstimate pe;
    pe.path = h.path(p);
    pe.estimate = estimate_of(path_sums, design, count);
    report.paths.push_back(std::move(pe));
  }
  report.distinct_paths = report.paths.size();
  report.total = estimate_of(total_sums, design, total_count);
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

  // --- the technique tables: one per class, one per listed row, then "other" ---
  const std::size_t other_table = classes.size() + listed;
  TechniqueTables tables(h, other_table + 1);
  tables.intern_rows();
  std::vector<std::size_t> own_table(order.size(), other_table);
  for (std::size_t i = 0; i < listed; ++i) own_table[static_cast<std::size_t>(order[i])] = classes.size() + i;
  for (int r = 0; r < h.num_rows(); ++r) {  // in the order of the row sums
    const std::size_t p = static_cast<std::size_t>(h.row(r).path);
    if (!classes.empty())
      for (int k : classifier->members(path_set[p])) tables.add(r, static_cast<std::size_t>(k));
    if (own_table[p] == other_table) tables.add(r, other_table);
    else tables.add_distinct(r, own_table[p]);
  }
  tables.sum();

  for (std::size_t k = 0; k < classes.size(); ++k) {
    ClassEstimate ce;
    ce.name = classes[k].name;
    ce.expr = classes[k].expr;
    ce.estimate = estimate_of(class_sums[k], design, class_counts[k]);
    ce.share = report.total.luminance != 0 ? ce.estimate.luminance / report.total.luminance : 0.0;
    ce.strategies = tables.estimates(k, design);
    report.classes.push_back(std::move(ce));
  }
  if (listed < order.size()) {
    // The total less the listed rows (integer sums: exactly the sum of the other rows' cells,
    // without reading the cells of every path again, in an order scattered over memory).
    std::vector<ExactRgb> other_sums = total_sums;
    std::uint64_t other_count = total_count;
    for (std::size_t i = 0; i < listed; ++i) {
      const Histogram::PathId p = order[i];
      for (int b : used) {
        const Histogram::Cell& c = h.cell(p, b);
        for (std::size_t ch = 0; ch < 3; ++ch) other_sums[static_cast<std::size_t>(b)][ch] -= c.sum[ch];
        other_count -= c.contributions;
      }
    }
    PathEstimate pe;
    pe.path = "other";
    pe.estimate = estimate_of(other_sums, design, other_count);
    pe.strategies = tables.estimates(other_table, design);
    report.other = std::move(pe);
    report.other_paths = order.size() - listed;
  }
  std::vector<PathEstimate> rows;
  rows.reserve(listed);
  for (std::size_t i = 0; i < listed; ++i) {
    rows.push_back(std::move(report.paths[order[i]]));
    rows.back().strategies = tables.estimates(classes.size() + i, design);
  }
  report.paths = std::move(rows);
  return report;
}

}  // namespace pathex
