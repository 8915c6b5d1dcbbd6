// image_error: the per-pixel error of rendered images against a reference, for
// bench/efficiency.py.
//
//     image_error REF.exr TEST.exr... [--border N] [--second-ref REF2.exr] [--lamp-luminance L]
//
// Every file is a `pathex trace` classes.exr. For each TEST it prints one JSON line:
//   {"file", "mse", "mse_off", "pixels", "pixels_off"}
// where mse is the mean over pixels of the squared error of the "total" layer, averaged over R, G
// and B, and mse_off the same over the pixels off the directly seen emitters: a pixel is excluded
// when the reference's "emission" layer (class $emission, the light seen directly) is nonzero
// within N pixels of it (Chebyshev distance; --border, default 2). With --lamp-luminance L the
// pixels left out are instead those within N pixels of one whose reference "total" luminance
// (Rec. 709 weights, of the mean of REF and REF2) is above L: issue 39's definition of the lamp
// (bench/tungsten.py, L = 5). With --second-ref, REF and REF2
// are two independent reference renders of equal length: the reference is their mean, and a first
// line {"reference_noise", "reference_noise_off"} gives the variance that mean still has per pixel
// (mean of (REF - REF2)² / 4), which the caller subtracts from each mse.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "io/image_io.h"

namespace {

using pathex::ImageLayer;
using pathex::RgbImage;

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "image_error: %s\n", message.c_str());
  std::exit(2);
}

RgbImage layer(const std::vector<ImageLayer>& layers, const std::string& name, const std::string& file) {
  for (const ImageLayer& l : layers)
    if (l.name == name) return l.image;
  fail(file + " has no layer '" + name + "'");
}

std::vector<ImageLayer> read(const std::string& file) {
  pathex::Result<std::vector<ImageLayer>> r = pathex::read_exr_layers(file);
  if (!r) fail(r.error().message);
  return *r;
}

// Mean squared difference of a and b (RGB averaged) over all pixels and over those `keep` marks.
void mse(const RgbImage& a, const RgbImage& b, const std::vector<char>& keep, double* all, double* off) {
  double s = 0.0, s_off = 0.0;
  std::size_t n_off = 0;
  const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    double e = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a.rgb[3 * p + c]) - static_cast<double>(b.rgb[3 * p + c]);
      e += d * d / 3.0;
    }
    s += e;
    if (keep[p]) s_off += e, ++n_off;
  }
  *all = s / static_cast<double>(pixels);
  *off = n_off ? s_off / static_cast<double>(n_off) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  int border = 2;
  double lamp_luminance = -1.0;  // < 0: the emission layer marks the lamp
  std::string ref_file, ref2_file;
  std::vector<std::string> tests;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--border" && i + 1 < argc) border = std::atoi(argv[++i]);
    else if (a == "--second-ref" && i + 1 < argc) ref2_file = argv[++i];
    else if (a == "--lamp-luminance" && i + 1 < argc) lamp_luminance = std::atof(argv[++i]);
    else if (ref_file.empty()) ref_file = a;
    else tests.push_back(a);
  }
  if (ref_file.empty())
    fail("usage: image_error REF.exr TEST.exr... [--border N] [--second-ref REF2.exr] [--lamp-luminance L]");
  const std::vector<ImageLayer> ref_layers = read(ref_file);
  RgbImage ref = layer(ref_layers, "total", ref_file);
  const int w = ref.width, h = ref.height;
  std::optional<RgbImage> ref2;
  if (!ref2_file.empty()) {
    ref2 = layer(read(ref2_file), "total", ref2_file);
    if (ref2->width != w || ref2->height != h) fail(ref2_file + " is not the size of " + ref_file);
  }
  // The pixels that are the lamp: nonzero emission, or (--lamp-luminance) a bright reference.
  const RgbImage emission = layer(ref_layers, "emission", ref_file);
  const auto lamp = [&](int x, int y) {
    if (lamp_luminance < 0.0)
      return emission.at(x, y, 0) != 0.0f || emission.at(x, y, 1) != 0.0f || emission.at(x, y, 2) != 0.0f;
    double lum = 0.0;
    constexpr double kWeights[3] = {0.2126, 0.7152, 0.0722};
    for (int c = 0; c < 3; ++c)
      lum += kWeights[c] * (ref2 ? 0.5 * (static_cast<double>(ref.at(x, y, c)) + static_cast<double>(ref2->at(x, y, c)))
                                 : static_cast<double>(ref.at(x, y, c)));
    return lum > lamp_luminance;
  };
  std::vector<char> keep(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 1);
  std::size_t pixels_off = keep.size();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!lamp(x, y)) continue;
      for (int yy = std::max(0, y - border); yy <= std::min(h - 1, y + border); ++yy)
        for (int xx = std::max(0, x - border); xx <= std::min(w - 1, x + border); ++xx) {
          char& k = keep[static_cast<std::size_t>(yy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(xx)];
          pixels_off -= k;
          k = 0;
        }
    }
  if (ref2) {
    double all = 0.0, off = 0.0;
    mse(ref, *ref2, keep, &all, &off);
    std::printf("{\"reference_noise\": %.9g, \"reference_noise_off\": %.9g}\n", all / 4.0, off / 4.0);
    for (std::size_t i = 0; i < ref.rgb.size(); ++i) ref.rgb[i] = 0.5f * (ref.rgb[i] + ref2->rgb[i]);
  }
  for (const std::string& file : tests) {
    const RgbImage img = layer(read(file), "total", file);
    if (img.width != w || img.height != h) fail(file + " is not the size of " + ref_file);
    double all = 0.0, off = 0.0;
    mse(img, ref, keep, &all, &off);
    std::printf("{\"file\": \"%s\", \"mse\": %.9g, \"mse_off\": %.9g, \"pixels\": %zu, \"pixels_off\": %zu}\n",
                file.c_str(), all, off, keep.size(), pixels_off);
  }
  return 0;
}
