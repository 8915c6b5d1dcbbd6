// Image outputs: the multi-layer EXR read back through OpenEXR and, independently, by parsing its
// header's channel list by hand; PNG previews read back with libpng (size, tone-mapped pixel
// values); and "written whole or not at all" — failed writes leave neither the target nor a
// temporary file behind.
#include "io/image_io.h"

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "io/atomic_file.h"

namespace pathex {
namespace {

namespace fs = std::filesystem;

// A fresh directory, removed with its contents at the end of the test.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("pathex-image-io-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }
  std::set<std::string> entries() const {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(path_)) out.insert(e.path().filename().string());
    return out;
  }

 private:
  fs::path path_;
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ImageLayer make_layer(const std::string& name, int w, int h, float offset) {
  ImageLayer l;
  l.name = name;
  l.image.width = w;
  l.image.height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) l.image.rgb.push_back(offset + static_cast<float>(x + 10 * y + 100 * c));
  return l;
}

// The channel names in an EXR header, parsed by hand from the "channels" attribute (OpenEXR file
// layout: magic, version, then name\0 type\0 size value … up to an empty name).
std::vector<std::string> exr_header_channels(const std::string& bytes) {
  std::vector<std::string> names;
  if (bytes.size() < 8 || static_cast<unsigned char>(bytes[0]) != 0x76 || bytes[1] != 0x2f || bytes[2] != 0x31 ||
      bytes[3] != 0x01)
    return names;
  std::size_t pos = 8;
  auto cstr = [&]() {
    const std::size_t end = bytes.find('\0', pos);
    std::string s = bytes.substr(pos, end - pos);
    pos = end + 1;
    return s;
  };
  while (pos < bytes.size()) {
    const std::string name = cstr();
    if (name.empty()) break;
    const std::string type = cstr();
    std::int32_t size;
    std::memcpy(&size, bytes.data() + pos, 4);  // little-endian, like every EXR field
    pos += 4;
    if (name == "channels" && type == "chlist") {
      std::size_t p = pos;
      while (bytes[p] != '\0') {
        const std::size_t end = bytes.find('\0', p);
        names.push_back(bytes.substr(p, end - p));
        p = end + 1 + 16;  // pixel type, pLinear + reserved, x and y sampling
      }
    }
    pos += static_cast<std::size_t>(size);
  }
  return names;
}

struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  std::uint8_t at(int x, int y, int c) const {
    return rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3 +
               static_cast<std::size_t>(c)];
  }
};

Png read_png(const std::string& path) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  Png out;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    ADD_FAILURE() << "libpng cannot read " << path << ": " << image.message;
    return out;
  }
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) {
    ADD_FAILURE() << "libpng cannot decode " << path << ": " << image.message;
    return out;
  }
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  return out;
}

// --- EXR ---

TEST(Exr, LayersAndValuesReadBackThroughOpenExr) {
  TempDir dir;
  std::vector<ImageLayer> layers = {make_layer("total", 5, 3, 0.5f), make_layer("caustic", 5, 3, 0.25f),
                                    make_layer("direct", 5, 3, -7.0f)};
  layers[0].image.rgb[7] = 3.0e10f;   // far beyond half's range: float channels keep it
  layers[1].image.rgb[0] = 1.0e-30f;  // and tiny values
  const std::string path = dir.file("render.exr");
  Result<bool> ok = write_exr(path, layers);
  ASSERT_TRUE(ok) << ok.error().render();
  EXPECT_EQ(dir.entries(), std::set<std::string>{"render.exr"}) << "no temporary file left";

  const std::vector<std::string> want = {"caustic.B", "caustic.G", "caustic.R", "direct.B", "direct.G",
                                         "direct.R",  "total.B",   "total.G",   "total.R"};
  EXPECT_EQ(exr_header_channels(read_bytes(path)), want) << "the header as written on disk";

  Result<ExrChannels> exr = read_exr(path);
  ASSERT_TRUE(exr) << exr.error().render();
  EXPECT_EQ(exr->width, 5);
  EXPECT_EQ(exr->height, 3);
  std::vector<std::string> names;
  for (const auto& [name, data] : exr->channels) names.push_back(name);
  EXPECT_EQ(names, want);
  EXPECT_EQ(exr->channels["total.G"][5 * 2 + 4], 0.5f + 4 + 20 + 100);  // pixel (4, 2), green
  EXPECT_EQ(exr->channels["direct.B"][0], -7.0f + 200);

  Result<std::vector<ImageLayer>> back = read_exr_layers(path);
  ASSERT_TRUE(back);
  ASSERT_EQ(back->size(), 3u);
  EXPECT_EQ((*back)[0].name, "caustic");
  EXPECT_EQ((*back)[2].name, "total");
  EXPECT_EQ((*back)[0].image.rgb, layers[1].image.rgb);
  EXPECT_EQ((*back)[1].image.rgb, layers[2].image.rgb);
  EXPECT_EQ((*back)[2].image.rgb, layers[0].image.rgb);
}

TEST(Exr, HalfChannelsRoundToHalf) {
  TempDir dir;
  ImageLayer l = make_layer("total", 2, 1, 0.0f);
  l.image.rgb[0] = 0.1f;
  l.image.rgb[1] = 1.0e5f;
  const std::string path = dir.file("half.exr");
  ASSERT_TRUE(write_exr(path, {l}, ExrOptions{/*half=*/true}));
  Result<ExrChannels> exr = read_exr(path);
  ASSERT_TRUE(exr);
  EXPECT_EQ(exr->channels["total.R"][0], 0.0999755859375f) << "0x2e66, the half nearest 0.1";
  EXPECT_TRUE(std::isinf(exr->channels["total.G"][0])) << "beyond 65504";
  EXPECT_EQ(exr->channels["total.R"][1], 1.0f);
}

TEST(Exr, BadLayersAreRefusedBeforeAnythingIsWritten) {
  TempDir dir;
  const std::string path = dir.file("bad.exr");
  Result<bool> dup = write_exr(path, {make_layer("total", 2, 2, 0), make_layer("total", 2, 2, 1)});
  ASSERT_FALSE(dup);
  EXPECT_EQ(dup.error().message, "two image layers are named 'total'");
  EXPECT_EQ(dup.error().where, path);
  Result<bool> size = write_exr(path, {make_layer("total", 2, 2, 0), make_layer("glass", 3, 2, 1)});
  ASSERT_FALSE(size);
  EXPECT_EQ(size.error().message, "image layer 'glass' does not have the size of the others");
  EXPECT_FALSE(write_exr(path, {}));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Exr, ReadingSomethingElseFailsNamingThePath) {
  TempDir dir;
  const std::string path = dir.file("not.exr");
  ASSERT_TRUE(write_file_atomic(path, "this is not an EXR file"));
  Result<ExrChannels> r = read_exr(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().where, path);
  EXPECT_EQ(r.error().message.rfind("cannot read the EXR file: ", 0), 0u);
  EXPECT_FALSE(read_exr(dir.file("missing.exr")));
}

// --- PNG previews ---

TEST(Png, PreviewsShareTheTotalsExposureAndReadBack) {
  TempDir dir;
  // Gray total with pixel luminances 0.01, 0.02, …, 1.00: the 99th percentile (nearest rank) is
  // 0.99, so the exposure is 1/0.99.
  ImageLayer total;
  total.name = "total";
  total.image.width = 10;
  total.image.height = 10;
  for (int i = 0; i < 100; ++i) total.image.rgb.insert(total.image.rgb.end(), 3, static_cast<float>(i + 1) / 100);
  ImageLayer caustic = total;
  caustic.name = "caustic";
  std::fill(caustic.image.rgb.begin(), caustic.image.rgb.end(), 0.0f);
  caustic.image.rgb[3 * 12 + 0] = 0.0099f;  // pixel (2, 1), red: 0.01 after exposure
  caustic.image.rgb[3 * 12 + 1] = 0.495f;   // green: 0.5 after exposure
  caustic.image.rgb[3 * 12 + 2] = -1.0f;    // blue: clamped to 0
  EXPECT_NEAR(preview_exposure(total.image), 1 / 0.99, 1e-6);

  ASSERT_TRUE(write_previews(dir.path().string(), {caustic, total}));
  EXPECT_EQ(dir.entries(), (std::set<std::string>{"caustic.png", "total.png"}));
  Png t = read_png(dir.file("total.png"));
  EXPECT_EQ(t.width, 10);
  EXPECT_EQ(t.height, 10);
  EXPECT_EQ(t.at(8, 9, 0), 255) << "0.99 maps to 1";
  EXPECT_EQ(t.at(9, 9, 1), 255) << "1.00 is clamped";
  EXPECT_EQ(t.at(0, 0, 2), 26) << "0.01/0.99 → sRGB 0.1005 → 25.63";
  Png c = read_png(dir.file("caustic.png"));
  EXPECT_EQ(c.at(2, 1, 0), 25) << "0.01 → sRGB 0.0999 → 25.46";
  EXPECT_EQ(c.at(2, 1, 1), 188) << "0.5 → sRGB 0.7354 → 187.52";
  EXPECT_EQ(c.at(2, 1, 2), 0);
  EXPECT_EQ(c.at(0, 0, 0), 0);
}

// Layers said to have the same pixels are made and encoded once: the files are the bytes of the
// writers that make every layer (write_exr, write_previews), and each layer still has its PNG.
class SameBands final : public LayerBands {
 public:
  explicit SameBands(const std::vector<ImageLayer>& layers) : fills(layers.size()), layers_(layers) {}
  mutable std::vector<std::atomic<int>> fills;  // fill() calls per layer
  int width() const override { return layers_[0].image.width; }
  int height() const override { return layers_[0].image.height; }
  std::size_t num_layers() const override { return layers_.size(); }
  const std::string& name(std::size_t layer) const override { return layers_[layer].name; }
  void fill(std::size_t layer, int y0, int rows, float* out) const override {
    ++fills[layer];
    const std::size_t row = static_cast<std::size_t>(width()) * 3;
    const float* src = layers_[layer].image.rgb.data() + static_cast<std::size_t>(y0) * row;
    std::copy(src, src + static_cast<std::size_t>(rows) * row, out);
  }
  bool same_pixels(std::size_t a, std::size_t b) const override { return layers_[a].image.rgb == layers_[b].image.rgb; }

 private:
  const std::vector<ImageLayer>& layers_;
};

TEST(Png, LayersWithTheSamePixelsAreMadeOnceAndWrittenAsBefore) {
  TempDir whole, once;
  const int w = 37, h = 40;  // bands of 16 rows and a short last band
  ImageLayer total = make_layer("total", w, h, 0.5f), local = total, other = make_layer("direct", w, h, 3.0f), copy = other;
  local.name = "local";
  copy.name = "copy";
  for (float& v : total.image.rgb) v /= 5000;
  local.image.rgb = total.image.rgb;
  const std::vector<ImageLayer> layers = {local, other, total, copy};
  ASSERT_TRUE(write_exr(whole.file("classes.exr"), layers));
  ASSERT_TRUE(write_previews(whole.path().string(), layers));
  const SameBands bands(layers);
  ASSERT_TRUE(write_image_files(bands, ImageFiles{once.file("classes.exr"), {}, once.path().string()}));
  EXPECT_EQ(once.entries(), whole.entries());
  for (const std::string& f : whole.entries()) EXPECT_EQ(read_bytes(once.file(f)), read_bytes(whole.file(f))) << f;
  EXPECT_EQ(read_bytes(once.file("local.png")), read_bytes(once.file("total.png")));
  // "local" (the first of its pair) is made whole for the exposure, in bands of 16 rows; the
  // others of each pair never.
  EXPECT_EQ(bands.fills[0].load(), 3);
  EXPECT_EQ(bands.fills[1].load(), 3);
  EXPECT_EQ(bands.fills[2].load(), 0);
  EXPECT_EQ(bands.fills[3].load(), 0);
}

TEST(Png, ExposureFallsBackForSparseAndBlackImages) {
  RgbImage black{4, 25, std::vector<float>(300, 0.0f)};
  EXPECT_EQ(preview_exposure(black), 1.0);
  RgbImage sparse = black;
  sparse.rgb[42] = 4.0f;  // one pixel in 100: the 99th percentile is 0
  EXPECT_DOUBLE_EQ(preview_exposure(sparse), 1 / (0.2126 * 4));
}

TEST(Png, ToneMappingNeverPassesNonFiniteValues) {
  RgbImage img{2, 1, {std::nanf(""), INFINITY, -INFINITY, 0.0031308f, 2.0f, 0.25f}};
  const std::vector<std::uint8_t> px = tonemap_srgb8(img, 1.0);
  EXPECT_EQ(px, (std::vector<std::uint8_t>{0, 0, 0, 10, 255, 137}));
}

// The sRGB transfer function (IEC 61966-2-1) rounded to 8 bits, one pow() per value: the table
// the tone mapping looks codes up in must give exactly this, at every step between two codes.
TEST(Png, ToneMappingIsTheSrgbCurveAtEveryCode) {
  const auto srgb8 = [](double v) {
    const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(255 * e));
  };
  RgbImage img{0, 1, {}};
  for (int i = 0; i <= 300000; ++i) img.rgb.push_back(static_cast<float>(i) / 300000.0f);  // every code, many times
  for (float v = 1e-7f; v < 1; v *= 1.0001f) img.rgb.push_back(v);                      // and the dark end finely
  while (img.rgb.size() % 3 != 0) img.rgb.push_back(1.0f);
  img.width = static_cast<int>(img.rgb.size() / 3);
  const std::vector<std::uint8_t> px = tonemap_srgb8(img, 1.0);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < px.size(); ++i) wrong += px[i] != srgb8(static_cast<double>(img.rgb[i]));
  EXPECT_EQ(wrong, 0u);
}

TEST(Png, EncodeRefusesMismatchedPixels) {
  Result<std::string> r = encode_png(2, 2, std::vector<std::uint8_t>(11));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "the PNG pixels do not match its size");
  Result<std::string> ok = encode_png(1, 1, {1, 2, 3});
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->substr(1, 3), "PNG");
}

// --- written whole or not at all ---

TEST(AtomicWrite, ReplacesTheFileWholeAndLeavesNoTemporary) {
  TempDir dir;
  const std::string path = dir.file("histogram.json");
  ASSERT_TRUE(write_file_atomic(path, std::string(100000, 'a')));
  ASSERT_TRUE(write_file_atomic(path, "{}\n"));
  EXPECT_EQ(read_bytes(path), "{}\n");
  EXPECT_EQ(dir.entries(), std::set<std::string>{"histogram.json"});
}

// Streamed: pieces larger and smaller than its buffer, and a patch over bytes both in the file
// and still in the buffer, give the bytes of one write.
TEST(AtomicWrite, AStreamedFileHasTheBytesOfOneWrite) {
  TempDir dir;
  const std::string path = dir.file("render.shard");
  std::string expected = std::string(3 << 20, 'a') + "0123456789" + std::string(1000, 'b');
  {
    AtomicFile file(path);
    ASSERT_TRUE(file.ok());
    file.append(std::string_view(expected).substr(0, 3 << 20));
    file.append("0123456789");
    file.append(std::string(1000, 'b'));
    EXPECT_EQ(file.size(), expected.size());
    file.write_at((3 << 20) - 2, "XXXX");  // two bytes written to the file, two still buffered
    expected.replace((3 << 20) - 2, 4, "XXXX");
    ASSERT_TRUE(file.commit());
  }
  EXPECT_EQ(read_bytes(path), expected);
  EXPECT_EQ(dir.entries(), std::set<std::string>{"render.shard"});
  {
    AtomicFile abandoned(dir.file("other.shard"));
    abandoned.append("never committed");
  }
  EXPECT_EQ(dir.entries(), std::set<std::string>{"render.shard"});
}

// Patches that continue one another (OpenEXR's offset table, eight bytes at a time) are gathered
// into one write; one that does not, or that writes over an earlier patch, still lands in order.
TEST(AtomicWrite, PatchesInPiecesGiveTheBytesOfOneWrite) {
  TempDir dir;
  const std::string path = dir.file("classes.exr");
  std::string expected(1 << 20, 'a');
  {
    AtomicFile file(path);
    file.append(expected);
    file.append("tail");  // the first MiB is in the file, "tail" still buffered
    for (int i = 0; i < 100; ++i) file.write_at(1000 + 8 * static_cast<std::uint64_t>(i), std::string(8, static_cast<char>('A' + i % 26)));
    file.write_at(500, "gap");       // not continuing: the pieces before it are written first
    file.write_at(1000, "over");     // over the first piece, after it
    file.write_at((1 << 20) - 1, "xy");  // one byte in the file, one buffered
    ASSERT_TRUE(file.commit());
  }
  for (int i = 0; i < 100; ++i) expected.replace(1000 + 8 * static_cast<std::size_t>(i), 8, std::string(8, static_cast<char>('A' + i % 26)));
  expected.replace(500, 3, "gap");
  expected.replace(1000, 4, "over");
  expected += "tail";
  expected.replace((1 << 20) - 1, 2, "xy");
  EXPECT_EQ(read_bytes(path), expected);
}

TEST(AtomicWrite, AMissingDirectoryIsAnErrorNamingThePath) {
  TempDir dir;
  const std::string path = dir.file("no/such/dir/histogram.json");
  Result<bool> r = write_file_atomic(path, "{}");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kBadFile);
  EXPECT_EQ(r.error().where, path);
  EXPECT_TRUE(dir.entries().empty());
  Result<bool> exr = write_exr(dir.file("missing/render.exr"), {make_layer("total", 2, 2, 0)});
  ASSERT_FALSE(exr);
  EXPECT_EQ(exr.error().where, dir.file("missing/render.exr"));
  Result<bool> png = write_previews(dir.file("missing"), {make_layer("total", 2, 2, 0)});
  ASSERT_FALSE(png);
  EXPECT_EQ(png.error().where, dir.file("missing/total.png"));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicWrite, AFailedRenameRemovesTheTemporary) {
  // The target is a non-empty directory: the bytes are written and flushed, then rename fails.
  TempDir dir;
  const std::string path = dir.file("render.exr");
  fs::create_directories(fs::path(path) / "occupied");
  Result<bool> r = write_exr(path, {make_layer("total", 4, 4, 0)});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().where, path);
  EXPECT_EQ(dir.entries(), std::set<std::string>{"render.exr"});
  EXPECT_TRUE(fs::is_directory(path));
}

TEST(AtomicWrite, AnUnwritableDirectoryIsAnErrorAndGetsNoFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root may write into a read-only directory";
  TempDir dir;
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  const std::string path = dir.file("histogram.json");
  Result<bool> r = write_file_atomic(path, "{}");
  fs::permissions(dir.path(), fs::perms::owner_all);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().where, path);
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace pathex
