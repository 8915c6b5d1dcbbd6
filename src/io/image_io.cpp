// OpenEXR and PNG encoding (the EXR straight into its file, the PNGs in memory; either placed
// whole by io/atomic_file.h), EXR reading, and the preview tone mapping. OpenEXR reports errors
// by exceptions; they are caught here and turned into Error values naming the file.
#include "io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>
#include <png.h>
#include <zlib.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "io/atomic_file.h"

namespace pathex {
namespace {

Error file_error(const std::string& path, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = path;
  return e;
}

class FileOStream : public Imf::OStream {
 public:
  explicit FileOStream(AtomicFile* file) : Imf::OStream("<file>"), file_(file) {}
  void write(const char c[], int n) override {
    const std::string_view bytes(c, static_cast<std::size_t>(n));
    if (pos_ == file_->size()) {
      file_->append(bytes);
    } else {
      const std::uint64_t inside = std::min<std::uint64_t>(bytes.size(), file_->size() - pos_);
      file_->write_at(pos_, bytes.substr(0, static_cast<std::size_t>(inside)));
      file_->append(bytes.substr(static_cast<std::size_t>(inside)));
    }
    pos_ += bytes.size();
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = pos; }

 private:
  AtomicFile* file_;
  std::uint64_t pos_ = 0;
};

Result<bool> check_layers(const std::vector<ImageLayer>& layers) {
  if (layers.empty()) return make_error(ErrorCode::kUsage, "no image layers to write");
  const int w = layers[0].image.width, h = layers[0].image.height;
  if (w <= 0 || h <= 0) return make_error(ErrorCode::kUsage, "cannot write an empty image");
  std::set<std::string> names;
  for (const ImageLayer& l : layers) {
    if (l.name.empty()) return make_error(ErrorCode::kUsage, "an image layer has no name");
    if (!names.insert(l.name).second)
      return make_error(ErrorCode::kUsage, "two image layers are named '" + l.name + "'");
    if (l.image.width != w || l.image.height != h ||
        l.image.rgb.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3)
      return make_error(ErrorCode::kUsage, "image layer '" + l.name + "' does not have the size of the others");
  }
  return true;
}

double srgb_encode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }

}  // namespace

// --- memory ---

std::uint64_t render_memory_estimate(int width, int height, int layers) {
  constexpr std::uint64_t kBytesPerPixelLayer = 48 + 12 + 2 * 12;
  return static_cast<std::uint64_t>(std::max(width, 0)) * static_cast<std::uint64_t>(std::max(height, 0)) *
         static_cast<std::uint64_t>(std::max(layers, 1)) * kBytesPerPixelLayer;
}

// --- OpenEXR ---

namespace {

// An EXR file written a band of scan lines at a time into an AtomicFile (the slices of each band
// point into its buffers; OpenEXR encodes blocks of lines on every core, and the bytes do not
// depend on it). RLE: the render's float noise barely compresses, the class layers' empty regions
// do; ZIP level 1 took six to eight times the CPU for files two thirds the size (bench/README.md).
class ExrStream {
 public:
  ExrStream(AtomicFile* file, const LayerBands& bands, const ExrOptions& options) : out_(file), bands_(bands), options_(options) {}

  Result<bool> open() {
    return guarded([&] {
      Imf::Header header(bands_.width(), bands_.height());
      header.compression() = Imf::RLE_COMPRESSION;
      static const char* const kChannel[3] = {"R", "G", "B"};
      for (std::size_t l = 0; l < bands_.num_layers(); ++l)
        for (const char* c : kChannel) header.channels().insert(bands_.name(l) + "." + c, Imf::Channel(type()));
      file_ = std::make_unique<Imf::OutputFile>(out_, header, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
    });
  }

  // Rows [y0, y0 + rows), band[l] pointing at layer l's (rows × width × 3 floats).
  Result<bool> write(int y0, int rows, const std::vector<const float*>& band) {
    return guarded([&] {
      const std::size_t w = static_cast<std::size_t>(bands_.width()), size = options_.half ? sizeof(half) : sizeof(float);
      const std::size_t x_stride = 3 * size, y_stride = x_stride * w;
      if (options_.half) halves_.resize(band.size());
      Imf::FrameBuffer frame;
      static const char* const kChannel[3] = {"R", "G", "B"};
      for (std::size_t l = 0; l < band.size(); ++l) {
        const char* data = reinterpret_cast<const char*>(band[l]);
        if (options_.half) {  // half channels need their own buffers
          const std::size_t n = static_cast<std::size_t>(rows) * w * 3;
          halves_[l].resize(n);
          for (std::size_t i = 0; i < n; ++i) halves_[l][i] = half(band[l][i]);
          data = reinterpret_cast<const char*>(halves_[l].data());
        }
        // OpenEXR addresses pixel (x, y) at base + x * x_stride + y * y_stride: the band's first
        // row is line y0.
        const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(data) - static_cast<std::uintptr_t>(y0) * y_stride;
        for (std::size_t c = 0; c < 3; ++c)
          frame.insert(bands_.name(l) + "." + kChannel[c],
                       Imf::Slice(type(), reinterpret_cast<char*>(base + c * size), x_stride, y_stride));
      }
      file_->setFrameBuffer(frame);
      file_->writePixels(rows);
    });
  }

  // Completes the file (the table of line offsets).
  Result<bool> close() {
    return guarded([&] { file_.reset(); });
  }

 private:
  Imf::PixelType type() const { return options_.half ? Imf::HALF : Imf::FLOAT; }
  template <typename F>
  Result<bool> guarded(F&& f) {
    try {
      f();
      return true;
    } catch (const std::exception& ex) {
      return make_error(ErrorCode::kBadFile, std::string("OpenEXR could not encode the image: ") + ex.what());
    }
  }

  FileOStream out_;
  const LayerBands& bands_;
  ExrOptions options_;
  std::unique_ptr<Imf::OutputFile> file_;
  std::vector<std::vector<half>> halves_;
};

// Whole layers (write_exr, write_previews) as bands.
class VectorBands final : public LayerBands {
 public:
  explicit VectorBands(const std::vector<ImageLayer>& layers) : layers_(layers) {}
  int width() const override { return layers_[0].image.width; }
  int height() const override { return layers_[0].image.height; }
  std::size_t num_layers() const override { return layers_.size(); }
  const std::string& name(std::size_t layer) const override { return layers_[layer].name; }
  void fill(std::size_t layer, int y0, int rows, float* out) const override {
    const std::size_t row = static_cast<std::size_t>(width()) * 3;
    const float* src = layers_[layer].image.rgb.data() + static_cast<std::size_t>(y0) * row;
    std::copy(src, src + static_cast<std::size_t>(rows) * row, out);
  }

 private:
  const std::vector<ImageLayer>& layers_;
};

}  // namespace

Result<bool> write_exr(const std::string& path, const std::vector<ImageLayer>& layers, const ExrOptions& options) {
  if (Result<bool> ok = check_layers(layers); !ok) {
    Error e = ok.error();
    e.where = path;
    return e;
  }
  return write_image_files(VectorBands(layers), ImageFiles{path, options, ""});
}

Result<ExrChannels> read_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    ExrChannels out;
    out.width = dw.max.x - dw.min.x + 1;
    out.height = dw.max.y - dw.min.y + 1;
    const std::size_t pixels = static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height);
    Imf::FrameBuffer frame;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
      std::vector<float>& data = out.channels[it.name()];
      data.assign(pixels, 0.0f);
      frame.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, data.data(), dw));
    }
    file.setFrameBuffer(frame);
    file.readPixels(dw.min.y, dw.max.y);
    return out;
  } catch (const std::exception& ex) {
    return file_error(path, std::string("cannot read the EXR file: ") + ex.what());
  }
}

Result<std::vector<ImageLayer>> read_exr_layers(const std::string& path) {
  Result<ExrChannels> exr = read_exr(path);
  if (!exr) return exr.error();
  std::vector<ImageLayer> layers;
  for (const auto& [name, data] : exr->channels) {
    if (name.size() < 3 || name.substr(name.size() - 2) != ".R") continue;
    const std::string layer = name.substr(0, name.size() - 2);
    auto g = exr->channels.find(layer + ".G"), b = exr->channels.find(layer + ".B");
    if (g == exr->channels.end() || b == exr->channels.end()) continue;
    ImageLayer l;
    l.name = layer;
    l.image.width = exr->width;
    l.image.height = exr->height;
    l.image.rgb.resize(data.size() * 3);
    for (std::size_t i = 0; i < data.size(); ++i) {
      l.image.rgb[3 * i] = data[i];
      l.image.rgb[3 * i + 1] = g->second[i];
      l.image.rgb[3 * i + 2] = b->second[i];
    }
    layers.push_back(std::move(l));
  }
  return layers;
}

// --- PNG previews ---

namespace {

// 1 / (the 99th percentile, nearest rank, of the luminances); else 1 / the largest; else 1.
double exposure_of(std::vector<double> lum) {
  if (lum.empty()) return 1;
  // Nearest rank: the smallest value with at least 99 % of the pixels at or below it.
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(lum.size()))) - 1;
  std::nth_element(lum.begin(), lum.begin() + static_cast<std::ptrdiff_t>(rank), lum.end());
  const double p99 = lum[rank];
  if (p99 > 0) return 1 / p99;
  const double top = *std::max_element(lum.begin(), lum.end());
  return top > 0 ? 1 / top : 1;
}

// The luminances of `pixels` RGB float pixels, non-finite ones as 0, into `lum`.
void luminances_into(const float* rgb, std::size_t pixels, double* lum) {
  for (std::size_t i = 0; i < pixels; ++i) {
    const double l = luminance({rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]});
    lum[i] = std::isfinite(l) ? l : 0.0;
  }
}

}  // namespace

double preview_exposure(const RgbImage& total) {
  std::vector<double> lum(total.rgb.size() / 3);
  luminances_into(total.rgb.data(), lum.size(), lum.data());
  return exposure_of(std::move(lum));
}

namespace {

// The 8-bit sRGB code of a linear value in [0, 1].
std::uint8_t srgb8(double v) { return static_cast<std::uint8_t>(std::lround(255 * srgb_encode(v))); }

// thresholds[k - 1] is the smallest linear value whose code is k (1 ≤ k ≤ 255), found by
// bisection on srgb8 itself, so that looking a value up gives exactly srgb8(v) (which does not
// decrease with v) without a pow() per channel: 21 layers of 512 x 512 took a second of pow().
const std::array<double, 255>& srgb8_thresholds() {
  static const std::array<double, 255> thresholds = [] {
    std::array<double, 255> t{};
    for (int k = 1; k <= 255; ++k) {
      double lo = 0, hi = 1;  // srgb8(lo) < k <= srgb8(hi)
      for (int i = 0; i < 200 && std::nextafter(lo, 1.0) < hi; ++i) {
        const double mid = lo + (hi - lo) / 2;
        (srgb8(mid) >= k ? hi : lo) = mid;
      }
      t[static_cast<std::size_t>(k - 1)] = hi;
    }
    return t;
  }();
  return thresholds;
}

}  // namespace

namespace {

// `n` values times exposure, sRGB-encoded, clamped, rounded to 8 bits, into `out`.
void tonemap_srgb8_into(const float* in, std::size_t n, double exposure, std::uint8_t* out) {
  const std::array<double, 255>& thresholds = srgb8_thresholds();
  // Per 1/4096 of [0, 1]: the code at the bucket's start (the number of thresholds at or below it)
  // and the next threshold. The thresholds are at least 1 / (12.92 · 255) = 1/3295 apart (the
  // curve's steepest slope), more than a bucket, so at most one lies inside a bucket and one
  // comparison decides: exactly the number of thresholds at or below v, as a search would give,
  // without the data-dependent branches of a search (which mispredicted on noisy layers).
  constexpr int kBuckets = 4096;
  struct Bucket {
    double next;  // the first threshold above the bucket's start; +inf past code 255
    unsigned code;
  };
  static const std::array<Bucket, kBuckets + 1> buckets = [&] {
    std::array<Bucket, kBuckets + 1> g{};
    for (int b = 0; b <= kBuckets; ++b) {
      const auto code = static_cast<unsigned>(
          std::upper_bound(thresholds.begin(), thresholds.end(), static_cast<double>(b) / kBuckets) - thresholds.begin());
      g[static_cast<std::size_t>(b)] = {code < 255 ? thresholds[code] : std::numeric_limits<double>::infinity(), code};
    }
    return g;
  }();
  for (std::size_t i = 0; i < n; ++i) {
    double v = in[i] * exposure;
    v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0;  // NaN and ±inf never reach a finished image
    const Bucket& b = buckets[static_cast<std::size_t>(v * kBuckets)];
    const unsigned code = b.code + (v >= b.next ? 1u : 0u);
    out[i] = static_cast<std::uint8_t>(code);
  }
}

}  // namespace

std::vector<std::uint8_t> tonemap_srgb8(const RgbImage& image, double exposure) {
  std::vector<std::uint8_t> out(image.rgb.size());
  tonemap_srgb8_into(image.rgb.data(), image.rgb.size(), exposure, out.data());
  return out;
}

namespace {

// libpng's low-level writer into a string. libpng reports errors by longjmp, so the calls live in
// functions with no C++ object to unwind (each sets its own return point); the message is kept in
// `message`.
struct PngSink {
  std::string* bytes;
  char message[160];
};

void png_append(png_structp png, png_bytep data, png_size_t n) {
  static_cast<PngSink*>(png_get_io_ptr(png))->bytes->append(reinterpret_cast<const char*>(data), n);
}
void png_no_flush(png_structp) {}
void png_fail(png_structp png, png_const_charp message) {
  PngSink* sink = static_cast<PngSink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof sink->message, "%s", message);
  png_longjmp(png, 1);
}
void png_ignore_warning(png_structp, png_const_charp) {}

bool png_begin(png_structp png, png_infop info, int width, int height) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Previews: zlib level 1 with its run-length strategy and no filter, five times faster than
  // libpng's "fast" mode (none filter, level 3 deflate) for 8 % more bytes (bench/README.md).
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_write_info(png, info);
  return true;
}
bool png_rows(png_structp png, const std::uint8_t* rgb8, int rows, std::size_t row_bytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  for (int y = 0; y < rows; ++y) png_write_row(png, rgb8 + static_cast<std::size_t>(y) * row_bytes);
  return true;
}
bool png_end(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_write_end(png, info);
  return true;
}

// An 8-bit RGB PNG encoded a band of rows at a time into a string.
class PngStream {
 public:
  PngStream() = default;
  PngStream(const PngStream&) = delete;
  PngStream& operator=(const PngStream&) = delete;
  ~PngStream() { png_destroy_write_struct(&png_, &info_); }

  Result<bool> begin(int width, int height) {
    width_ = width;
    bytes_.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3 / 2);
    png_ = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink_, png_fail, png_ignore_warning);
    info_ = png_ != nullptr ? png_create_info_struct(png_) : nullptr;
    if (info_ == nullptr) return make_error(ErrorCode::kBadFile, "libpng could not encode the image: out of memory");
    png_set_write_fn(png_, &sink_, png_append, png_no_flush);
    return check(png_begin(png_, info_, width, height));
  }
  Result<bool> rows(const std::uint8_t* rgb8, int rows) { return check(png_rows(png_, rgb8, rows, static_cast<std::size_t>(width_) * 3)); }
  Result<bool> end() { return check(png_end(png_, info_)); }
  const std::string& bytes() const { return bytes_; }
  std::string take() { return std::move(bytes_); }

 private:
  Result<bool> check(bool ok) {
    if (ok) return true;
    return make_error(ErrorCode::kBadFile, std::string("libpng could not encode the image: ") + sink_.message);
  }
  std::string bytes_;
  PngSink sink_{&bytes_, {}};
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
  int width_ = 0;
};

}  // namespace

Result<std::string> encode_png(int width, int height, const std::vector<std::uint8_t>& rgb8) {
  if (width <= 0 || height <= 0 ||
      rgb8.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return make_error(ErrorCode::kUsage, "the PNG pixels do not match its size");
  PngStream png;
  if (Result<bool> r = png.begin(width, height); !r) return r.error();
  if (Result<bool> r = png.rows(rgb8.data(), height); !r) return r.error();
  if (Result<bool> r = png.end(); !r) return r.error();
  return png.take();
}

Result<bool> write_png(const std::string& path, const RgbImage& image, double exposure) {
  Result<std::string> bytes = encode_png(image.width, image.height, tonemap_srgb8(image, exposure));
  if (!bytes) {
    Error e = bytes.error();
    e.where = path;
    return e;
  }
  return write_file_atomic(path, *bytes);
}

Result<bool> write_previews(const std::string& dir, const std::vector<ImageLayer>& layers) {
  if (Result<bool> ok = check_layers(layers); !ok) {
    Error e = ok.error();
    e.where = dir;
    return e;
  }
  return write_image_files(VectorBands(layers), ImageFiles{"", {}, dir.empty() ? std::string(".") : dir});
}

// --- an image's files a band of rows at a time ---

Result<bool> write_image_files(const LayerBands& bands, const ImageFiles& files) {
  const std::size_t n = bands.num_layers();
  const int w = bands.width(), h = bands.height();
  const std::size_t band_floats = static_cast<std::size_t>(kBandRows) * static_cast<std::size_t>(w) * 3;
  const auto located = [](Error e, const std::string& where) {
    e.where = where;
    return e;
  };
  {
    std::set<std::string> names;
    for (std::size_t l = 0; l < n; ++l)
      if (bands.name(l).empty() || !names.insert(bands.name(l)).second)
        return located(make_error(ErrorCode::kUsage, "the image layers' names are not distinct and nonempty"),
                       files.exr.empty() ? files.previews : files.exr);
    if (n == 0 || w <= 0 || h <= 0)
      return located(make_error(ErrorCode::kUsage, "cannot write an empty image"), files.exr.empty() ? files.previews : files.exr);
  }
  const bool previews = !files.previews.empty();
  const auto png_path = [&](std::size_t l) { return files.previews + "/" + bands.name(l) + ".png"; };
  const std::size_t row_floats = static_cast<std::size_t>(w) * 3;

  // --- layers with the same pixels: each is made (and its preview encoded) as the first of them ---
  std::vector<std::size_t> like(n);
  for (std::size_t l = 0; l < n; ++l) {
    like[l] = l;
    for (std::size_t k = 0; k < l && like[l] == l; ++k)
      if (like[k] == k && bands.same_pixels(k, l)) like[l] = k;
  }

  // --- the previews' exposure: a first pass makes the total whole (kept for the bands) ---
  double exposure = 1;
  std::size_t total = n;  // the layer kept whole; n: none
  std::vector<float> total_rgb;
  if (previews) {
    total = 0;
    for (std::size_t l = 0; l < n; ++l)
      if (bands.name(l) == "total") {
        total = l;
        break;
      }
    total = like[total];
    total_rgb.resize(static_cast<std::size_t>(h) * row_floats);
    std::vector<double> lum(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    tbb::parallel_for(0, (h + kBandRows - 1) / kBandRows, [&](int b) {
      const int y0 = b * kBandRows, rows = std::min(kBandRows, h - y0);
      float* band = total_rgb.data() + static_cast<std::size_t>(y0) * row_floats;
      bands.fill(total, y0, rows, band);
      luminances_into(band, static_cast<std::size_t>(rows) * static_cast<std::size_t>(w),
                      lum.data() + static_cast<std::size_t>(y0) * static_cast<std::size_t>(w));
    });
    exposure = exposure_of(std::move(lum));
  }

  // --- the files, band by band ---
  std::optional<AtomicFile> exr_file;
  std::optional<ExrStream> exr;
  std::optional<Error> exr_error;
  if (!files.exr.empty()) {
    exr_file.emplace(files.exr);
    if (!exr_file->ok()) return exr_file->commit();  // the error
    exr.emplace(&*exr_file, bands, files.exr_options);
    if (Result<bool> r = exr->open(); !r) return located(r.error(), files.exr);
  }
  // Previews are encoded for the first layer of each same-pixels group only.
  std::vector<std::size_t> encoded;
  if (previews)
    for (std::size_t l = 0; l < n; ++l)
      if (like[l] == l) encoded.push_back(l);
  std::vector<PngStream> pngs(encoded.size());
  std::vector<std::optional<Error>> png_errors(pngs.size());
  for (std::size_t i = 0; i < pngs.size(); ++i)
    if (Result<bool> r = pngs[i].begin(w, h); !r) png_errors[i] = located(r.error(), png_path(encoded[i]));
  // The layers made band by band: every first of a group but the total kept whole.
  std::vector<std::size_t> made;
  for (std::size_t l = 0; l < n; ++l)
    if (like[l] == l && l != total) made.push_back(l);
  std::vector<std::vector<float>> band(n);
  for (std::size_t l : made) band[l].resize(band_floats);
  std::vector<const float*> data(n);
  std::vector<std::vector<std::uint8_t>> rgb8(pngs.size(), std::vector<std::uint8_t>(band_floats));
  for (int y0 = 0; y0 < h; y0 += kBandRows) {
    const int rows = std::min(kBandRows, h - y0);
    const std::size_t values = static_cast<std::size_t>(rows) * row_floats;
    tbb::parallel_for(std::size_t{0}, made.size(), [&](std::size_t i) { bands.fill(made[i], y0, rows, band[made[i]].data()); });
    for (std::size_t l = 0; l < n; ++l) {
      const std::size_t k = like[l];
      data[l] = k == total ? total_rgb.data() + static_cast<std::size_t>(y0) * row_floats : band[k].data();
    }
    tbb::task_group group;
    if (exr && !exr_error)
      group.run([&] {
        if (Result<bool> r = exr->write(y0, rows, data); !r) exr_error = located(r.error(), files.exr);
      });
    tbb::parallel_for(std::size_t{0}, pngs.size(), [&](std::size_t i) {
      if (png_errors[i]) return;
      tonemap_srgb8_into(data[encoded[i]], values, exposure, rgb8[i].data());
      if (Result<bool> r = pngs[i].rows(rgb8[i].data(), rows); !r) png_errors[i] = located(r.error(), png_path(encoded[i]));
    });
    group.wait();
  }
  // --- completed and put in place: the EXR beside the previews (each file's flush to disk waits
  // beside the others'); a layer like an earlier one gets that one's preview bytes ---
  std::optional<Result<bool>> exr_done;
  tbb::task_group group;
  if (exr && !exr_error)
    group.run([&] {
      if (Result<bool> r = exr->close(); !r) exr_error = located(r.error(), files.exr);
      else exr_done.emplace(exr_file->commit());
    });
  std::vector<std::optional<Error>> layer_errors(previews ? n : 0);
  tbb::parallel_for(std::size_t{0}, pngs.size(), [&](std::size_t i) {
    if (!png_errors[i])
      if (Result<bool> r = pngs[i].end(); !r) png_errors[i] = located(r.error(), png_path(encoded[i]));
    for (std::size_t l = encoded[i]; l < n; ++l) {
      if (like[l] != encoded[i]) continue;
      if (png_errors[i]) layer_errors[l] = png_errors[i];
      else if (Result<bool> wr = write_file_atomic(png_path(l), pngs[i].bytes()); !wr) layer_errors[l] = wr.error();
    }
  });
  group.wait();
  if (exr_error) return *exr_error;
  if (exr_done && !*exr_done) return std::move(*exr_done);
  for (const std::optional<Error>& e : layer_errors)
    if (e) return *e;
  return true;
}

}  // namespace pathex
