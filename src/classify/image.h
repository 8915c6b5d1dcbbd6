// Per-class images: one RGB framebuffer for the total and one per requested class, accumulated
// with the same exact fixed-point sums as the histogram (classify/histogram.h), so that the
// images, too, are bit-identical whatever the thread count and merge order.
//
// Any thread may add to any pixel at any time — camera samples to their own pixel, light-tracing
// splats anywhere — without locks and without per-thread copies of the frame: each channel is a
// 128-bit integer held as two 64-bit words, added with two relaxed atomic fetch-adds. The low
// word's fetch-add returns its exact previous value in the word's modification order, so the
// thread whose addition wraps it (and only that thread) carries 1 into the high word; when all
// adds are done both words hold the exact sum. Integer addition commutes, so the interleaving
// does not matter.
//
// Memory: 48 bytes per pixel per layer, one copy in all (a 512×512 image with the total and 7
// classes: 96 MiB). A camera sample contributes to its own pixel several times (one contribution
// per bounce or strategy); PixelSum collects those with plain integer adds and reaches the shared
// frame in one atomic add per touched layer, which keeps the atomics off the hot path.
//
// The contribution convention is the histogram's: what a sample adds to one pixel's sum before
// the division by the pixel's sample count. layer() applies that division (scale = 1 / spp), so
// the mean of the total layer equals the histogram's total estimate.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "classify/histogram.h"
#include "core/error.h"

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

  int width() const { return width_; }
  int height() const { return height_; }
  int num_layers() const { return static_cast<int>(names_.size()); }
  const std::string& layer_name(int layer) const { return names_[static_cast<std::size_t>(layer)]; }
  // The layers a contribution of class set `set` lands in: 0 (total) first, then its classes'.
  const std::vector<int>& layers_of_set(std::uint32_t set) const;

  // Adds a contribution of a path in class set `set` (Histogram::class_set) to pixel (x, y) of
  // the total and of the layers of its classes. Thread-safe and lock-free. Returns false, adding
  // nothing, for a pixel outside the image.
  bool add(int x, int y, std::uint32_t set, const ExactRgb& c);
  // The same for one layer only.
  bool add_to_layer(int layer, int x, int y, const ExactRgb& c);

  // Adds another image of the same size and layers (e.g. from another process). Exact.
  Result<bool> merge(const ClassImages& other);

  // The exact sum in a pixel of a layer (read after all writers are done).
  ExactRgb sum(int layer, int x, int y) const;
  // The layer as floats, each pixel's sum times `scale` (1 / spp for the pixel's mean).
  ImageLayer layer(int layer, double scale) const;
  std::vector<ImageLayer> layers(double scale) const;
  std::size_t memory_bytes() const { return words_.size() * sizeof(std::uint64_t); }

  // The contributions of one sample (or of all samples of one pixel) summed without atomics;
  // flush() adds them to the shared image and clears the buffer. One per thread.
  class PixelSum {
   public:
    explicit PixelSum(const ClassImages& images);
    void add(std::uint32_t set, const ExactRgb& c);
    // Adds the collected sums to pixel (x, y) of `images` and clears them. Returns false (and
    // still clears) for a pixel outside the image.
    bool flush(ClassImages& images, int x, int y);

   private:
    // Contributions are summed per class set (a pixel sees few distinct sets) and expanded into
    // layers only at flush(), so adding costs one sum whatever the number of class layers.
    const ClassImages* images_;
    std::vector<std::pair<std::uint32_t, ExactRgb>> by_set_;  // class sets touched since the last flush
    std::vector<ExactRgb> sums_;     // per layer, used during flush()
    std::vector<int> touched_;       // layers with a nonzero sum during flush()
    std::vector<std::uint8_t> is_touched_;
  };

 private:
  std::size_t word_index(int layer, int x, int y) const {
    return ((static_cast<std::size_t>(layer) * static_cast<std::size_t>(height_) + static_cast<std::size_t>(y)) *
                static_cast<std::size_t>(width_) +
            static_cast<std::size_t>(x)) *
           6;
  }
  static const std::vector<int>& total_only();
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }

  int width_ = 0;
  int height_ = 0;
  std::vector<std::string> names_;
  std::vector<std::vector<int>> layers_of_set_;  // class-set id -> layers, total first
  std::vector<std::uint64_t> words_;             // per layer, pixel, channel: low word, high word
};

}  // namespace pathex
