// Exact per-class framebuffers: 128-bit fixed-point channels added with two atomic fetch-adds
// (see image.h for why the carry is exact), a per-thread PixelSum, and conversion to floats.
#include "classify/image.h"

#include <algorithm>
#include <atomic>

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

ExactSum load(const std::uint64_t* words) {
  return (static_cast<ExactSum>(words[1]) << 64) | static_cast<ExactSum>(words[0]);
}

}  // namespace

ClassImages::ClassImages(int width, int height, const Classifier* classifier, const std::vector<int>& layer_classes)
    : width_(std::max(width, 0)), height_(std::max(height, 0)) {
  names_.push_back("total");
  for (int k : layer_classes) names_.push_back(classifier->name(k));
  const int num_sets = classifier != nullptr ? classifier->num_sets() : 1;
  layers_of_set_.resize(static_cast<std::size_t>(num_sets));
  for (int s = 0; s < num_sets; ++s) {
    std::vector<int>& layers = layers_of_set_[static_cast<std::size_t>(s)];
    layers.push_back(0);
    if (classifier == nullptr) continue;
    for (int k : classifier->members(static_cast<std::uint32_t>(s))) {
      for (std::size_t i = 0; i < layer_classes.size(); ++i)
        if (layer_classes[i] == k) layers.push_back(static_cast<int>(i) + 1);
    }
    std::sort(layers.begin(), layers.end());
  }
  words_.assign(static_cast<std::size_t>(num_layers()) * static_cast<std::size_t>(width_) *
                    static_cast<std::size_t>(height_) * 6,
                0);
}

const std::vector<int>& ClassImages::layers_of_set(std::uint32_t set) const {
  // An unknown set id is a caller's bug; its contribution still belongs to the total.
  return set < layers_of_set_.size() ? layers_of_set_[set] : total_only();
}

const std::vector<int>& ClassImages::total_only() {
  static const std::vector<int> layers = {0};
  return layers;
}

bool ClassImages::add(int x, int y, std::uint32_t set, const ExactRgb& c) {
  if (!inside(x, y)) return false;
  for (int layer : layers_of_set(set)) {
    std::uint64_t* w = &words_[word_index(layer, x, y)];
    for (std::size_t ch = 0; ch < 3; ++ch)
      if (c[ch] != 0) atomic_add(w + 2 * ch, c[ch]);
  }
  return true;
}

bool ClassImages::add_to_layer(int layer, int x, int y, const ExactRgb& c) {
  if (!inside(x, y) || layer < 0 || layer >= num_layers()) return false;
  std::uint64_t* w = &words_[word_index(layer, x, y)];
  for (std::size_t ch = 0; ch < 3; ++ch)
    if (c[ch] != 0) atomic_add(w + 2 * ch, c[ch]);
  return true;
}

Result<bool> ClassImages::merge(const ClassImages& other) {
  if (other.width_ != width_ || other.height_ != height_ || other.names_ != names_)
    return make_error(ErrorCode::kUsage, "cannot merge images of different sizes or layers");
  for (std::size_t i = 0; i < words_.size(); i += 2) {
    const ExactSum v = load(&words_[i]) + load(&other.words_[i]);
    words_[i] = static_cast<std::uint64_t>(v);
    words_[i + 1] = static_cast<std::uint64_t>(v >> 64);
  }
  return true;
}

ExactRgb ClassImages::sum(int layer, int x, int y) const {
  const std::uint64_t* w = &words_[word_index(layer, x, y)];
  return {load(w), load(w + 2), load(w + 4)};
}

ImageLayer ClassImages::layer(int layer, double scale) const {
  ImageLayer out;
  out.name = names_[static_cast<std::size_t>(layer)];
  out.image.width = width_;
  out.image.height = height_;
  out.image.rgb.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 3);
  const std::uint64_t* w = &words_[word_index(layer, 0, 0)];
  for (std::size_t i = 0; i < out.image.rgb.size(); ++i)
    out.image.rgb[i] = static_cast<float>(to_double(load(w + 2 * i)) * scale);
  return out;
}

std::vector<ImageLayer> ClassImages::layers(double scale) const {
  std::vector<ImageLayer> out;
  for (int l = 0; l < num_layers(); ++l) out.push_back(layer(l, scale));
  return out;
}

// --- PixelSum ---

ClassImages::PixelSum::PixelSum(const ClassImages& images)
    : images_(&images),
      sums_(static_cast<std::size_t>(images.num_layers()), ExactRgb{}),
      is_touched_(static_cast<std::size_t>(images.num_layers()), 0) {}

void ClassImages::PixelSum::add(std::uint32_t set, const ExactRgb& c) {
  for (auto& [s, sum] : by_set_)
    if (s == set) {
      add_to(sum, c);
      return;
    }
  by_set_.push_back({set, c});
}

bool ClassImages::PixelSum::flush(ClassImages& images, int x, int y) {
  for (const auto& [set, sum] : by_set_)
    for (int layer : images_->layers_of_set(set)) {
      const auto l = static_cast<std::size_t>(layer);
      add_to(sums_[l], sum);
      if (!is_touched_[l]) {
        is_touched_[l] = 1;
        touched_.push_back(layer);
      }
    }
  by_set_.clear();
  bool ok = true;
  for (int layer : touched_) {
    const auto l = static_cast<std::size_t>(layer);
    if (!images.add_to_layer(layer, x, y, sums_[l])) ok = false;
    sums_[l] = ExactRgb{};
    is_touched_[l] = 0;
  }
  touched_.clear();
  return ok;
}

}  // namespace pathex
