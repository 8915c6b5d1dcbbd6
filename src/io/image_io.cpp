// OpenEXR and PNG encoding (the EXR straight into its file, the PNGs in memory; either placed
// whole by io/atomic_file.h), EXR reading, and the preview tone mapping. OpenEXR reports errors
// by exceptions; they are caught here and turned into Error values naming the file.
#include "io/image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <array>
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

#include "io/atomic_file.h"

namespace pathex {
namespace {

Error file_error(const std::string& path, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = path;
  return e;
}

// An OpenEXR output stream into a string.
class MemoryOStream : public Imf::OStream {
 public:
  // `capacity`: the bytes expected, allocated once (the file is written in small pieces).
  explicit MemoryOStream(std::size_t capacity) : Imf::OStream("<memory>") { bytes_.reserve(capacity); }
  void write(const char c[], int n) override {
    const auto count = static_cast<std::size_t>(n);
    if (pos_ == bytes_.size()) {
      bytes_.append(c, count);
    } else {
      if (pos_ + count > bytes_.size()) bytes_.resize(pos_ + count);
      std::memcpy(bytes_.data() + pos_, c, count);
    }
    pos_ += count;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = static_cast<std::size_t>(pos); }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
  std::size_t pos_ = 0;
};

// An OpenEXR output stream into an AtomicFile, written as it is encoded (OpenEXR seeks back once,
// to fill in the table of line offsets).
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

// The file into `out` (MemoryOStream or FileOStream).
Result<bool> encode_exr_into(Imf::OStream& out, const std::vector<ImageLayer>& layers, const ExrOptions& options) {
  if (Result<bool> ok = check_layers(layers); !ok) return ok.error();
  const int w = layers[0].image.width, h = layers[0].image.height;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
  const std::size_t size = options.half ? sizeof(half) : sizeof(float);
  try {
    Imf::Header header(w, h);
    // RLE: the render's float noise barely compresses, the class layers' empty regions do; ZIP
    // level 1 took six to eight times the CPU for files two thirds the size (bench/README.md).
    header.compression() = Imf::RLE_COMPRESSION;
    // Half channels need their own buffers; float channels point straight into the layers.
    std::vector<std::vector<half>> halves;
    Imf::FrameBuffer frame;
    static const char* const kChannel[3] = {"R", "G", "B"};
    for (const ImageLayer& l : layers) {
      const char* base = reinterpret_cast<const char*>(l.image.rgb.data());
      std::size_t x_stride = 3 * sizeof(float);
      if (options.half) {
        halves.emplace_back(pixels * 3);
        for (std::size_t i = 0; i < pixels * 3; ++i) halves.back()[i] = half(l.image.rgb[i]);
        base = reinterpret_cast<const char*>(halves.back().data());
        x_stride = 3 * sizeof(half);
      }
      for (std::size_t c = 0; c < 3; ++c) {
        const std::string name = l.name + "." + kChannel[c];
        header.channels().insert(name, Imf::Channel(type));
        frame.insert(name, Imf::Slice(type, const_cast<char*>(base + c * size), x_stride,
                                      x_stride * static_cast<std::size_t>(w)));
      }
    }
    {
      // Blocks of scan lines compressed on every core (the bytes do not depend on it).
      Imf::OutputFile file(out, header, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
      file.setFrameBuffer(frame);
      file.writePixels(h);
    }  // the destructor completes the file (line offset table)
    return true;
  } catch (const std::exception& ex) {
    return make_error(ErrorCode::kBadFile, std::string("OpenEXR could not encode the image: ") + ex.what());
  }
}

}  // namespace

Result<std::string> encode_exr(const std::vector<ImageLayer>& layers, const ExrOptions& options) {
  // At most the raw pixels (RLE grows a run-free line by one byte in 128) and the header.
  const std::size_t raw = layers.empty() ? 0 : layers.size() * layers[0].image.rgb.size() * (options.half ? 2 : 4);
  MemoryOStream out(raw * 130 / 128 + 65536);
  if (Result<bool> r = encode_exr_into(out, layers, options); !r) return r.error();
  return out.take();
}

Result<bool> write_exr(const std::string& path, const std::vector<ImageLayer>& layers, const ExrOptions& options) {
  // Straight into the file: a memory copy of it would be as large as the layers.
  AtomicFile file(path);
  if (!file.ok()) return file.commit();  // the error
  FileOStream out(&file);
  if (Result<bool> r = encode_exr_into(out, layers, options); !r) {
    Error e = r.error();
    e.where = path;
    return e;
  }
  return file.commit();
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

double preview_exposure(const RgbImage& total) {
  const std::size_t pixels = total.rgb.size() / 3;
  std::vector<double> lum;
  lum.reserve(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    const double l = luminance({total.rgb[3 * i], total.rgb[3 * i + 1], total.rgb[3 * i + 2]});
    lum.push_back(std::isfinite(l) ? l : 0.0);
  }
  if (lum.empty()) return 1;
  // Nearest rank: the smallest value with at least 99 % of the pixels at or below it.
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(lum.size()))) - 1;
  std::nth_element(lum.begin(), lum.begin() + static_cast<std::ptrdiff_t>(rank), lum.end());
  const double p99 = lum[rank];
  if (p99 > 0) return 1 / p99;
  const double top = *std::max_element(lum.begin(), lum.end());
  return top > 0 ? 1 / top : 1;
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

std::vector<std::uint8_t> tonemap_srgb8(const RgbImage& image, double exposure) {
  const std::array<double, 255>& thresholds = srgb8_thresholds();
  // A first guess per 1/4096 of [0, 1] (the curve's steepest slope, 12.92 · 255 codes per unit,
  // moves less than one code per bucket), then the thresholds themselves decide: the code is
  // exactly the number of thresholds at or below v, as a search would give, at two comparisons.
  constexpr int kBuckets = 4096;
  static const std::array<std::uint8_t, kBuckets + 1> guess = [&] {
    std::array<std::uint8_t, kBuckets + 1> g{};
    for (int b = 0; b <= kBuckets; ++b)
      g[static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(
          std::upper_bound(thresholds.begin(), thresholds.end(), static_cast<double>(b) / kBuckets) - thresholds.begin());
    return g;
  }();
  std::vector<std::uint8_t> out(image.rgb.size());
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    double v = image.rgb[i] * exposure;
    v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0;  // NaN and ±inf never reach a finished image
    unsigned code = guess[static_cast<std::size_t>(v * kBuckets)];
    while (code > 0 && v < thresholds[code - 1]) --code;
    while (code < 255 && v >= thresholds[code]) ++code;
    out[i] = static_cast<std::uint8_t>(code);
  }
  return out;
}

namespace {

// libpng's low-level writer into a string. libpng reports errors by longjmp, so the calls live in
// a function with no C++ object to unwind; the message is kept in `message`.
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

bool png_write_rows(png_structp png, png_infop info, int width, int height, const std::uint8_t* rgb8) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Previews: zlib level 1 with its run-length strategy and no filter, five times faster than
  // libpng's "fast" mode (none filter, level 3 deflate) for 8 % more bytes (bench/README.md).
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_write_info(png, info);
  const std::size_t row = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y) png_write_row(png, rgb8 + static_cast<std::size_t>(y) * row);
  png_write_end(png, info);
  return true;
}

}  // namespace

Result<std::string> encode_png(int width, int height, const std::vector<std::uint8_t>& rgb8) {
  if (width <= 0 || height <= 0 ||
      rgb8.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    return make_error(ErrorCode::kUsage, "the PNG pixels do not match its size");
  std::string bytes;
  bytes.reserve(rgb8.size() / 2);
  PngSink sink{&bytes, {}};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, png_fail, png_ignore_warning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return make_error(ErrorCode::kBadFile, "libpng could not encode the image: out of memory");
  }
  png_set_write_fn(png, &sink, png_append, png_no_flush);
  const bool ok = png_write_rows(png, info, width, height, rgb8.data());
  png_destroy_write_struct(&png, &info);
  if (!ok) return make_error(ErrorCode::kBadFile, std::string("libpng could not encode the image: ") + sink.message);
  return bytes;
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
  auto total = std::find_if(layers.begin(), layers.end(), [](const ImageLayer& l) { return l.name == "total"; });
  const double exposure = preview_exposure((total != layers.end() ? *total : layers[0]).image);
  // Encoded and written in parallel (a file's flush to disk waits beside the others' encoding);
  // the first failure in layer order is the one reported.
  std::vector<std::optional<Result<bool>>> written(layers.size());
  tbb::parallel_for(std::size_t{0}, layers.size(), [&](std::size_t i) {
    const std::string path = (dir.empty() ? std::string(".") : dir) + "/" + layers[i].name + ".png";
    written[i].emplace(write_png(path, layers[i].image, exposure));
  });
  for (std::optional<Result<bool>>& w : written)
    if (!*w) return std::move(*w);
  return true;
}

}  // namespace pathex
