// Exact per-class framebuffers: 128-bit fixed-point channels added with two atomic fetch-adds
// (see image.h for why the carry is exact), a per-thread PixelSum, and conversion to floats.
#include "film/image.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <map>

#include <tbb/parallel_for.h>

namespace pathex {
namespace {

// Adds the 128-bit value v to the pair (lo, hi) = words[0], words[1]; safe against concurrent
// calls on the same pair.
void atomic_add(std::uint64_t* words, ExactSum v) {
  const auto lo = static_cast<std::uint64_t>(v);
  const auto hi = static_cast<std::uint64_t>(v >> 64);
  const std::uint64_t old = std::atomic_ref<std::uint64_t>(words[0]).fetch_add(lo, std::memory_order_relaxed);
  const std::uint64_t carry = static_cast<std::uint64_t>(old + lo < old);  // this add wrapped the low word
  const std::uint64_t high = hi + carry;
  if (high != 0) std::atomic_ref<std::uint64_t>(words[1]).fetch_add(high, std::memory_order_relaxed);
}

// Asks for the cache lines of a pixel's six words (48 bytes may straddle two lines) ahead of the
// atomic adds to them (the splat buffer's spill queue).
void request(const std::uint64_t* words) {
  __builtin_prefetch(words, 1);
  __builtin_prefetch(words + 5, 1);
}

ExactSum load(const std::uint64_t* words) {
  return (static_cast<ExactSum>(words[1]) << 64) | static_cast<ExactSum>(words[0]);
}

}  // namespace

ClassImages::ClassImages(int width, int height, const Classifier* classifier, const std::vector<int>& layer_classes)
    : width_(std::max(width, 0)), height_(std::max(height, 0)) {
  names_.push_back("total");
  for (int k : layer_classes) names_.push_back(classifier->name(k));
  // Sets whose classes have the same layers share a plane: without class layers every set lands
  // in the one plane of the total. Slot 0 holds the sets with no class layer, and unknown ids.
  const int num_sets = classifier != nullptr ? classifier->num_sets() : 1;
  std::map<std::vector<std::size_t>, std::size_t> slot_of_layers{{{}, 0}};
  slot_of_set_.assign(static_cast<std::size_t>(num_sets), 0);
  for (int set = 0; classifier != nullptr && set < num_sets; ++set) {
    std::vector<std::size_t> layers;
    for (int k : classifier->members(static_cast<std::uint32_t>(set)))
      for (std::size_t i = 0; i < layer_classes.size(); ++i)
        if (layer_classes[i] == k) layers.push_back(i + 1);
    std::sort(layers.begin(), layers.end());
    const auto [it, added] = slot_of_layers.emplace(layers, slot_of_layers.size());
    slot_of_set_[static_cast<std::size_t>(set)] = it->second;
  }
  num_slots_ = slot_of_layers.size();
  slots_of_layer_.resize(names_.size());
  for (const auto& [layers, slot] : slot_of_layers) {
    slots_of_layer_[0].push_back(slot);
    for (std::size_t layer : layers) slots_of_layer_[layer].push_back(slot);
  }
  for (auto& slots : slots_of_layer_) std::sort(slots.begin(), slots.end());
  allocation_ = std::make_unique<std::mutex>();
  planes_ = std::make_unique<std::atomic<TileDirectory*>[]>(num_slots_);
  for (std::size_t slot = 0; slot < num_slots_; ++slot) planes_[slot].store(nullptr, std::memory_order_relaxed);
}

ClassImages::~ClassImages() { release(); }

ClassImages::ClassImages(ClassImages&& other) noexcept
    : width_(other.width_),
      height_(other.height_),
      names_(std::move(other.names_)),
      slots_of_layer_(std::move(other.slots_of_layer_)),
      slot_of_set_(std::move(other.slot_of_set_)),
      num_slots_(other.num_slots_),
      planes_(std::move(other.planes_)),
      tiles_(std::move(other.tiles_)),
      allocation_(std::move(other.allocation_)) {
  other.num_slots_ = 0;
}

ClassImages& ClassImages::operator=(ClassImages&& other) noexcept {
  if (this != &other) {
    release();
    width_ = other.width_;
    height_ = other.height_;
    names_ = std::move(other.names_);
    slots_of_layer_ = std::move(other.slots_of_layer_);
    slot_of_set_ = std::move(other.slot_of_set_);
    num_slots_ = other.num_slots_;
    planes_ = std::move(other.planes_);
    tiles_ = std::move(other.tiles_);
    allocation_ = std::move(other.allocation_);
    other.num_slots_ = 0;
  }
  return *this;
}

void ClassImages::release() {
  if (!planes_) return;
  for (std::size_t slot = 0; slot < num_slots_; ++slot) {
    TileDirectory* dir = planes_[slot].load(std::memory_order_relaxed);
    if (dir == nullptr) continue;
    delete[] dir;  // its tiles are the arena's
  }
  planes_.reset();
  tiles_ = ZeroedArena();
}

std::uint64_t* ClassImages::tile(std::size_t slot, std::size_t tile) {
  if (const TileDirectory* dir = planes_[slot].load(std::memory_order_acquire))
    if (std::uint64_t* words = dir[tile].load(std::memory_order_acquire)) return words;
  // The first touch of the plane or the tile: both are made under the lock, once (the adds
  // themselves stay lock-free); the tile comes zeroed from the arena.
  const std::lock_guard<std::mutex> hold(*allocation_);
  TileDirectory* dir = planes_[slot].load(std::memory_order_acquire);
  if (dir == nullptr) {
    dir = new TileDirectory[num_tiles()];
    for (std::size_t t = 0; t < num_tiles(); ++t) dir[t].store(nullptr, std::memory_order_relaxed);
    planes_[slot].store(dir, std::memory_order_release);
  }
  std::uint64_t* words = dir[tile].load(std::memory_order_acquire);
  if (words == nullptr) {
    words = static_cast<std::uint64_t*>(tiles_.allocate(kTileWords * sizeof(std::uint64_t)));
    dir[tile].store(words, std::memory_order_release);
  }
  return words;
}

const std::uint64_t* ClassImages::tile_words(std::size_t plane, std::size_t tile) const {
  const TileDirectory* dir = planes_ ? planes_[plane].load(std::memory_order_acquire) : nullptr;
  return dir != nullptr ? dir[tile].load(std::memory_order_acquire) : nullptr;
}

void ClassImages::add_tile(std::size_t plane, std::size_t tile_id, const std::uint64_t* src) {
  std::uint64_t* dst = tile(plane, tile_id);
  for (std::size_t i = 0; i < kTileWords; i += 2) {
    const ExactSum v = load(&dst[i]) + load(&src[i]);
    dst[i] = static_cast<std::uint64_t>(v);
    dst[i + 1] = static_cast<std::uint64_t>(v >> 64);
  }
}

const std::uint64_t* ClassImages::words_if_any(std::size_t slot, int x, int y) const {
  const TileDirectory* dir = planes_ ? planes_[slot].load(std::memory_order_acquire) : nullptr;
  if (dir == nullptr) return nullptr;
  const std::uint64_t* tile = dir[tile_index(x, y)].load(std::memory_order_acquire);
  return tile != nullptr ? tile + in_tile_index(x, y) : nullptr;
}

std::size_t ClassImages::memory_bytes() const {
  std::size_t tiles = 0;
  for (std::size_t slot = 0; slot < num_slots_ && planes_; ++slot) {
    const TileDirectory* dir = planes_[slot].load(std::memory_order_acquire);
    for (std::size_t t = 0; dir != nullptr && t < num_tiles(); ++t) tiles += dir[t].load(std::memory_order_acquire) != nullptr ? 1 : 0;
  }
  return tiles * kTileWords * sizeof(std::uint64_t);
}

bool ClassImages::add(int x, int y, std::uint32_t set, const ExactRgb& c) {
  if (!inside(x, y)) return false;
  add_to_slot(set < slot_of_set_.size() ? slot_of_set_[set] : 0, x, y, c);
  return true;
}

void ClassImages::add_to_slot(std::size_t slot, int x, int y, const ExactRgb& c) {
  std::uint64_t* w = words(slot, x, y);
  for (std::size_t ch = 0; ch < 3; ++ch)
    if (c[ch] != 0) atomic_add(w + 2 * ch, c[ch]);
}

Result<bool> ClassImages::merge(const ClassImages& other) {
  if (other.width_ != width_ || other.height_ != height_ || other.names_ != names_ || other.num_slots_ != num_slots_)
    return make_error(ErrorCode::kUsage, "cannot merge images of different sizes or layers");
  for (std::size_t slot = 0; slot < num_slots_; ++slot)
    for (std::size_t t = 0; t < num_tiles(); ++t)
      if (const std::uint64_t* src = other.tile_words(slot, t)) add_tile(slot, t, src);
  return true;
}

ExactRgb ClassImages::sum(int layer, int x, int y) const {
  ExactRgb out{};
  for (std::size_t slot : slots_of_layer_[static_cast<std::size_t>(layer)]) {
    const std::uint64_t* w = words_if_any(slot, x, y);
    if (w == nullptr) continue;
    add_to(out, {load(w), load(w + 2), load(w + 4)});
  }
  return out;
}

ImageLayer ClassImages::layer(int layer, double scale) const {
  ImageLayer out;
  out.name = names_[static_cast<std::size_t>(layer)];
  out.image.width = width_;
  out.image.height = height_;
  out.image.rgb.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 3);
  layer_rows(layer, scale, 0, height_, out.image.rgb.data());
  return out;
}

void ClassImages::layer_rows(int layer, double scale, int y0, int rows, float* out) const {
  const int y1 = std::min(y0 + rows, height_);
  const std::size_t row_floats = static_cast<std::size_t>(width_) * 3;
  // Tile by tile: the exact sums of the layer's planes in the tile (most planes touch few tiles:
  // a pixel-by-pixel search of every plane cost seconds at 512 x 512 with twenty layers), then
  // its floats. Pixels of tiles no plane touched are zero.
  const std::vector<std::size_t>& slots = slots_of_layer_[static_cast<std::size_t>(layer)];
  std::array<ExactSum, kTileWords / 2> sums;
  for (int ty = y0 / kTile; ty * kTile < y1; ++ty) {
    const int row_lo = std::max(ty * kTile, y0), row_hi = std::min(ty * kTile + kTile, y1);
    for (std::size_t tx = 0; tx < tiles_x(); ++tx) {
      const std::size_t t = static_cast<std::size_t>(ty) * tiles_x() + tx;
      const int x0 = static_cast<int>(tx) * kTile, x1 = std::min(x0 + kTile, width_);
      bool any = false;
      for (std::size_t slot : slots) {
        const std::uint64_t* w = tile_words(slot, t);
        if (w == nullptr) continue;
        if (!any) sums.fill(0);
        any = true;
        for (std::size_t i = 0; i < sums.size(); ++i) sums[i] += load(w + 2 * i);
      }
      for (int y = row_lo; y < row_hi; ++y) {
        float* dst = out + static_cast<std::size_t>(y - y0) * row_floats + static_cast<std::size_t>(x0) * 3;
        if (!any) {
          std::fill(dst, dst + static_cast<std::size_t>(x1 - x0) * 3, 0.0f);
          continue;
        }
        for (int x = x0; x < x1; ++x, dst += 3) {
          const ExactSum* src = &sums[in_tile_index(x, y) / 2];
          for (std::size_t ch = 0; ch < 3; ++ch) dst[ch] = static_cast<float>(to_double(src[ch]) * scale);
        }
      }
    }
  }
}

bool ClassImages::same_sums(int a, int b) const {
  const auto used = [&](int layer) {
    std::vector<std::size_t> slots;
    for (std::size_t slot : slots_of_layer_[static_cast<std::size_t>(layer)])
      if (planes_ && planes_[slot].load(std::memory_order_acquire) != nullptr) slots.push_back(slot);
    return slots;
  };
  return used(a) == used(b);
}

std::vector<ImageLayer> ClassImages::layers(double scale) const {
  std::vector<ImageLayer> out(static_cast<std::size_t>(num_layers()));
  tbb::parallel_for(0, num_layers(), [&](int l) { out[static_cast<std::size_t>(l)] = layer(l, scale); });
  return out;
}

// --- PixelSum ---

void ClassImages::PixelSum::add(std::uint32_t set, const ExactRgb& c) {
  const auto slot = static_cast<std::uint32_t>(set < slot_of_set_->size() ? (*slot_of_set_)[set] : 0);  // as ClassImages::add
  // Without an early exit: the plane's position among a pixel's planes is unpredictable, and a
  // search that stops at it mispredicted about once per contribution.
  const std::size_t n = slots_.size();
  std::size_t at = n;
  for (std::size_t i = 0; i < n; ++i) at = slots_[i] == slot ? i : at;
  if (at < n) {
    add_to(sums_[at], c);
    return;
  }
  slots_.push_back(slot);
  sums_.push_back(c);
}

bool ClassImages::PixelSum::flush(ClassImages& images, int x, int y) {
  const bool inside = images.inside(x, y);
  if (inside)
    for (std::size_t i = 0; i < slots_.size(); ++i)
      if (!is_zero(sums_[i])) images.add_to_slot(slots_[i], x, y, sums_[i]);
  slots_.clear();
  sums_.clear();
  return inside;
}

std::uint64_t ClassImages::splat_keys() const { return num_pixels() * std::max<std::uint64_t>(num_slots_, 1); }

std::size_t ClassImages::splat_entries() const {
  return static_cast<std::size_t>(std::min<std::uint64_t>(splat_keys(), SplatBuffer::kMaxEntries));
}

ClassImages::SplatBuffer::SplatBuffer(std::size_t entries, std::uint64_t keys)
    : entries_(std::bit_ceil(std::max<std::size_t>(entries, 1))), hashed_(keys > entries_.size()) {}

bool ClassImages::SplatBuffer::add(ClassImages& images, int x, int y, std::uint32_t set, const ExactRgb& c) {
  if (!images.inside(x, y)) return false;
  const std::uint64_t slot = set < images.slot_of_set_.size() ? images.slot_of_set_[set] : 0;  // as add()
  const std::uint64_t pixel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(images.width_) + static_cast<std::uint64_t>(x);
  const std::uint64_t key = slot * images.num_pixels() + pixel;
  Entry& e = entries_[index(key)];
  if (e.key == key) {
    add_to(e.sum, c);
    return true;
  }
  evictions_ += e.key != kEmpty;
  spill(images, e);
  e.key = key;
  e.sum = c;
  return true;
}

void ClassImages::SplatBuffer::spill(ClassImages& images, Entry& e) {
  if (e.key == kEmpty) return;
  const std::uint64_t pixel = e.key % images.num_pixels(), width = static_cast<std::uint64_t>(images.width_);
  std::uint64_t* w = images.words(e.key / images.num_pixels(), static_cast<int>(pixel % width), static_cast<int>(pixel / width));
  request(w);
  queue_[static_cast<std::size_t>(queued_++)] = {w, e.sum};
  e.key = kEmpty;
  if (queued_ == kSpillQueue) drain();
}

void ClassImages::SplatBuffer::drain() {
  for (int i = 0; i < queued_; ++i) {
    const Spilled& q = queue_[static_cast<std::size_t>(i)];
    for (std::size_t ch = 0; ch < 3; ++ch)
      if (q.sum[ch] != 0) atomic_add(q.words + 2 * ch, q.sum[ch]);
  }
  queued_ = 0;
}

void ClassImages::SplatBuffer::flush(ClassImages& images) {
  for (Entry& e : entries_) spill(images, e);
  drain();
}

}  // namespace pathex
