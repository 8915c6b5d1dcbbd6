// Image outputs of `pathex trace`: one multi-layer OpenEXR file (a layer per class plus "total",
// channels "<layer>.R", "<layer>.G", "<layer>.B") and an 8-bit sRGB PNG preview per layer.
//
// Every writer goes through io/atomic_file.h (the EXR streamed into its file as it is encoded, a
// PNG's bytes handed over whole), so an output file is written whole or not at all (DESIGN §12).
// Errors are values naming the path.
//
// Previews share one exposure, chosen so that the 99th percentile of the total's luminance maps
// to 1 (preview_exposure), so class previews are comparable with the total and with each other;
// values are then encoded with the sRGB transfer curve and clamped to [0, 1].
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "film/image.h"
#include "core/error.h"

namespace pathex {

// --- memory ---

// What the images of a render of `width` x `height` pixels with `layers` layers (the total and one
// per class) take at their peak, which is while they are written: the render's exact sums (48
// bytes per pixel per plane, counted as one plane per layer: ClassImages) and, kept as a margin
// since the EXR and the previews are now written band by band (write_image_files), the layers as
// floats (12 bytes per pixel each) and twice that again (what the EXR's bytes took in memory before). pathex trace compares it with
// --max-memory before rendering. Measured peaks stay below it (README "Limits").
std::uint64_t render_memory_estimate(int width, int height, int layers);

// --- OpenEXR ---

struct ExrOptions {
  bool half = false;  // 16-bit half channels instead of 32-bit float (values above 65504 become inf)
};

// All layers must have the same nonzero size and distinct, nonempty names.
Result<bool> write_exr(const std::string& path, const std::vector<ImageLayer>& layers, const ExrOptions& options = {});

// Every channel of a scanline or tiled EXR file, as floats, row-major from the top of the data
// window. For reading outputs back (tests, references, merging).
struct ExrChannels {
  int width = 0;
  int height = 0;
  std::map<std::string, std::vector<float>> channels;  // by full channel name, e.g. "caustic.R"
};
Result<ExrChannels> read_exr(const std::string& path);
// The layers of a file written by write_exr: every "<layer>.R/.G/.B" triple, by layer name.
Result<std::vector<ImageLayer>> read_exr_layers(const std::string& path);

// --- an image's files a band of rows at a time ---

// The layers of an image, made a band of rows at a time when a writer asks for them, so that
// writing the EXR and the previews never holds every layer as floats (a 512 x 512 render with
// twenty class layers: 66 MB, whose first touches cost more than encoding them on the
// development VM, bench/README.md).
class LayerBands {
 public:
  virtual ~LayerBands() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual std::size_t num_layers() const = 0;
  virtual const std::string& name(std::size_t layer) const = 0;
  // Rows [y0, y0 + rows) of a layer, rows × width × 3 floats (RGB, row-major), into `out`. Called
  // from several threads at once, with y0 a multiple of kBandRows.
  virtual void fill(std::size_t layer, int y0, int rows, float* out) const = 0;
  // Whether layers `a` and `b` are known to be equal pixel for pixel (false: not known). The
  // writer then makes the pixels and the preview of such layers once: in the default scene the
  // class "local" holds every sampled path, and its layer was made and encoded as the total's was.
  virtual bool same_pixels(std::size_t /*a*/, std::size_t /*b*/) const { return false; }
};
inline constexpr int kBandRows = 16;

struct ImageFiles {
  std::string exr;       // the EXR file of every layer; empty: none
  ExrOptions exr_options;
  std::string previews;  // the folder of the PNG previews, <layer>.png each; empty: none
};
// Writes `files` from `bands`: the EXR and every preview encoded band by band, the layers of a
// band made in parallel and the EXR and the PNGs encoded side by side. The previews' exposure is
// that of the layer named "total" (else the first), from a first pass that makes that layer
// whole (12 bytes per pixel, kept for the bands: it is made once). Layers with the same pixels
// (LayerBands::same_pixels) are made and their previews encoded once. The bytes are those of the
// whole-image writers. Errors name the file; the first in the order EXR, previews by layer is
// returned.
Result<bool> write_image_files(const LayerBands& bands, const ImageFiles& files);

// --- PNG previews ---

// 1 / (the 99th percentile, nearest rank, of the pixel luminances of `total`); if that is not
// positive, 1 / the largest luminance; if that is not positive either, 1.
double preview_exposure(const RgbImage& total);
// Pixels times exposure, sRGB-encoded, clamped, rounded to 8 bits; RGB interleaved.
std::vector<std::uint8_t> tonemap_srgb8(const RgbImage& image, double exposure);
// An 8-bit RGB PNG (the file's bytes).
Result<std::string> encode_png(int width, int height, const std::vector<std::uint8_t>& rgb8);
Result<bool> write_png(const std::string& path, const RgbImage& image, double exposure);
// DIR/<layer>.png for every layer, with the exposure of the layer named "total" (else the first).
Result<bool> write_previews(const std::string& dir, const std::vector<ImageLayer>& layers);

}  // namespace pathex
