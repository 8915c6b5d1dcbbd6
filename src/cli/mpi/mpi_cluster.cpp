// pathex-mpi: the pathex command line with `trace` split across MPI ranks (built when CMake finds
// MPI, e.g. Debian's OpenMPI). Each rank renders its part of the passes with TBB inside; the
// exact integer sums are then added on rank 0 by MPI reductions (a user operation adding 128-bit
// integers, which is associative and commutative, so the result does not depend on the order MPI
// combines ranks in), and rank 0 writes the outputs: the same bytes as one process.
//
// What is reduced, in this order:
//   paths      the union of the ranks' path strings (gathered on rank 0, sorted, broadcast), so that
//              every rank lays its histogram out in the same order;
//   histogram  the union of the (path, batch) cells and the paths' strategy sums that are nonzero
//              on some rank (a bitwise-or reduction), then those: per cell the sums and the
//              contribution count, per path the strategy sums; per batch the sample counts and
//              the non-finite count: one 128-bit sum each; the magnitude bound (saturating)
//              gathered on rank 0;
//   images     the union of the (plane, tile) pairs some rank touched (a bitwise-or reduction),
//              then those tiles' words, in blocks of at most 4096 tiles (12 MiB);
//   connectors the connector statistics' counts (ConnectorStats::counts_of), 64-bit sums;
//   passes     gathered on rank 0 as [first, last) pairs.
// Rank 0 contributes zeros and adds the reduced sums of the others into its own accumulators.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "cli/mpi/mpi_cluster.h"

namespace pathex::cli {
namespace {

using Word = std::uint64_t;

// inout[i] += in[i] for 128-bit integers stored as (low, high) word pairs.
extern "C" void add_u128(void* in, void* inout, int* len, MPI_Datatype*) {
  const auto* a = static_cast<const Word*>(in);
  auto* b = static_cast<Word*>(inout);
  for (int i = 0; i < *len; ++i) {
    const Word lo = a[2 * i] + b[2 * i];
    b[2 * i + 1] += a[2 * i + 1] + (lo < a[2 * i] ? 1 : 0);
    b[2 * i] = lo;
  }
}

void put(Word* w, ExactSum x) {
  w[0] = static_cast<Word>(x);
  w[1] = static_cast<Word>(x >> 64);
}
ExactSum get(const Word* w) { return (static_cast<ExactSum>(w[1]) << 64) | static_cast<ExactSum>(w[0]); }

}  // namespace

MpiCluster::MpiCluster() {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Type_contiguous(2, MPI_UINT64_T, &u128_);
  MPI_Type_commit(&u128_);
  MPI_Op_create(&add_u128, /*commute=*/1, &add_);
}

MpiCluster::~MpiCluster() {
  MPI_Op_free(&add_);
  MPI_Type_free(&u128_);
}

Result<bool> MpiCluster::check(int code, const char* what) const {
  if (code == MPI_SUCCESS) return true;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  return make_error(ErrorCode::kBadFile, "rank " + std::to_string(rank_) + ": MPI " + what + " failed: " + std::string(text, static_cast<std::size_t>(len)));
}

Result<bool> MpiCluster::wait_for_all(const char* what) {
  MPI_Request request{};
  if (Result<bool> r = check(MPI_Ibarrier(MPI_COMM_WORLD, &request), what); !r) return r;
  // Polls every 0.25 ms at first, backing off to every 8 ms: a wake-up costs some 30 µs of CPU
  // here (a virtual machine), and a rank that waits seconds for a slower one polled 1000 times a
  // second (38 ms of CPU in a 128-spp run of the Cornell box); the added latency is at most 8 ms.
  for (std::chrono::microseconds pause(250);; pause = std::min(2 * pause, std::chrono::microseconds(8000))) {
    int done = 0;
    if (Result<bool> r = check(MPI_Test(&request, &done, MPI_STATUS_IGNORE), what); !r) return r;
    if (done != 0) return true;
    std::this_thread::sleep_for(pause);
  }
}

Result<bool> MpiCluster::sum_to_root(std::vector<Word>* words) {
  if (rank_ == 0) std::fill(words->begin(), words->end(), 0);  // rank 0 adds the others' into its own
  std::vector<Word> out(rank_ == 0 ? words->size() : 0);
  const std::size_t pairs = words->size() / 2;
  constexpr std::size_t kBlock = std::size_t{1} << 20;  // pairs per call, within MPI's int counts
  for (std::size_t at = 0; at < pairs; at += kBlock) {
    const int n = static_cast<int>(std::min(kBlock, pairs - at));
    Result<bool> r = check(MPI_Reduce(words->data() + 2 * at, rank_ == 0 ? out.data() + 2 * at : nullptr, n, u128_, add_, 0,
                                      MPI_COMM_WORLD),
                           "reduce");
    if (!r) return r;
  }
  words->swap(out);
  return true;
}

Result<bool> MpiCluster::or_all(const std::vector<unsigned char>& flags, std::vector<unsigned char>* any) {
  for (std::size_t at = 0; at < flags.size(); at += std::size_t{1} << 30) {
    const int n = static_cast<int>(std::min(flags.size() - at, std::size_t{1} << 30));
    if (Result<bool> r = check(MPI_Allreduce(flags.data() + at, any->data() + at, n, MPI_UNSIGNED_CHAR, MPI_BOR, MPI_COMM_WORLD), "reduce");
        !r)
      return r;
  }
  return true;
}

Result<bool> MpiCluster::reduce(RenderSums* sums, PassSet* passes, ShardRun* run) {
  if (Result<bool> r = wait_for_all("barrier before the reduction"); !r) return r;
  Histogram& h = sums->histogram;
  // --- the union of the path strings and of the (path, technique) rows ("path\tcode"), on every rank ---
  std::string mine;
  for (int p = 0; p < h.num_paths(); ++p) {
    mine += h.path(p) + "\n";
    for (int r = h.first_row(p); r >= 0; r = h.row(r).next) mine += h.path(p) + "\t" + std::to_string(h.row(r).technique) + "\n";
  }
  const int my_size = static_cast<int>(mine.size());
  std::vector<int> sizes(static_cast<std::size_t>(size_)), offsets(static_cast<std::size_t>(size_));
  if (Result<bool> r = check(MPI_Gather(&my_size, 1, MPI_INT, sizes.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "gather"); !r) return r;
  std::string all;
  if (rank_ == 0) {
    int total = 0;
    for (int i = 0; i < size_; ++i) offsets[static_cast<std::size_t>(i)] = total, total += sizes[static_cast<std::size_t>(i)];
    all.resize(static_cast<std::size_t>(total));
  }
  if (Result<bool> r = check(MPI_Gatherv(mine.data(), my_size, MPI_CHAR, all.data(), sizes.data(), offsets.data(), MPI_CHAR, 0,
                                         MPI_COMM_WORLD),
                             "gather");
      !r)
    return r;
  std::vector<std::string> paths;
  std::string joined;
  if (rank_ == 0) {
    for (std::size_t at = 0; at < all.size();) {
      const std::size_t nl = all.find('\n', at);
      paths.push_back(all.substr(at, nl - at));
      at = nl + 1;
    }
    std::sort(paths.begin(), paths.end());
    paths.erase(std::unique(paths.begin(), paths.end()), paths.end());
    for (const std::string& p : paths) joined += p + "\n";
  }
  std::uint64_t joined_size = joined.size();
  if (Result<bool> r = check(MPI_Bcast(&joined_size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "broadcast"); !r) return r;
  joined.resize(joined_size);
  if (Result<bool> r = check(MPI_Bcast(joined.data(), static_cast<int>(joined_size), MPI_CHAR, 0, MPI_COMM_WORLD), "broadcast"); !r)
    return r;
  if (rank_ != 0)
    for (std::size_t at = 0; at < joined.size();) {
      const std::size_t nl = joined.find('\n', at);
      paths.push_back(joined.substr(at, nl - at));
      at = nl + 1;
    }

  // --- the histogram's sums: only the cells some rank holds ---
  // Most of a path's B batch cells are empty (a rare path lands in few batches), so the ranks
  // first agree on which cells are nonzero on any rank (a bitwise-or reduction of one byte each)
  // and then reduce those alone: 2.4 MB instead of 28 MB for the 13,302 paths of the Cornell box
  // at 128 spp (bench/README.md, "MPI"). A path line has B cells of 8 words (RGB sums and the
  // contribution count); a (path, technique) row line has one cell of 2B + 2 words (its B
  // per-batch luminance sums and its contribution count) in its first column.
  const int B = h.num_batches();
  const std::size_t columns = std::max<std::size_t>(static_cast<std::size_t>(B), 1);
  const std::size_t path_cell = 8, row_cell = 2 * static_cast<std::size_t>(B) + 2;
  // A row line's path and technique.
  const auto split = [](const std::string& line, std::size_t tab) {
    return std::pair<std::string, int>(line.substr(0, tab), std::stoi(line.substr(tab + 1)));
  };
  std::vector<Histogram::PathId> ids(paths.size(), -1);
  std::vector<int> rows(paths.size(), -1);  // a row line's row here, -1 if this rank has none
  std::vector<char> is_row(paths.size(), 0);
  std::vector<unsigned char> held(paths.size() * columns, 0), any_held(held.size(), 0);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (const std::size_t tab = paths[i].find('\t'); tab != std::string::npos) {
      is_row[i] = 1;
      const auto [p, code] = split(paths[i], tab);
      const std::optional<Histogram::PathId> id = h.find(p);
      for (int r = id ? h.first_row(*id) : -1; r >= 0 && rows[i] < 0; r = h.row(r).next)
        if (h.row(r).technique == code) rows[i] = r;
      held[i * columns] = rows[i] >= 0 ? 1 : 0;
      continue;
    }
    const std::optional<Histogram::PathId> id = h.find(paths[i]);
    if (!id) continue;
    ids[i] = *id;
    for (int b = 0; b < B; ++b) {
      const Histogram::Cell& cell = h.cell(*id, b);
      held[i * columns + static_cast<std::size_t>(b)] = cell.contributions != 0 || !is_zero(cell.sum);
    }
  }
  if (Result<bool> r = or_all(held, &any_held); !r) return r;
  std::size_t n_words = 2 * (static_cast<std::size_t>(B) + 1);  // batch sample counts, non-finite count
  for (std::size_t i = 0; i < any_held.size(); ++i)
    if (any_held[i] != 0) n_words += is_row[i / columns] != 0 ? row_cell : path_cell;
  std::vector<Word> words(n_words, 0);
  Word* w = words.data();
  for (std::size_t i = 0; i < paths.size(); ++i)
    for (std::size_t c = 0; c < columns; ++c) {
      if (any_held[i * columns + c] == 0) continue;
      if (is_row[i] != 0) {
        if (rows[i] >= 0) {  // else zeros
          for (int b = 0; b < B; ++b) put(w + 2 * static_cast<std::size_t>(b), h.row_sum(rows[i], b));
          put(w + 2 * static_cast<std::size_t>(B), h.row(rows[i]).contributions);
        }
        w += row_cell;
        continue;
      }
      if (held[i * columns + c] != 0) {  // else zeros
        const Histogram::Cell& cell = h.cell(ids[i], static_cast<int>(c));
        put(w, cell.sum[0]), put(w + 2, cell.sum[1]), put(w + 4, cell.sum[2]), put(w + 6, cell.contributions);
      }
      w += path_cell;
    }
  for (int b = 0; b < B; ++b, w += 2) put(w, h.batch_samples(b));
  put(w, h.nonfinite());
  if (Result<bool> r = sum_to_root(&words); !r) return r;
  std::vector<Word> magnitudes(2 * static_cast<std::size_t>(size_));
  const Word my_magnitude[2] = {static_cast<Word>(h.magnitude()), static_cast<Word>(h.magnitude() >> 64)};
  if (Result<bool> r = check(MPI_Gather(my_magnitude, 2, MPI_UINT64_T, magnitudes.data(), 2, MPI_UINT64_T, 0, MPI_COMM_WORLD), "gather");
      !r)
    return r;
  if (rank_ == 0) {
    const Word* r = words.data();
    std::vector<ExactSum> row_sums(static_cast<std::size_t>(B));
    for (std::size_t i = 0; i < paths.size(); ++i) {
      if (is_row[i] != 0) {
        if (any_held[i * columns] == 0) continue;
        const auto [p, code] = split(paths[i], paths[i].find('\t'));
        for (int b = 0; b < B; ++b, r += 2) row_sums[static_cast<std::size_t>(b)] = get(r);
        h.add_technique(h.intern(p), code, static_cast<std::uint64_t>(get(r)), row_sums.data());
        r += 2;
        continue;
      }
      // Every path of the union, held or not: a path string with no nonzero sum is still one of the
      // render's distinct paths.
      const Histogram::PathId id = ids[i] >= 0 ? ids[i] : h.intern(paths[i]);
      for (std::size_t c = 0; c < columns; ++c) {
        if (any_held[i * columns + c] == 0) continue;
        h.add_cell(id, static_cast<int>(c), {get(r), get(r + 2), get(r + 4)}, static_cast<std::uint64_t>(get(r + 6)));
        r += 8;
      }
    }
    for (int b = 0; b < B; ++b, r += 2) h.add_samples(b, static_cast<std::uint64_t>(get(r)));
    h.add_nonfinite(static_cast<std::uint64_t>(get(r)));
    for (int i = 1; i < size_; ++i) h.add_magnitude(get(&magnitudes[2 * static_cast<std::size_t>(i)]));
  }

  // --- the images: the tiles any rank touched, in blocks ---
  ClassImages& im = sums->images;
  const std::size_t planes = im.num_planes(), tiles = im.num_tiles();
  std::vector<unsigned char> touched(planes * tiles), any(planes * tiles);
  for (std::size_t p = 0; p < planes; ++p)
    for (std::size_t t = 0; t < tiles; ++t) touched[p * tiles + t] = im.tile_words(p, t) != nullptr ? 1 : 0;
  if (Result<bool> r = or_all(touched, &any); !r) return r;
  std::vector<std::size_t> cells;
  for (std::size_t i = 0; i < any.size(); ++i)
    if (any[i] != 0) cells.push_back(i);
  constexpr std::size_t kTilesPerBlock = 4096;
  for (std::size_t at = 0; at < cells.size(); at += kTilesPerBlock) {
    const std::size_t n = std::min(kTilesPerBlock, cells.size() - at);
    std::vector<Word> block(n * ClassImages::kTileWords, 0);
    for (std::size_t k = 0; k < n; ++k)
      if (const Word* src = im.tile_words(cells[at + k] / tiles, cells[at + k] % tiles))
        std::memcpy(block.data() + k * ClassImages::kTileWords, src, ClassImages::kTileWords * sizeof(Word));
    if (Result<bool> r = sum_to_root(&block); !r) return r;
    if (rank_ == 0)
      for (std::size_t k = 0; k < n; ++k)
        im.add_tile(cells[at + k] / tiles, cells[at + k] % tiles, block.data() + k * ClassImages::kTileWords);
  }

  // --- the connector statistics: the same strategies on every rank, their counts summed ---
  std::vector<Word> counts, total(sums->connectors.size() * ConnectorStats::kCounts);
  for (const ConnectorStats& c : sums->connectors)
    for (const std::uint64_t* n : ConnectorStats::counts_of(c)) counts.push_back(*n);
  if (!counts.empty()) {
    if (Result<bool> r = check(MPI_Reduce(counts.data(), total.data(), static_cast<int>(counts.size()), MPI_UINT64_T, MPI_SUM, 0,
                                          MPI_COMM_WORLD),
                               "reduce");
        !r)
      return r;
    if (rank_ == 0)
      for (std::size_t i = 0; i < sums->connectors.size(); ++i) {
        const auto to = ConnectorStats::counts_of(sums->connectors[i]);
        for (std::size_t k = 0; k < ConnectorStats::kCounts; ++k) *to[k] = total[i * ConnectorStats::kCounts + k];
      }
  }

  // --- passes and run figures ---
  std::vector<Word> ranges;
  for (const PassRange& r : passes->ranges()) ranges.push_back(r.first), ranges.push_back(r.last);
  const int my_count = static_cast<int>(ranges.size());
  if (Result<bool> r = check(MPI_Gather(&my_count, 1, MPI_INT, sizes.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "gather"); !r) return r;
  std::vector<Word> all_ranges;
  if (rank_ == 0) {
    int total = 0;
    for (int i = 0; i < size_; ++i) offsets[static_cast<std::size_t>(i)] = total, total += sizes[static_cast<std::size_t>(i)];
    all_ranges.resize(static_cast<std::size_t>(total));
  }
  if (Result<bool> r = check(MPI_Gatherv(ranges.data(), my_count, MPI_UINT64_T, all_ranges.data(), sizes.data(), offsets.data(),
                                         MPI_UINT64_T, 0, MPI_COMM_WORLD),
                             "gather");
      !r)
    return r;
  for (std::size_t i = 0; i + 1 < all_ranges.size(); i += 2) passes->add(all_ranges[i], all_ranges[i + 1]);
  double time_max = 0;
  std::uint64_t rays = 0;
  int threads = 0;
  if (Result<bool> r = check(MPI_Reduce(&run->time_s, &time_max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (Result<bool> r = check(MPI_Reduce(&run->rays, &rays, 1, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (Result<bool> r = check(MPI_Reduce(&run->threads, &threads, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  double cpu_sum = 0.0;
  if (Result<bool> r = check(MPI_Reduce(&run->cpu_s, &cpu_sum, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (rank_ == 0) *run = {time_max, threads, rays, cpu_sum};
  return true;
}

int MpiCluster::count_failures(bool ok) {
  int failed = ok ? 0 : 1, total = 0;
  if (!wait_for_all("barrier after the outputs").ok()) return size_;
  if (MPI_Allreduce(&failed, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD) != MPI_SUCCESS) return size_;
  return total;
}

}  // namespace pathex::cli
