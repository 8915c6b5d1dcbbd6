// pathex-mpi: the pathex command line with `trace` split across MPI ranks (built when CMake finds
// MPI, e.g. Debian's OpenMPI). Each rank renders, with TBB inside, the chunks of passes that the
// ranks' shared deal hands it (mpi_deal.h: whoever is free takes the next chunk); the exact integer sums are then added on rank 0 by MPI reductions (a user operation adding 128-bit
// integers, which is associative and commutative, so the result does not depend on the order MPI
// combines ranks in), and rank 0 writes the outputs: the same bytes as one process.
//
// What is reduced, in this order:
//   paths      the union of the ranks' path strings (gathered on rank 0, sorted, broadcast), so that
//              every rank lays its histogram out in the same order;
//   rows       the union of the (path, technique) rows as (index of the path above, technique code)
//              pairs, gathered on rank 0, sorted and broadcast the same way;
//   flags      one bit per (batch, path) cell, per (batch, row) luminance sum and per (image plane,
//              tile), set where this rank holds something nonzero: one bitwise-or reduction;
//   histogram  the held cells' RGB sums and the held row sums (128-bit sums, batch-major as the
//              histogram keeps them), then in one 64-bit reduction the held cells' and every
//              row's contribution counts, the batches' sample counts and the non-finite count;
//              the magnitude bound (saturating) gathered on rank 0;
//   images     the held tiles' words, in blocks of at most 4096 tiles (12 MiB);
//   connectors the connector statistics' counts (ConnectorStats::counts_of), 64-bit sums;
//   passes     gathered on rank 0 as [first, last) pairs.
// Rank 0 contributes zeros and, after the last collective (so that the others wait asleep in
// count_failures while it works), adds the reduced histogram sums into its own accumulators.
// Only the held sums travel: at 2,048 spp of the Cornell box (42 k paths, 138 k rows, B = 32) 30.5 MB
// per rank instead of 92.5 MB with dense rows (bench/README.md, "MPI's fixed cost").
#include <mpi.h>
#include <sys/mman.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cli/mpi/mpi_cluster.h"
#include "cli/mpi/mpi_deal.h"

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

// A bit set over [0, n), 64 bits a word.
struct Bits {
  explicit Bits(std::size_t n) : words((n + 63) / 64, 0) {}
  void set(std::size_t i) { words[i >> 6] |= Word{1} << (i & 63); }
  // The set bits in [begin, end), in increasing order.
  template <typename F>
  void for_each(std::size_t begin, std::size_t end, F&& f) const {
    for (std::size_t k = begin >> 6; begin < end && k <= (end - 1) >> 6; ++k) {
      Word x = words[k];
      if (k == begin >> 6) x &= ~Word{0} << (begin & 63);
      if (k == (end - 1) >> 6 && (end & 63) != 0) x &= ~Word{0} >> (64 - (end & 63));
      for (; x != 0; x &= x - 1) f((k << 6) + static_cast<std::size_t>(std::countr_zero(x)));
    }
  }
  std::size_t count(std::size_t begin, std::size_t end) const {
    std::size_t n = 0;
    for_each(begin, end, [&](std::size_t) { ++n; });
    return n;
  }
  std::vector<Word> words;
};

// Words that start as zeros without being written: fresh pages from the kernel, already zero, so
// they are touched once, by whoever fills them (the reduction's tens of megabytes: written once
// instead of zeroed and then written). Large blocks ask for transparent huge pages: a page fault
// per 2 MiB instead of per 4 KiB (on this project's virtual machines a fault costs some 30 µs, and
// 30 MB of 4 KiB pages took a tenth of a second; bench/README.md, "issue 16, sixth session").
class ZeroedWords {
 public:
  explicit ZeroedWords(std::size_t n) : n_(n), bytes_(std::max<std::size_t>(n, 1) * sizeof(Word)) {
    if (bytes_ >= kMapped) {
      void* p = ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::bad_alloc();
      ::madvise(p, bytes_, MADV_HUGEPAGE);  // advice: without it (or refused), 4 KiB pages
      p_ = static_cast<Word*>(p);
    } else {
      p_ = static_cast<Word*>(std::calloc(bytes_, 1));
      if (p_ == nullptr) throw std::bad_alloc();
    }
  }
  ~ZeroedWords() {
    if (bytes_ >= kMapped) ::munmap(p_, bytes_);
    else std::free(p_);
  }
  ZeroedWords(const ZeroedWords&) = delete;
  ZeroedWords& operator=(const ZeroedWords&) = delete;
  Word* data() { return p_; }
  const Word* data() const { return p_; }
  std::size_t size() const { return n_; }

 private:
  static constexpr std::size_t kMapped = std::size_t{4} << 20;
  std::size_t n_, bytes_;
  Word* p_ = nullptr;
};

}  // namespace

MpiCluster::MpiCluster() {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  int level = MPI_THREAD_SINGLE;
  MPI_Query_thread(&level);
  serialized_ = level >= MPI_THREAD_SERIALIZED;
  MPI_Comm_dup(MPI_COMM_WORLD, &deal_comm_);  // inherits MPI_ERRORS_RETURN
  MPI_Type_contiguous(2, MPI_UINT64_T, &u128_);
  MPI_Type_commit(&u128_);
  MPI_Op_create(&add_u128, /*commute=*/1, &add_);
}

MpiCluster::~MpiCluster() {
  MPI_Op_free(&add_);
  MPI_Type_free(&u128_);
  MPI_Comm_free(&deal_comm_);
}

std::unique_ptr<PassDealer> MpiCluster::deal(const PassSet& todo, std::uint64_t chunk, int batches) {
  if (!serialized_)  // rank 0 could not serve the others from a thread: a static share each
    return std::make_unique<ChunkDeal>(todo.part(static_cast<std::uint64_t>(rank_), static_cast<std::uint64_t>(size_)), chunk);
  if (rank_ == 0) return std::make_unique<RootDeal>(todo, chunk, static_cast<std::uint64_t>(batches), deal_comm_, size_);
  return std::make_unique<RemoteDeal>(todo.count(), deal_comm_, rank_);
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
  // Backing off to every 8 ms: a wake-up costs some 30 µs of CPU here (a virtual machine), and a
  // rank that waits seconds for a slower one polled 1000 times a second (38 ms of CPU in a 128-spp
  // run of the Cornell box); the added latency is at most 8 ms.
  return check(wait_sleeping(&request, MPI_STATUS_IGNORE, std::chrono::microseconds(8000)), what);
}

Result<bool> MpiCluster::sum_to_root(Word* words, std::size_t size) {
  // Rank 0's own words are zeros (it adds the others' into its own sums afterwards): in place, the
  // result replaces them.
  const std::size_t pairs = size / 2;
  constexpr std::size_t kBlock = std::size_t{1} << 20;  // pairs per call, within MPI's int counts
  for (std::size_t at = 0; at < pairs; at += kBlock) {
    const int n = static_cast<int>(std::min(kBlock, pairs - at));
    Word* block = words + 2 * at;
    Result<bool> r = check(MPI_Reduce(rank_ == 0 ? MPI_IN_PLACE : block, rank_ == 0 ? block : nullptr, n, u128_, add_, 0, MPI_COMM_WORLD),
                           "reduce");
    if (!r) return r;
  }
  return true;
}

Result<bool> MpiCluster::or_all(const std::vector<Word>& flags, std::vector<Word>* any) {
  for (std::size_t at = 0; at < flags.size(); at += std::size_t{1} << 30) {
    const int n = static_cast<int>(std::min(flags.size() - at, std::size_t{1} << 30));
    if (Result<bool> r = check(MPI_Allreduce(flags.data() + at, any->data() + at, n, MPI_UINT64_T, MPI_BOR, MPI_COMM_WORLD), "reduce");
        !r)
      return r;
  }
  return true;
}

template <typename T>
Result<bool> MpiCluster::gather_to_root(const std::vector<T>& mine, MPI_Datatype type, std::vector<T>* all) {
  const int my_count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), offsets(static_cast<std::size_t>(size_));
  if (Result<bool> r = check(MPI_Gather(&my_count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "gather"); !r) return r;
  all->clear();
  if (rank_ == 0) {
    int total = 0;
    for (int i = 0; i < size_; ++i) offsets[static_cast<std::size_t>(i)] = total, total += counts[static_cast<std::size_t>(i)];
    all->resize(static_cast<std::size_t>(total));
  }
  return check(MPI_Gatherv(mine.data(), my_count, type, all->data(), counts.data(), offsets.data(), type, 0, MPI_COMM_WORLD), "gather");
}

template <typename T>
Result<bool> MpiCluster::broadcast(std::vector<T>* v, MPI_Datatype type) {
  std::uint64_t n = v->size();
  if (Result<bool> r = check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "broadcast"); !r) return r;
  v->resize(n);
  return check(MPI_Bcast(v->data(), static_cast<int>(n), type, 0, MPI_COMM_WORLD), "broadcast");
}

Result<bool> MpiCluster::reduce(RenderSums* sums, PassSet* passes, ShardRun* run, const std::function<void()>& before_changing) {
  if (Result<bool> r = wait_for_all("barrier before the reduction"); !r) return r;
  Histogram& h = sums->histogram;
  const bool root = rank_ == 0;

  // --- the union of the path strings, sorted, on every rank ---
  std::vector<char> mine, all;
  for (int p = 0; p < h.num_paths(); ++p) mine.insert(mine.end(), h.path(p).begin(), h.path(p).end()), mine.push_back('\n');
  if (Result<bool> r = gather_to_root(mine, MPI_CHAR, &all); !r) return r;
  std::vector<std::string_view> paths;
  std::vector<char> joined;
  if (root) {
    for (std::size_t at = 0; at < all.size();) {
      const std::size_t nl = static_cast<std::size_t>(std::find(all.begin() + static_cast<std::ptrdiff_t>(at), all.end(), '\n') - all.begin());
      paths.emplace_back(all.data() + at, nl - at);
      at = nl + 1;
    }
    std::sort(paths.begin(), paths.end());
    paths.erase(std::unique(paths.begin(), paths.end()), paths.end());
    for (std::string_view p : paths) joined.insert(joined.end(), p.begin(), p.end()), joined.push_back('\n');
  }
  if (Result<bool> r = broadcast(&joined, MPI_CHAR); !r) return r;
  paths.clear();
  for (std::size_t at = 0; at < joined.size();) {
    const std::size_t nl = static_cast<std::size_t>(std::find(joined.begin() + static_cast<std::ptrdiff_t>(at), joined.end(), '\n') - joined.begin());
    paths.emplace_back(joined.data() + at, nl - at);
    at = nl + 1;
  }
  std::vector<Histogram::PathId> ids(paths.size(), -1);  // this rank's id of each path, -1: none
  for (std::size_t i = 0; i < paths.size(); ++i)
    if (const std::optional<Histogram::PathId> id = h.find(paths[i])) ids[i] = *id;

  // --- the union of the (path, technique) rows, as (path's index above, technique code) pairs ---
  std::vector<int> my_rows, union_rows;
  for (std::size_t i = 0; i < paths.size(); ++i)
    if (ids[i] >= 0)
      for (int r = h.first_row(ids[i]); r >= 0; r = h.row(r).next) my_rows.push_back(static_cast<int>(i)), my_rows.push_back(h.row(r).technique);
  if (Result<bool> r = gather_to_root(my_rows, MPI_INT, &union_rows); !r) return r;
  if (root) {
    std::vector<std::pair<int, int>> pairs;
    for (std::size_t k = 0; k + 1 < union_rows.size(); k += 2) pairs.emplace_back(union_rows[k], union_rows[k + 1]);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    union_rows.clear();
    for (const auto& [i, code] : pairs) union_rows.push_back(i), union_rows.push_back(code);
  }
  if (Result<bool> r = broadcast(&union_rows, MPI_INT); !r) return r;
  const std::size_t num_rows = union_rows.size() / 2;
  std::vector<int> rows(num_rows, -1);  // this rank's row of each, -1: none
  for (std::size_t k = 0; k < num_rows; ++k)
    if (const Histogram::PathId id = ids[static_cast<std::size_t>(union_rows[2 * k])]; id >= 0)
      for (int r = h.first_row(id); r >= 0 && rows[k] < 0; r = h.row(r).next)
        if (h.row(r).technique == union_rows[2 * k + 1]) rows[k] = r;

  // --- which sums are nonzero on some rank: one bit per (batch, path) cell, per (batch, row) sum
  // and per (image plane, tile), or-reduced. Most of a path's or a row's B batches are empty (a
  // rare path lands in few batches), so the sums reduced below are a fraction of the dense ones.
  // Batch-major, as the histogram keeps them: a batch's cells and row sums are one array each,
  // read here in this rank's order (each rank sets the bits of its own nonzero sums at their
  // places in the union: a batch's bits fit in cache, its sums are read in memory order) ---
  const auto B = static_cast<std::size_t>(h.num_batches());
  const std::size_t P = paths.size();
  ClassImages& im = sums->images;
  const std::size_t planes = im.num_planes(), tiles = im.num_tiles();
  const std::size_t cell_bits = B * P, row_bits = B * num_rows, n_bits = cell_bits + row_bits + planes * tiles;
  Bits held(n_bits), any_held(n_bits);
  {
    std::vector<std::size_t> place(static_cast<std::size_t>(h.num_paths())), row_place(static_cast<std::size_t>(h.num_rows()));
    for (std::size_t i = 0; i < P; ++i)
      if (ids[i] >= 0) place[static_cast<std::size_t>(ids[i])] = i;
    for (std::size_t k = 0; k < num_rows; ++k)
      if (rows[k] >= 0) row_place[static_cast<std::size_t>(rows[k])] = k;
    for (std::size_t b = 0; b < B; ++b) {
      for (std::size_t j = 0; h.batch_in_use(static_cast<int>(b)) && j < place.size(); ++j)
        if (const Histogram::Cell& cell = h.cell(static_cast<Histogram::PathId>(j), static_cast<int>(b));
            cell.contributions != 0 || !is_zero(cell.sum))
          held.set(b * P + place[j]);
      for (std::size_t r = 0; r < row_place.size(); ++r)
        if (h.row_sum(static_cast<int>(r), static_cast<int>(b)) != 0) held.set(cell_bits + b * num_rows + row_place[r]);
    }
  }
  for (std::size_t p = 0; p < planes; ++p)
    for (std::size_t t = 0; t < tiles; ++t)
      if (im.tile_words(p, t) != nullptr) held.set(cell_bits + row_bits + p * tiles + t);
  if (Result<bool> r = or_all(held.words, &any_held.words); !r) return r;

  // --- the histogram's sums, in the order of the bits: 128-bit words for the held cells' RGB sums
  // and the held row sums; 64-bit counts (their own type, summed by MPI_SUM modulo 2^64 like the
  // accumulator's) for the held cells' contributions, every row's contributions, the batches'
  // samples and the non-finite count. Rank 0 contributes zeros and adds the others' sums into its
  // own accumulators ---
  const std::size_t held_cells = any_held.count(0, cell_bits), held_row_sums = any_held.count(cell_bits, cell_bits + row_bits);
  ZeroedWords words(6 * held_cells + 2 * held_row_sums);  // zeros where this rank holds nothing
  std::vector<Word> counts(held_cells + num_rows + B + 1, 0);
  if (!root) {
    Word* w = words.data();
    Word* n = counts.data();
    for (std::size_t b = 0; b < B; ++b) {
      any_held.for_each(b * P, (b + 1) * P, [&](std::size_t bit) {
        if (const Histogram::PathId id = ids[bit - b * P]; id >= 0) {
          const Histogram::Cell& cell = h.cell(id, static_cast<int>(b));
          put(w, cell.sum[0]), put(w + 2, cell.sum[1]), put(w + 4, cell.sum[2]), *n = cell.contributions;
        }
        w += 6, ++n;
      });
      const std::size_t at = cell_bits + b * num_rows;
      any_held.for_each(at, at + num_rows, [&](std::size_t bit) {
        if (const int r = rows[bit - at]; r >= 0) put(w, h.row_sum(r, static_cast<int>(b)));
        w += 2;
      });
    }
    for (std::size_t k = 0; k < num_rows; ++k, ++n)
      if (rows[k] >= 0) *n = h.row(rows[k]).contributions;
    for (std::size_t b = 0; b < B; ++b) *n++ = h.batch_samples(static_cast<int>(b));
    *n = h.nonfinite();
  }
  if (Result<bool> r = sum_to_root(words.data(), words.size()); !r) return r;
  std::vector<Word> count_sums(root ? counts.size() : 0);
  if (Result<bool> r = check(MPI_Reduce(counts.data(), count_sums.data(), static_cast<int>(counts.size()), MPI_UINT64_T, MPI_SUM, 0,
                                        MPI_COMM_WORLD),
                             "reduce");
      !r)
    return r;
  std::vector<Word> magnitudes(2 * static_cast<std::size_t>(size_));
  const Word my_magnitude[2] = {static_cast<Word>(h.magnitude()), static_cast<Word>(h.magnitude() >> 64)};
  if (Result<bool> r = check(MPI_Gather(my_magnitude, 2, MPI_UINT64_T, magnitudes.data(), 2, MPI_UINT64_T, 0, MPI_COMM_WORLD), "gather");
      !r)
    return r;

  // --- the images: the tiles any rank touched, in blocks (rank 0 adds each block as it comes:
  // the first change to its sums) ---
  if (root && before_changing) before_changing();
  std::vector<std::size_t> touched;
  any_held.for_each(cell_bits + row_bits, n_bits, [&](std::size_t bit) { touched.push_back(bit - cell_bits - row_bits); });
  constexpr std::size_t kTilesPerBlock = 4096;
  for (std::size_t at = 0; at < touched.size(); at += kTilesPerBlock) {
    const std::size_t n = std::min(kTilesPerBlock, touched.size() - at);
    std::vector<Word> block(n * ClassImages::kTileWords, 0);
    if (!root)
      for (std::size_t k = 0; k < n; ++k)
        if (const Word* src = im.tile_words(touched[at + k] / tiles, touched[at + k] % tiles))
          std::memcpy(block.data() + k * ClassImages::kTileWords, src, ClassImages::kTileWords * sizeof(Word));
    if (Result<bool> r = sum_to_root(block.data(), block.size()); !r) return r;
    if (root)
      for (std::size_t k = 0; k < n; ++k)
        im.add_tile(touched[at + k] / tiles, touched[at + k] % tiles, block.data() + k * ClassImages::kTileWords);
  }

  // --- the connector statistics: the same strategies on every rank, their counts summed ---
  std::vector<Word> connector_counts, total(sums->connectors.size() * ConnectorStats::kCounts);
  for (const ConnectorStats& c : sums->connectors)
    for (const std::uint64_t* n : ConnectorStats::counts_of(c)) connector_counts.push_back(*n);
  if (!connector_counts.empty()) {
    if (Result<bool> r = check(MPI_Reduce(connector_counts.data(), total.data(), static_cast<int>(connector_counts.size()), MPI_UINT64_T,
                                          MPI_SUM, 0, MPI_COMM_WORLD),
                               "reduce");
        !r)
      return r;
    if (root)
      for (std::size_t i = 0; i < sums->connectors.size(); ++i) {
        const auto to = ConnectorStats::counts_of(sums->connectors[i]);
        for (std::size_t k = 0; k < ConnectorStats::kCounts; ++k) *to[k] = total[i * ConnectorStats::kCounts + k];
      }
  }

  // --- passes and run figures ---
  std::vector<Word> ranges, all_ranges;
  for (const PassRange& r : passes->ranges()) ranges.push_back(r.first), ranges.push_back(r.last);
  if (Result<bool> r = gather_to_root(ranges, MPI_UINT64_T, &all_ranges); !r) return r;
  for (std::size_t i = 0; i + 1 < all_ranges.size(); i += 2) passes->add(all_ranges[i], all_ranges[i + 1]);
  double time_max = 0;
  std::uint64_t rays = 0;
  int threads = 0;
  if (Result<bool> r = check(MPI_Reduce(&run->time_s, &time_max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (Result<bool> r = check(MPI_Reduce(&run->rays, &rays, 1, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (Result<bool> r = check(MPI_Reduce(&run->threads, &threads, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  double cpu_sum = 0.0;
  if (Result<bool> r = check(MPI_Reduce(&run->cpu_s, &cpu_sum, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD), "reduce"); !r) return r;
  if (!root) return true;
  *run = {time_max, threads, rays, cpu_sum};

  // --- rank 0 adds the others' histogram sums into its own (after the last collective, so that
  // the other ranks wait for it asleep, in count_failures, not polling in a collective) ---
  // Every path of the union, held or not: a path string with no nonzero sum is still one of the
  // render's distinct paths; and every row of the union, with its contributions.
  h.reserve_paths(P);
  h.reserve_rows(num_rows);
  for (std::size_t i = 0; i < P; ++i)
    if (ids[i] < 0) ids[i] = h.intern(paths[i]);
  const Word* n = count_sums.data() + held_cells;
  for (std::size_t k = 0; k < num_rows; ++k, ++n) {
    const Histogram::PathId id = ids[static_cast<std::size_t>(union_rows[2 * k])];
    h.add_technique(id, union_rows[2 * k + 1], *n, nullptr);
    rows[k] = h.technique_row(id, union_rows[2 * k + 1]);
  }
  const Word* w = words.data();
  const Word* c = count_sums.data();
  for (std::size_t b = 0; b < B; ++b) {
    any_held.for_each(b * P, (b + 1) * P, [&](std::size_t bit) {
      h.add_cell(ids[bit - b * P], static_cast<int>(b), {get(w), get(w + 2), get(w + 4)}, *c++), w += 6;
    });
    const std::size_t at = cell_bits + b * num_rows;
    any_held.for_each(at, at + num_rows, [&](std::size_t bit) { h.add_row_sum(rows[bit - at], static_cast<int>(b), get(w)), w += 2; });
  }
  for (std::size_t b = 0; b < B; ++b) h.add_samples(static_cast<int>(b), *n++);
  h.add_nonfinite(*n);
  for (int i = 1; i < size_; ++i) h.add_magnitude(get(&magnitudes[2 * static_cast<std::size_t>(i)]));
  return true;
}

int MpiCluster::count_failures(bool ok) {
  int failed = ok ? 0 : 1, total = 0;
  if (!wait_for_all("barrier after the outputs").ok()) return size_;
  if (MPI_Allreduce(&failed, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD) != MPI_SUCCESS) return size_;
  return total;
}

}  // namespace pathex::cli
