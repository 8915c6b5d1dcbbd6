// Per-class images: one RGB framebuffer for the total and one per requested class, accumulated
// with the same exact fixed-point sums as the histogram (stats/histogram.h), so that the
// images, too, are bit-identical whatever the thread count and merge order.
//
// Storage is per class set, not per layer: a contribution belongs to exactly one class set (the
// set of classes its path is in, Histogram::class_set), so it is added once, to that set's plane,
// whatever the number of class layers; a layer is the sum of the planes of the sets that contain
// its class (the total: of all planes), formed only when read. Sets with the same layers share a
// plane (without class layers there is one plane, the total's). Planes are allocated in 8 × 8-pixel
// tiles (carved from a ZeroedArena, film/zeroed_arena.h), each the first time a contribution lands
// in it, so memory is 48 bytes per pixel per combination of layers, counted only over the tiles
// where that combination occurs (rare combinations, and there are hundreds with twenty
// overlapping classes, cost a few tiles).
//
// Any thread may add to any pixel at any time — camera samples to their own pixel, light-tracing
// splats anywhere — without locks and without per-thread copies of the frame: each channel is a
// 128-bit integer held as two 64-bit words, added with two relaxed atomic fetch-adds. The low
// word's fetch-add returns its exact previous value in the word's modification order, so the
// thread whose addition wraps it (and only that thread) carries 1 into the high word; when all
// adds are done both words hold the exact sum. Integer addition commutes, so the interleaving
// does not matter. A camera sample contributes to its own pixel several times (one contribution
// per bounce or strategy); PixelSum collects those with plain integer adds and reaches the shared
// frame in one atomic add per class set it touched.
//
// The contribution convention is the histogram's: what a sample adds to one pixel's sum before
// the division by the pixel's sample count. layer() applies that division (scale = 1 / spp), so
// the mean of the total layer equals the histogram's total estimate.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "stats/histogram.h"
#include "core/error.h"
#include "film/zeroed_arena.h"

namespace pathex {

// A finished RGB float image: row-major from the top row, three floats per pixel.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
  float at(int x, int y, int channel) const {
    return rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3 +
               static_cast<std::size_t>(channel)];
  }
};

struct ImageLayer {
  std::string name;  // "total" or a class name
  RgbImage image;
};

class ClassImages {
 public:
  // Layer 0 is "total"; then one layer per entry of `layer_classes` (indices of classifier
  // classes, named after them). `classifier` may be null when `layer_classes` is empty.
  ClassImages(int width, int height, const Classifier* classifier, const std::vector<int>& layer_classes);
  ~ClassImages();
  ClassImages(ClassImages&& other) noexcept;
  ClassImages& operator=(ClassImages&& other) noexcept;
  ClassImages(const ClassImages&) = delete;
  ClassImages& operator=(const ClassImages&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  int num_layers() const { return static_cast<int>(names_.size()); }
  const std::string& layer_name(int layer) const { return names_[static_cast<std::size_t>(layer)]; }

  // Adds a contribution of a path in class set `set` (Histogram::class_set) to pixel (x, y): it
  // shows in the total and in the layers of its classes. Thread-safe and lock-free. Returns
  // false, adding nothing, for a pixel outside the image. A set id the classifier does not know
  // (a caller's bug) still counts in the total.
  bool add(int x, int y, std::uint32_t set, const ExactRgb& c);
  // The SplatBuffer size that holds every (plane, pixel) of this image without evicting, at most
  // SplatBuffer::kMaxEntries.
  std::size_t splat_entries() const;
  std::uint64_t splat_keys() const;  // planes × pixels: the keys a SplatBuffer sees

  // Adds another image of the same size and layers (e.g. from another process). Exact.
  Result<bool> merge(const ClassImages& other);

  // The exact sum in a pixel of a layer (read after all writers are done).
  ExactRgb sum(int layer, int x, int y) const;
  // The layer as floats, each pixel's sum times `scale` (1 / spp for the pixel's mean).
  ImageLayer layer(int layer, double scale) const;
  // Rows [y0, y0 + rows) of the layer as floats (as layer() has them) into `out`, rows × width × 3
  // floats: writers that go a band of rows at a time never hold the whole layer. Fastest with y0 a
  // multiple of kTile (a tile's planes are summed once per call that covers it).
  void layer_rows(int layer, double scale, int y0, int rows, float* out) const;
  std::vector<ImageLayer> layers(double scale) const;  // every layer, in parallel
  // Whether layers `a` and `b` sum the same planes among those anything was added to, so that
  // their sums (and layer_rows) are equal pixel for pixel: e.g. a class that holds every path the
  // render sampled and the total. Read after all writers are done.
  bool same_sums(int a, int b) const;
  std::size_t memory_bytes() const;

  // --- the exact state, tile by tile (shard files, MPI reductions) ---
  // A plane (a combination of layers, see above) is num_tiles() tiles of kTile × kTile pixels;
  // a tile is kTileWords words: per pixel (row-major in the tile) per channel the low then the
  // high word of the 128-bit sum. Pixels of an edge tile outside the image stay zero.
  static constexpr int kTile = 8;
  static constexpr std::size_t kTileWords = kTile * kTile * 6;
  std::size_t num_planes() const { return num_slots_; }
  std::size_t num_tiles() const { return tiles_x() * static_cast<std::size_t>((height_ + kTile - 1) / kTile); }
  // The tile's words, or null when nothing was ever added to it. Read after all writers are done.
  const std::uint64_t* tile_words(std::size_t plane, std::size_t tile) const;
  // Adds kTileWords words to the tile (exactly, as 128-bit sums); not thread-safe.
  void add_tile(std::size_t plane, std::size_t tile, const std::uint64_t* words);

  // The contributions of one sample (or of all samples of one pixel) summed per plane (the class
  // sets whose classes have the same layers share one) without atomics; flush() adds them to
  // `images`, which must be the image it was made for, and clears the buffer. One per thread.
  class PixelSum {
   public:
    explicit PixelSum(const ClassImages& images) : slot_of_set_(&images.slot_of_set_) {}
    void add(std::uint32_t set, const ExactRgb& c);
    // Adds the collected sums to pixel (x, y) of `images` and clears them. Returns false (and
    // still clears) for a pixel outside the image.
    bool flush(ClassImages& images, int x, int y);

   private:
    const std::vector<std::size_t>* slot_of_set_;  // the image's, read only
    // The planes touched since the last flush and their sums, in parallel: the search for a
    // plane reads one short array (one cache line for up to 16 planes) instead of striding over
    // the 48-byte sums.
    std::vector<std::uint32_t> slots_;
    std::vector<ExactRgb> sums_;
  };

  // Contributions to arbitrary pixels (light tracing's splats) summed without atomics in a
  // direct-mapped table of (plane, pixel) entries: a pixel splatted again while its entry is held
  // costs an integer add, and the shared image gets one atomic add per channel when the entry is
  // evicted or flushed. The sums are exact, so the result does not depend on when that happens.
  // One per thread; flush() before the image is read.
  // Key k = plane × pixels + pixel goes to entry k when the table holds every key (it then never
  // evicts), else to entry (k × 0x9E3779B97F4A7C15) >> 32 modulo the size, a hash of every bit:
  // key modulo size made the same pixel of planes (size / pixels) apart always collide, and with
  // twenty class layers the hash cut the evictions of the benchmark's render from 61 k to 24 k.
  class SplatBuffer {
   public:
    static constexpr std::size_t kMaxEntries = 16384;  // 64 bytes each: 1 MiB
    SplatBuffer() : SplatBuffer(1) {}
    // `entries` rounded up to a power of two, for keys below `keys` (default: any).
    explicit SplatBuffer(std::size_t entries, std::uint64_t keys = ~std::uint64_t{0});
    // As ClassImages::add (false, adding nothing, outside the image).
    bool add(ClassImages& images, int x, int y, std::uint32_t set, const ExactRgb& c);
    void flush(ClassImages& images);
    std::uint64_t evictions() const { return evictions_; }  // entries spilled early, by add()

   private:
    struct Entry {
      std::uint64_t key = kEmpty;  // slot * pixels + pixel
      ExactRgb sum{};
    };
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
    // Moves an entry to the spill queue and empties it. The queue starts loading each spilled
    // entry's words in the image and adds them all when it is full (drain()): an evicted entry's
    // pixel is anywhere in the image, rarely in cache, and its atomic adds waited for it one by one.
    void spill(ClassImages& images, Entry& e);
    void drain();
    struct Spilled {
      std::uint64_t* words;  // the pixel's words in the entry's plane
      ExactRgb sum;
    };
    static constexpr int kSpillQueue = 16;
    std::array<Spilled, kSpillQueue> queue_{};
    int queued_ = 0;
    std::size_t index(std::uint64_t key) const {
      const std::uint64_t h = hashed_ ? (key * 0x9E3779B97F4A7C15ull) >> 32 : key;
      return static_cast<std::size_t>(h & (entries_.size() - 1));
    }
    std::vector<Entry> entries_;  // a power of two
    bool hashed_ = true;          // false: every key has its own entry
    std::uint64_t evictions_ = 0;
  };

 private:
  // A plane is a directory of 8 × 8-pixel tiles, each allocated when first touched, so that a
  // combination of layers that only a few pixels see costs only their tiles.
  using TileDirectory = std::atomic<std::uint64_t*>;  // an array of num_tiles() of these
  std::size_t tiles_x() const { return static_cast<std::size_t>((width_ + kTile - 1) / kTile); }
  std::size_t tile_index(int x, int y) const {
    return static_cast<std::size_t>(y / kTile) * tiles_x() + static_cast<std::size_t>(x / kTile);
  }
  static std::size_t in_tile_index(int x, int y) {
    return static_cast<std::size_t>((y % kTile) * kTile + x % kTile) * 6;
  }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  std::uint64_t num_pixels() const { return static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_); }
  // The six words of pixel (x, y) in the plane of `slot`, allocating on first use; or, const,
  // null when that tile was never touched.
  std::uint64_t* words(std::size_t slot, int x, int y) { return tile(slot, tile_index(x, y)) + in_tile_index(x, y); }
  std::uint64_t* tile(std::size_t slot, std::size_t tile);  // allocating on first use
  void add_to_slot(std::size_t slot, int x, int y, const ExactRgb& c);  // (x, y) inside
  const std::uint64_t* words_if_any(std::size_t slot, int x, int y) const;
  void release();

  int width_ = 0;
  int height_ = 0;
  std::vector<std::string> names_;
  std::vector<std::vector<std::size_t>> slots_of_layer_;  // layer -> the slots whose sets it sums
  std::vector<std::size_t> slot_of_set_;                  // class set -> its plane's slot
  std::size_t num_slots_ = 0;                             // distinct layer lists among the sets
  std::unique_ptr<std::atomic<TileDirectory*>[]> planes_;  // per slot, null until first used
  ZeroedArena tiles_;                                      // every tile's words
  std::unique_ptr<std::mutex> allocation_;                 // held while a directory or tile is made
};

}  // namespace pathex
