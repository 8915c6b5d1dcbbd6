// Shard files (format in shard.h): framing and checksum first, then the JSON header, then the
// varint-encoded exact sums.
#include "output/shard.h"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <string_view>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "io/atomic_file.h"
#include "io/json_reader.h"

namespace pathex {
namespace {

using json = nlohmann::ordered_json;

static_assert(std::endian::native == std::endian::little, "shard files store raw little-endian words");

constexpr char kMagic[8] = {'P', 'X', 'S', 'H', 'A', 'R', 'D', '\n'};
constexpr std::size_t kFixedBytes = 8 + 4 + 4 + 8 + 4;  // magic, version, H, N, CRC
// A file's path and row counts are believed this far when room is made for them ahead (a damaged
// or hostile count costs at most this many paths' cells of address space per file, untouched).
constexpr std::uint64_t kMaxReservedPaths = std::uint64_t{1} << 16;
constexpr std::uint64_t kMaxReservedInAll = std::uint64_t{1} << 19;  // for all the files to come
// A tile's pixels (ClassImages: six words each, the low and high word of R, G and B).
constexpr std::size_t kTilePixels = ClassImages::kTile * ClassImages::kTile;
static_assert(kTilePixels == 64 && ClassImages::kTileWords == 6 * kTilePixels);
// Stored tiles per image frame: about 1 to 1.7 MB of body each (the merged 512 × 512 twenty-class
// render has 60 such frames), so that a file's frames decode on every core.
constexpr std::size_t kTilesPerFrame = 512;
// The body's index: K, the K + 2 frames' sizes and the K image frames' first keys.
constexpr std::size_t body_index_bytes(std::size_t image_frames) { return 4 + 8 * (image_frames + 2) + 8 * image_frames; }

std::uint32_t crc32_of(const char* data, std::size_t n) {
  return static_cast<std::uint32_t>(
      crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(data), static_cast<z_size_t>(n)));
}

template <class T>
void put_le(std::string& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
template <class T>
T get_le(const std::string& in, std::size_t at) {
  T v = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<unsigned char>(in[at + i])) << (8 * i);
  return v;
}

// --- body encoding ---

// Where an encoded shard's bytes go as they are made: a string (encode_shard) or the output file
// (write_shard, which never holds the file in memory).
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void append(std::string_view bytes) = 0;
  virtual void write_at(std::uint64_t offset, std::string_view bytes) = 0;  // over bytes appended already
};

class StringSink final : public Sink {
 public:
  explicit StringSink(std::string* out) : out_(out) {}
  void append(std::string_view bytes) override { out_->append(bytes); }
  void write_at(std::uint64_t offset, std::string_view bytes) override {
    std::memcpy(out_->data() + offset, bytes.data(), bytes.size());
  }

 private:
  std::string* out_;
};

class FileSink final : public Sink {
 public:
  explicit FileSink(AtomicFile* file) : file_(file) {}
  void append(std::string_view bytes) override { file_->append(bytes); }
  void write_at(std::uint64_t offset, std::string_view bytes) override { file_->write_at(offset, bytes); }

 private:
  AtomicFile* file_;
};

// Encodes the body into a staging window and compresses each full window into the sink, keeping
// the compressed bytes' count and CRC-32. zstd at its fast level -3: the varints' high bytes and
// the images' zeros still shrink to 0.72 of the body where level 1 gave 0.63, in half the time
// (the merged 512 × 512 twenty-class render's 60 MB body: 0.17 against 0.34 s CPU, 43 against 37
// MB; `zstd --fast=3`), so a render's shard file costs less to write than its images.
class Writer {
 public:
  explicit Writer(Sink* out)
      : out_(out), stream_(ZSTD_createCStream()), window_(kWindow), compressed_(ZSTD_CStreamOutSize()) {
    ZSTD_initCStream(stream_, /*compressionLevel=*/-3);
  }
  ~Writer() { ZSTD_freeCStream(stream_); }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  void u(std::uint64_t v) {
    room(10);
    while (v >= 0x80) {
      window_[used_++] = static_cast<char>((v & 0x7f) | 0x80);
      v >>= 7;
    }
    window_[used_++] = static_cast<char>(v);
  }
  void x(ExactSum v) {
    ExactSum z = (v << 1) ^ static_cast<ExactSum>(static_cast<SignedExactSum>(v) >> 127);
    if (z >> 64 == 0) return u(static_cast<std::uint64_t>(z));
    room(19);
    while (z >= 0x80) {
      window_[used_++] = static_cast<char>((static_cast<unsigned>(z) & 0x7f) | 0x80);
      z >>= 7;
    }
    window_[used_++] = static_cast<char>(z);
  }
  void rgb(const ExactRgb& c) {
    x(c[0]);
    x(c[1]);
    x(c[2]);
  }
  // Eight bytes, little-endian (the machine's order, asserted above).
  void raw64(std::uint64_t v) {
    room(8);
    std::memcpy(window_.data() + used_, &v, 8);
    used_ += 8;
  }
  // A signed 64-bit integer as the varint of its zigzag form (one byte from -64 to 63).
  void signed64(std::int64_t v) { u((static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63)); }
  void bytes(std::string_view s) {
    for (std::size_t at = 0; at < s.size();) {
      room(1);
      const std::size_t n = std::min(s.size() - at, window_.size() - used_);
      std::memcpy(window_.data() + used_, s.data() + at, n);
      used_ += n;
      at += n;
    }
  }
  void text(const std::string& s) {
    u(s.size());
    bytes(s);
  }
  // Compresses what is left and ends the frame; what follows starts another. Its compressed size.
  std::uint64_t end_frame() {
    compress(ZSTD_e_end);
    const std::uint64_t n = size_ - frame_start_;
    frame_start_ = size_;
    return n;
  }
  std::uint64_t size() const { return size_; }  // compressed bytes so far
  std::uint32_t crc() const { return crc_; }    // their CRC-32

 private:
  // zstd's block (ZSTD_CStreamInSize()): a larger window only costs fresh pages (a 1 MiB one was
  // 5 % of a small render's per-run cost, bench/README.md).
  static constexpr std::size_t kWindow = std::size_t{1} << 17;
  void room(std::size_t n) {
    if (window_.size() - used_ < n) compress(ZSTD_e_continue);
  }
  void compress(ZSTD_EndDirective mode) {
    ZSTD_inBuffer in{window_.data(), used_, 0};
    for (;;) {
      ZSTD_outBuffer o{compressed_.data(), compressed_.size(), 0};
      const std::size_t left = ZSTD_compressStream2(stream_, &o, &in, mode);
      if (ZSTD_isError(left)) throw std::bad_alloc();  // with valid buffers zstd fails only to allocate
      const std::string_view piece(compressed_.data(), o.pos);
      crc_ = static_cast<std::uint32_t>(crc32_z(crc_, reinterpret_cast<const Bytef*>(piece.data()), piece.size()));
      size_ += piece.size();
      out_->append(piece);
      if (mode == ZSTD_e_end ? left == 0 : in.pos == in.size) break;
    }
    used_ = 0;
  }

  Sink* out_;
  ZSTD_CStream* stream_;
  std::vector<char> window_;
  std::vector<char> compressed_;  // one output block of the stream, reused
  std::size_t used_ = 0;
  std::uint64_t size_ = 0, frame_start_ = 0;
  std::uint32_t crc_ = 0;
};

// Reads the body as it is decompressed, a window at a time (the whole body is never in memory;
// its size, whatever the file claims, costs no allocation). Any read past its end or of a
// damaged frame sets failed() and returns zeros, so a decoder checks once.
class Reader {
 public:
  Reader(const char* p, std::size_t n) : stream_(ZSTD_createDStream()), in_{p, n, 0}, window_(kWindow) {
    if (stream_ == nullptr || ZSTD_isError(ZSTD_initDStream(stream_))) failed_ = true;
  }
  ~Reader() { ZSTD_freeDStream(stream_); }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  bool failed() const { return failed_; }
  // The body's last byte was read and nothing follows it.
  bool at_end() {
    refill(1);
    return !failed_ && p_ == end_ && in_.pos == in_.size;
  }
  std::uint64_t u() {
    refill(kMaxVarint);
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (p_ == end_) return fail();
      const auto b = static_cast<unsigned char>(*p_++);
      v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
      if (b < 0x80) return v;
    }
    return fail();
  }
  // A zigzag 128-bit sum. The low 63 bits (nine bytes) are gathered in 64-bit arithmetic: sums
  // of a few contributions near 1 (2^64 on the grid) rarely need more.
  ExactSum x() {
    refill(kMaxVarint);
    std::uint64_t low = 0;
    for (int shift = 0; shift < 63; shift += 7) {
      if (p_ == end_) return fail();
      const auto b = static_cast<unsigned char>(*p_++);
      low |= static_cast<std::uint64_t>(b & 0x7f) << shift;
      if (b < 0x80) return unzigzag(low);
    }
    ExactSum z = low;
    for (int shift = 63; shift < 128; shift += 7) {
      if (p_ == end_) return fail();
      const auto b = static_cast<unsigned char>(*p_++);
      z |= static_cast<ExactSum>(b & 0x7f) << shift;
      if (b < 0x80) return unzigzag(z);
    }
    return fail();
  }
  ExactRgb rgb() { return {x(), x(), x()}; }
  std::uint64_t raw64() {
    refill(8);
    if (end_ - p_ < 8) return fail();
    std::uint64_t v;
    std::memcpy(&v, p_, 8);  // little-endian hosts only (static_assert at the top)
    p_ += 8;
    return v;
  }
  std::int64_t signed64() {
    const std::uint64_t z = u();
    return static_cast<std::int64_t>((z >> 1) ^ (std::uint64_t{0} - (z & 1)));
  }
  // The next `n` ≤ kMaxBytes bytes, in the window: valid until the next read.
  std::string_view bytes(std::size_t n) {
    if (n > kMaxBytes) return fail(), std::string_view();
    refill(n);
    if (n > static_cast<std::size_t>(end_ - p_)) return fail(), std::string_view();
    const std::string_view s(p_, n);
    p_ += n;
    return s;
  }
  // A string in the window: valid until the next read (no allocation per path string).
  std::string_view text() {
    const std::uint64_t n = u();
    if (n > kMaxBytes) return fail(), std::string_view();
    return bytes(static_cast<std::size_t>(n));
  }
  static constexpr std::size_t kMaxBytes = std::size_t{1} << 19;  // a string, or a piece of a byte plane

 private:
  static constexpr std::size_t kWindow = std::size_t{1} << 20;
  static constexpr std::size_t kMaxVarint = 19;  // 128 bits, 7 per byte
  static ExactSum unzigzag(ExactSum z) { return (z >> 1) ^ (ExactSum{0} - (z & 1)); }

  // Makes at least `n` bytes readable, unless the body ends first.
  void refill(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) >= n || failed_ || finished_) return;
    const std::size_t kept = static_cast<std::size_t>(end_ - p_);
    // Before the first refill p_ is null, and memmove's arguments must not be, even for 0 bytes
    // (UBSan's nonnull-attribute check, `pathex merge` in the sanitized build).
    if (kept > 0) std::memmove(window_.data(), p_, kept);
    ZSTD_outBuffer out{window_.data(), window_.size(), kept};
    while (out.pos < n || (out.pos < out.size && in_.pos < in_.size)) {
      const std::size_t before = out.pos, taken = in_.pos;
      const std::size_t r = ZSTD_decompressStream(stream_, &out, &in_);
      if (ZSTD_isError(r)) {
        fail();
        return;
      }
      if (r == 0 && in_.pos == in_.size) {
        finished_ = true;
        break;
      }
      if (out.pos == before && in_.pos == taken) break;  // no progress: the frame is cut short
    }
    p_ = window_.data();
    end_ = window_.data() + out.pos;
  }
  std::uint64_t fail() {
    failed_ = true;
    p_ = end_;
    return 0;
  }

  ZSTD_DStream* stream_;
  ZSTD_inBuffer in_;
  std::vector<char> window_;
  const char* p_ = nullptr;
  const char* end_ = nullptr;
  bool failed_ = false;
  bool finished_ = false;
};

// --- header ---

// A roulette threshold: `auto` (negative: chosen by the render's pilot, trace/accel/join_plan.h) or its value.
json auto_or_number(double threshold) { return threshold < 0 ? json("auto") : json(threshold); }

json identity_json(const RenderIdentity& id) {
  json j = json::object();
  j["pathex"] = id.pathex;
  j["scene"] = {{"name", id.scene}, {"file", id.scene_file}, {"hash", id.scene_hash}};
  j["renderer"] = {{"name", id.renderer}, {"source", id.renderer_source}, {"hash", id.renderer_hash}};
  j["classes"] = {{"file", id.classes_file}, {"text", id.classes_text}, {"hash", id.classes_hash}};
  if (!id.only.empty()) j["classes"]["only"] = id.only;  // absent when every class is rendered
  j["ends"] = {{"lights", id.lights}, {"sensor", id.sensor}};
  j["seed"] = id.seed;
  j["options"] = {{"max_bounces", id.max_bounces}, {"sampler", id.sampler}, {"light_sampling", id.light_sampling}, {"rr_depth", id.rr_depth},
                  {"rr_threshold", auto_or_number(id.rr_threshold)}, {"rr_light_threshold", id.rr_light_threshold},
                  {"rr_join_threshold", auto_or_number(id.rr_join_threshold)},
                  {"splits", id.splits}, {"batches", id.batches},
                  {"replicates", id.replicates}, {"width", id.width},           {"height", id.height},     {"images", id.images},
                  {"max_paths", id.max_paths}};
  if (const std::optional<ManifoldOptions>& m = id.manifold) {
    j["options"]["manifold"] = {{"max_iterations", m->max_iterations}, {"threshold", m->threshold},
                                {"min_segment", m->min_segment},       {"singular", m->singular},
                                {"max_trials", m->max_trials},             {"seeds", m->seeds.value_or(kManifoldSeeds)}};
    // Only when set: an unbiased render's header is as before.
    if (m->biased_trials > 0) j["options"]["manifold"]["biased_trials"] = m->biased_trials;
    if (m->rate.value_or(1.0) != 1.0) j["options"]["manifold"]["rate"] = *m->rate;
  } else {
    j["options"]["manifold"] = nullptr;
  }
  j["strategies"] = id.strategies;
  json connectors = json::array();
  for (const ConnectorStrategy& c : id.connectors) connectors.push_back({{"strategy", c.strategy}, {"connector", c.connector}});
  j["connectors"] = std::move(connectors);
  return j;
}

// Reads the header through the one JSON reader (io/json_reader.h), keeping its first error (a
// located kBadFile at "file:/pointer"), so the walk below reads as a list of fields.
class HeaderFields {
 public:
  using Json = nlohmann::json;
  explicit HeaderFields(const std::string& path) : rd_(path) {}
  std::optional<Error> error;

  // `obj` must be an object with exactly these keys.
  bool object(const Json& obj, const std::string& ptr, std::initializer_list<const char*> keys) {
    return take(rd_.keys(obj, ptr, keys), false);
  }
  std::string str(const Json& obj, const std::string& ptr, const char* key) {
    return take(rd_.string(obj, key, ptr), std::string());
  }
  std::uint64_t uint(const Json& obj, const std::string& ptr, const char* key) {
    return take(rd_.unsigned_integer(obj, key, ptr, std::numeric_limits<std::uint64_t>::max()), std::uint64_t{0});
  }
  int small(const Json& obj, const std::string& ptr, const char* key) {
    return static_cast<int>(take(rd_.integer(obj, key, ptr, 0, 1 << 30), 0LL));
  }
  double number(const Json& obj, const std::string& ptr, const char* key) {
    return take(rd_.number(obj, key, ptr, 0, std::numeric_limits<double>::max()), 0.0);
  }
  bool boolean(const Json& obj, const std::string& ptr, const char* key) {
    return take(rd_.boolean(obj, key, ptr), false);
  }
  std::vector<std::string> strings(const Json& obj, const std::string& ptr, const char* key) {
    std::vector<std::string> out;
    const std::string p = ptr + "/" + key;
    if (error) return out;
    const Json& v = obj.at(key);
    if (!v.is_array()) return fail(p, "expected an array of strings, found " + JsonReader::kind(v)), out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string()) return fail(p + "/" + std::to_string(i), "expected a string, found " + JsonReader::kind(v[i])), out;
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }
  PassSet passes(const Json& obj, const char* key) {
    PassSet set;
    const std::string ptr = std::string("/") + key;
    if (error) return set;
    const Json& p = obj.at(key);
    if (!p.is_array()) return fail(ptr, "expected an array of [first, last) pairs, found " + JsonReader::kind(p)), set;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Json& r = p[i];
      if (!r.is_array() || r.size() != 2 || !r[0].is_number_unsigned() || !r[1].is_number_unsigned() ||
          r[0].get<std::uint64_t>() >= r[1].get<std::uint64_t>() || (!set.empty() && r[0].get<std::uint64_t>() <= set.end())) {
        fail(ptr + "/" + std::to_string(i), "expected [first, last) with first < last, after the previous range");
        break;
      }
      set.add(r[0].get<std::uint64_t>(), r[1].get<std::uint64_t>());
    }
    return set;
  }
  void fail(const std::string& ptr, std::string message) {
    if (!error) error = rd_.fail(ptr, std::move(message));
  }

 private:
  template <class T, class U>
  T take(Result<T> r, U fallback) {
    if (error) return static_cast<T>(fallback);
    if (!r.ok()) {
      error = r.error();
      return static_cast<T>(fallback);
    }
    return std::move(r.value());
  }
  JsonReader rd_;
};

Result<ShardHeader> header_from_json(const nlohmann::json& j, const std::string& path) {
  HeaderFields rd(path);
  ShardHeader h;
  RenderIdentity& id = h.identity;
  if (!rd.object(j, "", {"pathex", "scene", "renderer", "classes", "ends", "seed", "options", "strategies", "connectors",
                         "spp", "share", "passes", "run"}))
    return *rd.error;
  for (const char* key : {"pathex", "scene", "renderer", "classes", "ends", "seed", "options", "strategies", "connectors",
                          "spp", "share", "passes", "run"})
    if (!j.contains(key)) return rd.fail(std::string("/") + key, std::string("missing ") + key), *rd.error;
  id.pathex = rd.str(j, "", "pathex");
  // Objects of three strings: {name, file, hash} and the like.
  const auto strings3 = [&](const char* key, const std::array<std::pair<const char*, std::string*>, 3>& fields) {
    const std::string ptr = std::string("/") + key;
    if (!rd.object(j.at(key), ptr, {fields[0].first, fields[1].first, fields[2].first})) return;
    for (const auto& [name, out] : fields) *out = rd.str(j.at(key), ptr, name);
  };
  strings3("scene", {{{"name", &id.scene}, {"file", &id.scene_file}, {"hash", &id.scene_hash}}});
  strings3("renderer", {{{"name", &id.renderer}, {"source", &id.renderer_source}, {"hash", &id.renderer_hash}}});
  nlohmann::json classes = j.at("classes");
  if (classes.is_object() && classes.contains("only")) {  // --only's classes, when given
    id.only = rd.strings(classes, "/classes", "only");
    classes.erase("only");
  }
  if (rd.object(classes, "/classes", {"file", "text", "hash"}))
    for (const auto& [name, out] : {std::pair{"file", &id.classes_file}, std::pair{"text", &id.classes_text},
                                    std::pair{"hash", &id.classes_hash}})
      *out = rd.str(classes, "/classes", name);
  if (rd.object(j.at("ends"), "/ends", {"lights", "sensor"})) {
    id.lights = rd.strings(j.at("ends"), "/ends", "lights");
    id.sensor = rd.str(j.at("ends"), "/ends", "sensor");
  }
  id.seed = rd.uint(j, "", "seed");
  h.spp = rd.uint(j, "", "spp");
  const nlohmann::json& o = j.at("options");
  if (rd.object(o, "/options", {"max_bounces", "sampler", "light_sampling", "rr_depth", "rr_threshold", "rr_light_threshold", "rr_join_threshold", "splits", "batches",
                                "replicates", "width", "height", "images", "max_paths", "manifold"})) {
    id.max_bounces = rd.small(o, "/options", "max_bounces");
    id.sampler = rd.str(o, "/options", "sampler");
    // Before issue 39's solid-angle sampling (eighth session) every light was sampled by area.
    id.light_sampling = o.contains("light_sampling") ? rd.str(o, "/options", "light_sampling") : "area";
    id.rr_depth = rd.small(o, "/options", "rr_depth");
    // `auto` (the pilot's choice, trace/accel/join_plan.h) or the threshold.
    const auto threshold = [&](const char* name) -> double {
      if (!o.at(name).is_string()) return rd.number(o, "/options", name);
      if (rd.str(o, "/options", name) != "auto") rd.fail(std::string("/options/") + name, "expected auto or a number");
      return -1.0;  // kEyeThresholdAuto, kJoinThresholdAuto
    };
    id.rr_threshold = threshold("rr_threshold");
    // Before issue 39 one threshold served both subpaths.
    id.rr_light_threshold = o.contains("rr_light_threshold") ? rd.number(o, "/options", "rr_light_threshold") : id.rr_threshold;
    // Before issue 39's join roulette every eye vertex made all its joins.
    id.rr_join_threshold = o.contains("rr_join_threshold") ? threshold("rr_join_threshold") : 0.0;
    // Before issue 39's splitting (tenth session) no sample was split.
    id.splits = o.contains("splits") ? rd.small(o, "/options", "splits") : 1;
    id.batches = rd.small(o, "/options", "batches");
    // Before issue 39's pixel groups every batch was a replicate of the whole image.
    id.replicates = o.contains("replicates") ? rd.small(o, "/options", "replicates") : id.batches;
    id.width = rd.small(o, "/options", "width");
    id.height = rd.small(o, "/options", "height");
    id.images = rd.boolean(o, "/options", "images");
    id.max_paths = rd.uint(o, "/options", "max_paths");
    if (!o.contains("manifold")) rd.fail("/options/manifold", "missing manifold (null, or the manifold connector's limits)");
    else if (const nlohmann::json& m = o.at("manifold"); !m.is_null() &&
        rd.object(m, "/options/manifold", {"max_iterations", "threshold", "min_segment", "singular", "max_trials", "seeds", "biased_trials", "rate"})) {
      const char* mp = "/options/manifold";
      ManifoldOptions limits;
      limits.max_iterations = rd.small(m, mp, "max_iterations");
      limits.threshold = rd.number(m, mp, "threshold");
      limits.min_segment = rd.number(m, mp, "min_segment");
      limits.singular = rd.number(m, mp, "singular");
      limits.max_trials = rd.small(m, mp, "max_trials");
      limits.seeds = rd.small(m, mp, "seeds");
      if (m.contains("biased_trials")) limits.biased_trials = rd.small(m, mp, "biased_trials");
      limits.rate = m.contains("rate") ? rd.number(m, mp, "rate") : 1.0;  // absent: every sample (as before issue 40)
      id.manifold = limits;
    }
  }
  if (!rd.error && (id.batches < 1 || id.batches > 1000000)) rd.fail("/options/batches", "expected 1 to 1000000 batches");
  if (!rd.error && (id.replicates < 1 || id.batches % id.replicates != 0))
    rd.fail("/options/replicates", "expected a divisor of the batch count " + std::to_string(id.batches));
  id.strategies = rd.strings(j, "", "strategies");
  if (const nlohmann::json& c = j.at("connectors"); !c.is_array()) {
    rd.fail("/connectors", "expected an array of {strategy, connector}, found " + JsonReader::kind(c));
  } else {
    for (std::size_t i = 0; i < c.size(); ++i) {
      const std::string ptr = "/connectors/" + std::to_string(i);
      if (!rd.object(c[i], ptr, {"strategy", "connector"})) break;
      id.connectors.push_back({rd.str(c[i], ptr, "strategy"), rd.str(c[i], ptr, "connector")});
    }
  }
  h.share = rd.passes(j, "share");
  h.passes = rd.passes(j, "passes");
  const nlohmann::json& r = j.at("run");
  if (rd.object(r, "/run", {"time_s", "threads", "rays", "cpu_s"})) {
    h.run.time_s = rd.number(r, "/run", "time_s");
    h.run.cpu_s = rd.number(r, "/run", "cpu_s");
    h.run.threads = rd.small(r, "/run", "threads");
    h.run.rays = rd.uint(r, "/run", "rays");
  }
  if (rd.error) return *rd.error;
  return h;
}

Error file_error(const std::string& path, const std::string& message) {
  Error e = make_error(ErrorCode::kBadFile, message);
  e.where = path;
  return e;
}

}  // namespace

std::optional<std::string> identity_difference(const RenderIdentity& a, const RenderIdentity& b) {
  const auto differ = [](const std::string& what, const std::string& x, const std::string& y) {
    return std::optional<std::string>(what + " (" + x + " against " + y + ")");
  };
  if (a.pathex != b.pathex) return differ("another pathex version", a.pathex, b.pathex);
  if (a.scene_hash != b.scene_hash)
    return differ("another scene", "content hash " + a.scene_hash + ", " + a.scene,
                  "content hash " + b.scene_hash + ", " + b.scene);
  if (a.renderer_hash != b.renderer_hash || a.renderer != b.renderer)
    return differ("another renderer profile", a.renderer + ", hash " + a.renderer_hash,
                  b.renderer + ", hash " + b.renderer_hash);
  if (a.seed != b.seed) return differ("another seed", std::to_string(a.seed), std::to_string(b.seed));
  if (a.classes_hash != b.classes_hash) {
    const auto name = [](const RenderIdentity& i) {
      return (i.classes_file.empty() ? std::string("the built-in classes") : i.classes_file) + ", hash " + i.classes_hash;
    };
    return differ("another class file", name(a), name(b));
  }
  if (a.only != b.only) {
    const auto list = [](const std::vector<std::string>& v) {
      std::string out;
      for (const std::string& e : v) out += (out.empty() ? "" : " ") + std::string("--only '") + e + "'";
      return out.empty() ? std::string("every class") : out;
    };
    return differ("other requested classes", list(a.only), list(b.only));
  }
  const auto option = [&](const char* name, long long x, long long y) -> std::optional<std::string> {
    if (x == y) return std::nullopt;
    return differ(std::string("another ") + name, std::to_string(x), std::to_string(y));
  };
  if (auto d = option("max_bounces", a.max_bounces, b.max_bounces)) return d;
  if (a.sampler != b.sampler) return differ("another sampler", a.sampler, b.sampler);
  if (a.light_sampling != b.light_sampling) return differ("another light sampling", a.light_sampling, b.light_sampling);
  if (auto d = option("rr_depth", a.rr_depth, b.rr_depth)) return d;
  const auto text = [](double t) { return t < 0 ? std::string("auto") : std::to_string(t); };
  if (a.rr_threshold != b.rr_threshold) return differ("another rr_threshold", text(a.rr_threshold), text(b.rr_threshold));
  if (a.rr_light_threshold != b.rr_light_threshold)
    return differ("another rr_light_threshold", std::to_string(a.rr_light_threshold), std::to_string(b.rr_light_threshold));
  if (a.rr_join_threshold != b.rr_join_threshold) return differ("another rr_join_threshold", text(a.rr_join_threshold), text(b.rr_join_threshold));
  if (auto d = option("splits", a.splits, b.splits)) return d;
  if (auto d = option("batch count", a.batches, b.batches)) return d;
  if (auto d = option("replicate count", a.replicates, b.replicates)) return d;
  if (a.width != b.width || a.height != b.height)
    return differ("another resolution", std::to_string(a.width) + "x" + std::to_string(a.height),
                  std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.images != b.images)
    return differ("another image setting", a.images ? "images" : "--no-images", b.images ? "images" : "--no-images");
  if (auto d = option("--max-paths", static_cast<long long>(a.max_paths), static_cast<long long>(b.max_paths))) return d;
  if (a.manifold && b.manifold) {  // both run the manifold connector (the profile hashes agree)
    const ManifoldOptions &x = *a.manifold, &y = *b.manifold;
    const auto real = [&](const char* name, double u, double v) -> std::optional<std::string> {
      if (u == v) return std::nullopt;
      return differ(std::string("another ") + name, JsonReader::fmt(u), JsonReader::fmt(v));
    };
    if (auto d = option("--manifold-iterations", x.max_iterations, y.max_iterations)) return d;
    if (auto d = real("--manifold-threshold", x.threshold, y.threshold)) return d;
    if (auto d = real("--manifold-min-segment", x.min_segment, y.min_segment)) return d;
    if (auto d = real("--manifold-singular", x.singular, y.singular)) return d;
    if (auto d = option("--manifold-trials", x.max_trials, y.max_trials)) return d;
    if (auto d = option("--manifold-seeds", x.seeds.value_or(kManifoldSeeds), y.seeds.value_or(kManifoldSeeds))) return d;
    if (auto d = option("--manifold-biased-trials", x.biased_trials, y.biased_trials)) return d;
    if (auto d = real("--manifold-rate", x.rate.value_or(1.0), y.rate.value_or(1.0))) return d;
  } else if (a.manifold.has_value() != b.manifold.has_value()) {
    return std::optional<std::string>("another manifold setting (one runs the manifold connector, the other does not)");
  }
  // Derived from what the hashes cover; different only in a hand-made file.
  if (a.strategies != b.strategies || a.connectors != b.connectors || a.lights != b.lights || a.sensor != b.sensor ||
      a.classes_text != b.classes_text)
    return std::optional<std::string>("another render description (strategies, connectors, end types or class text)");
  return std::nullopt;
}

namespace {

// The file into `sink`, in order but for N and the body's index, written over their placeholders
// at the end; the CRC-32 of the whole is that of the prefix and the index combined with the
// frames', which the Writer kept.
// Every technique row's nonzero batch sums, in batch order: row r's are [begin[r], begin[r + 1]).
struct RowBatchSums {
  std::vector<std::size_t> begin;
  std::vector<int> batch;
  std::vector<ExactSum> sum;
};

RowBatchSums row_batch_sums(const Histogram& h) {
  const int rows = h.num_rows();
  RowBatchSums out;
  out.begin.reserve(static_cast<std::size_t>(rows) + 1);
  out.begin.push_back(0);
  for (int r = 0; r < rows; ++r) {
    h.for_each_row_sum(r, [&](int b, ExactSum s) {
      if (s == 0) return;
      out.batch.push_back(b);
      out.sum.push_back(s);
    });
    out.begin.push_back(out.batch.size());
  }
  return out;
}

void encode_shard_into(Sink& sink, const ShardHeader& header, const RenderSums& state) {
  const Histogram& h = state.histogram;
  const ClassImages& images = state.images;
  json hj = identity_json(header.identity);
  hj["spp"] = header.spp;
  const auto passes_json = [](const PassSet& set) {
    json a = json::array();
    for (const PassRange& r : set.ranges()) a.push_back(json::array({r.first, r.last}));
    return a;
  };
  hj["share"] = passes_json(header.share);
  hj["passes"] = passes_json(header.passes);
  hj["run"] = {{"time_s", header.run.time_s}, {"threads", header.run.threads}, {"rays", header.run.rays},
               {"cpu_s", header.run.cpu_s}};
  const std::string head = hj.dump(1) + "\n";

  // The stored tiles (any nonzero word), in key order, and the image frames they fall into.
  const std::size_t planes = images.num_planes(), tiles = images.num_tiles();
  std::vector<std::pair<std::size_t, std::size_t>> stored;
  for (std::size_t p = 0; p < planes; ++p)
    for (std::size_t t = 0; t < tiles; ++t)
      if (const std::uint64_t* words = images.tile_words(p, t);
          words != nullptr && std::any_of(words, words + ClassImages::kTileWords, [](std::uint64_t v) { return v != 0; }))
        stored.emplace_back(p, t);
  const std::size_t frames = (stored.size() + kTilesPerFrame - 1) / kTilesPerFrame;

  std::string prefix(kMagic, sizeof kMagic);
  put_le<std::uint32_t>(prefix, kShardFormatVersion);
  put_le<std::uint32_t>(prefix, static_cast<std::uint32_t>(head.size()));
  prefix += head;
  put_le<std::uint64_t>(prefix, 0);  // N, once the body is written
  sink.append(prefix);
  std::string index(body_index_bytes(frames), '\0');  // written again once the frames' sizes are known
  sink.append(index);
  std::vector<std::uint64_t> sizes;
  Writer w(&sink);
  // --- histogram ---
  for (int b = 0; b < h.num_batches(); ++b) w.u(h.batch_samples(b));
  w.u(h.nonfinite());
  w.x(h.magnitude());
  std::vector<Histogram::PathId> order(static_cast<std::size_t>(h.num_paths()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Histogram::PathId>(i);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return h.path(a) < h.path(b); });
  const RowBatchSums row_sums = row_batch_sums(h);
  w.u(order.size());
  w.u(static_cast<std::uint64_t>(h.num_rows()));
  // Only the cells that hold something, in batch order.
  std::vector<std::pair<int, const Histogram::Cell*>> held;
  for (Histogram::PathId p : order) {
    w.text(h.path(p));
    held.clear();
    h.for_each_cell(p, [&](int b, const Histogram::Cell& c) {
      if (c.contributions != 0 || !is_zero(c.sum)) held.emplace_back(b, &c);
    });
    w.u(held.size());
    int previous = -1;
    for (const auto& [b, c] : held) {
      w.u(static_cast<std::uint64_t>(b - previous - 1));
      previous = b;
      w.u(c->contributions);
      w.rgb(c->sum);
    }
    const std::vector<int> rows = h.sorted_rows(p);
    w.u(rows.size());
    for (int r : rows) {
      w.u(static_cast<std::uint64_t>(h.row(r).technique));
      w.u(h.row(r).contributions);
      const std::size_t first = row_sums.begin[static_cast<std::size_t>(r)], end = row_sums.begin[static_cast<std::size_t>(r) + 1];
      w.u(static_cast<std::uint64_t>(end - first));
      for (std::size_t i = first, last = 0; i < end; ++i) {
        const auto b = static_cast<std::size_t>(row_sums.batch[i]);
        w.u(static_cast<std::uint64_t>(b - last));  // the batches skipped since the last
        last = b + 1;
        w.x(row_sums.sum[i]);
      }
    }
  }
  sizes.push_back(w.end_frame());
  // --- images, kTilesPerFrame stored tiles a frame: the tiles' keys and masks, then their sums'
  // low words in byte planes, then their high words ---
  std::vector<std::uint64_t> first_keys, low, high;
  std::string plane;
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t begin = f * kTilesPerFrame, end = std::min(stored.size(), begin + kTilesPerFrame);
    first_keys.push_back(stored[begin].first * tiles + stored[begin].second);
    w.u(planes);
    w.u(tiles);
    w.u(end - begin);
    low.clear();
    high.clear();
    for (std::size_t i = begin; i < end; ++i) {
      const auto [p, t] = stored[i];
      w.u(p);
      w.u(t);
      const std::uint64_t* words = images.tile_words(p, t);
      std::uint64_t mask = 0;  // the tile's pixels with a nonzero sum
      for (std::size_t k = 0; k < kTilePixels; ++k)
        if (std::any_of(words + 6 * k, words + 6 * k + 6, [](std::uint64_t v) { return v != 0; })) mask |= std::uint64_t{1} << k;
      w.raw64(mask);
      for (std::size_t k = 0; k < kTilePixels; ++k)
        if (mask >> k & 1)
          for (std::size_t c = 0; c < 6; c += 2) {
            low.push_back(words[6 * k + c]);
            high.push_back(words[6 * k + c + 1]);
          }
    }
    plane.resize(low.size());
    for (int j = 0; j < 8; ++j) {
      for (std::size_t i = 0; i < low.size(); ++i) plane[i] = static_cast<char>(low[i] >> (8 * j));
      w.bytes(plane);
    }
    for (std::uint64_t v : high) w.signed64(static_cast<std::int64_t>(v));
    sizes.push_back(w.end_frame());
  }
  // --- connector statistics ---
  w.u(state.connectors.size());
  for (const ConnectorStats& c : state.connectors)
    for (const std::uint64_t* count : ConnectorStats::counts_of(c)) w.u(*count);
  sizes.push_back(w.end_frame());

  index.clear();
  put_le<std::uint32_t>(index, static_cast<std::uint32_t>(frames));
  for (std::uint64_t n : sizes) put_le<std::uint64_t>(index, n);
  for (std::uint64_t k : first_keys) put_le<std::uint64_t>(index, k);
  sink.write_at(prefix.size(), index);
  std::string n;
  put_le<std::uint64_t>(n, index.size() + w.size());
  prefix.replace(prefix.size() - 8, 8, n);
  sink.write_at(prefix.size() - 8, n);
  const auto crc = static_cast<std::uint32_t>(
      crc32_combine(crc32_of((prefix + index).data(), prefix.size() + index.size()), w.crc(), static_cast<z_off_t>(w.size())));
  std::string tail;
  put_le<std::uint32_t>(tail, crc);
  sink.append(tail);
}

}  // namespace

std::string encode_shard(const ShardHeader& header, const RenderSums& sums) {
  std::string out;
  StringSink sink(&out);
  encode_shard_into(sink, header, sums);
  return out;
}

Result<bool> write_shard(const std::string& path, const ShardHeader& header, const RenderSums& sums) {
  AtomicFile file(path);
  FileSink sink(&file);
  if (file.ok()) encode_shard_into(sink, header, sums);
  return file.commit();
}

Result<ShardFile> parse_shard(std::string bytes, const std::string& path) {
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    if (bytes.size() < 16 && std::memcmp(bytes.data(), kMagic, std::min(bytes.size(), sizeof kMagic)) == 0)
      return file_error(path, "truncated shard file: " + std::to_string(bytes.size()) + " bytes");
    return file_error(path, "not a pathex shard file (it does not begin with \"PXSHARD\")");
  }
  const auto version = get_le<std::uint32_t>(bytes, 8);
  if (version != kShardFormatVersion)
    return file_error(path, "shard file format version " + std::to_string(version) + "; this pathex reads version " +
                                std::to_string(kShardFormatVersion));
  const std::uint64_t head_size = get_le<std::uint32_t>(bytes, 12);
  const std::uint64_t size = bytes.size();
  const auto truncated = [&](std::uint64_t expected) {
    return file_error(path, "truncated shard file: " + std::to_string(size) + " bytes, its header says at least " +
                                std::to_string(expected));
  };
  if (size < kFixedBytes + head_size) return truncated(kFixedBytes + head_size);
  const std::uint64_t body_size = get_le<std::uint64_t>(bytes, 16 + head_size);
  if (body_size > size || size - kFixedBytes - head_size < body_size) return truncated(kFixedBytes + head_size + body_size);
  if (size != kFixedBytes + head_size + body_size)
    return file_error(path, "corrupted shard file: " + std::to_string(size - kFixedBytes - head_size - body_size) +
                                " bytes after its checksum");
  const auto stored = get_le<std::uint32_t>(bytes, size - 4);
  if (crc32_of(bytes.data(), size - 4) != stored)
    return file_error(path, "corrupted shard file: its CRC-32 does not match its contents");

  Result<nlohmann::json> hj = parse_json(std::string_view(bytes).substr(16, head_size), path);
  if (!hj) return hj.error();
  Result<ShardHeader> header = header_from_json(*hj, path);
  if (!header) return header.error();
  ShardFile f;
  f.path = path;
  f.header = std::move(*header);
  f.body_offset = 24 + head_size;
  f.body_size = body_size;
  f.bytes = std::move(bytes);
  return f;
}

Result<ShardFile> read_shard(const std::string& path, std::string buffer) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return file_error(path, "cannot open the shard file");
  const std::streamoff size = in.tellg();
  std::string bytes = std::move(buffer);
  const auto n = static_cast<std::size_t>(std::max<std::streamoff>(size, 0));
  if (n > bytes.capacity()) {
    // Room for files a little larger than this one too (the shards of a render differ in size by
    // a fraction of a percent), so that the buffer passed on to read the next is not reallocated
    // into fresh pages; the old contents are not copied.
    bytes.clear();
    bytes.reserve(n + n / 16);
  }
  bytes.resize(n);
  in.seekg(0);
  if (size < 0 || !in.read(bytes.data(), size)) return file_error(path, "cannot read the shard file");
  return parse_shard(std::move(bytes), path);
}

namespace {

using BadBody = std::optional<std::string>;  // what is wrong with a frame, if anything

// The histogram frame, added to `h`.
BadBody add_histogram(Reader& r, Histogram* h, std::size_t files) {
  const int B = h->num_batches(), S = h->num_strategies();
  std::vector<ExactSum> technique_sums(static_cast<std::size_t>(B));
  for (int b = 0; b < B; ++b) h->add_samples(b, r.u());
  h->add_nonfinite(r.u());
  h->add_magnitude(r.x());
  const std::uint64_t paths = r.u(), rows_in_all = r.u();
  // Room for the paths and rows of this file and as many more for each file still to come, at
  // once, so that the histogram's B rows of cells and of row sums are not regrown (each regrowth
  // moves every row, into fresh pages).
  if (!r.failed()) {
    const auto room = [&](std::uint64_t n) {
      return static_cast<std::size_t>(std::min<std::uint64_t>(std::min(n, kMaxReservedPaths) * std::max<std::size_t>(files, 1), kMaxReservedInAll));
    };
    h->reserve_paths(static_cast<std::size_t>(h->num_paths()) + room(paths));
    h->reserve_rows(static_cast<std::size_t>(h->num_rows()) + room(rows_in_all));
  }
  // The held batches, each given by its gap after the previous one, so that they come in
  // order; one at or past B makes the body malformed. `next` is one past the previous batch.
  const auto next_batch = [&](std::uint64_t& next) {
    const std::uint64_t gap = r.u();
    if (gap >= static_cast<std::uint64_t>(B) - next) return false;
    next += gap + 1;
    return true;
  };
  for (std::uint64_t i = 0; i < paths && !r.failed(); ++i) {
    const std::string_view path = r.text();
    if (r.failed()) break;
    const Histogram::PathId id = h->intern(path);
    const std::uint64_t cells = r.u();
    if (cells > static_cast<std::uint64_t>(B)) return "path \"" + std::string(path) + "\" holds more cells than batches";
    std::uint64_t b1 = 0;  // one past the previous held batch
    for (std::uint64_t k = 0; k < cells && !r.failed(); ++k) {
      if (!next_batch(b1)) return "a cell of path \"" + std::string(path) + "\" is past the last batch";
      const std::uint64_t n = r.u();
      h->add_cell(id, static_cast<int>(b1 - 1), r.rgb(), n);
    }
    const std::uint64_t rows = r.u();
    for (std::uint64_t k = 0; k < rows && !r.failed(); ++k) {
      const std::uint64_t code = r.u(), n = r.u(), sums = r.u();
      if (sums > static_cast<std::uint64_t>(B)) return "a technique of path \"" + std::string(path) + "\" holds more sums than batches";
      std::fill(technique_sums.begin(), technique_sums.end(), ExactSum{0});
      b1 = 0;
      for (std::uint64_t j = 0; j < sums && !r.failed(); ++j) {
        if (!next_batch(b1)) return "a technique sum of path \"" + std::string(path) + "\" is past the last batch";
        technique_sums[static_cast<std::size_t>(b1 - 1)] = r.x();
      }
      if (r.failed()) break;
      if (code >= (std::uint64_t{1} << 29) || Technique::from_code(static_cast<int>(code)).strategy >= S)
        return "a technique of path \"" + std::string(path) + "\" names no strategy of the render";
      h->add_technique(id, static_cast<int>(code), n, technique_sums.data());
    }
  }
  if (r.failed()) return "the histogram ends early";
  if (!r.at_end()) return "bytes after the histogram";
  return std::nullopt;
}

// An image frame, added to `images`: its tiles' keys (plane × tiles + tile) are increasing and in
// [first, end), which the index keeps apart from every other frame's, so that frames add at once.
BadBody add_image_frame(Reader& r, ClassImages* images, std::uint64_t first, std::uint64_t end) {
  const std::uint64_t planes = r.u(), tiles = r.u(), stored = r.u();
  if (r.failed()) return "an image frame ends early";
  if (planes != images->num_planes() || tiles != images->num_tiles())
    return "its images have " + std::to_string(planes) + " planes of " + std::to_string(tiles) + " tiles; the merge's have " +
           std::to_string(images->num_planes()) + " of " + std::to_string(images->num_tiles());
  // The tiles' keys and masks (each key checked before the next is read: at most end - first).
  std::vector<std::uint64_t> keys, masks;
  std::size_t values = 0;  // channel sums in all: three per pixel of a mask
  for (std::uint64_t i = 0, next = first; i < stored; ++i) {
    const std::uint64_t p = r.u(), t = r.u();
    if (r.failed() || p >= planes || t >= tiles || p * tiles + t < next || p * tiles + t >= end)
      return "a stored tile is out of its frame's range or order";
    next = p * tiles + t + 1;
    keys.push_back(p * tiles + t);
    masks.push_back(r.raw64());
    values += 3 * static_cast<std::size_t>(std::popcount(masks.back()));
  }
  if (r.failed()) return "an image frame ends early";
  // The low words, a byte plane at a time, a piece of the window at a time.
  std::vector<std::uint64_t> low(values, 0);
  for (int j = 0; j < 8; ++j)
    for (std::size_t i = 0; i < values;) {
      const std::string_view piece = r.bytes(std::min(values - i, Reader::kMaxBytes));
      if (r.failed()) return "an image frame ends early";
      for (const char c : piece) low[i++] |= static_cast<std::uint64_t>(static_cast<unsigned char>(c)) << (8 * j);
    }
  std::array<std::uint64_t, ClassImages::kTileWords> words;
  std::size_t v = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    for (std::size_t k = 0; k < kTilePixels; ++k) {
      std::uint64_t* px = words.data() + 6 * k;
      if (masks[i] >> k & 1) {
        for (std::size_t c = 0; c < 6; c += 2, ++v) {
          px[c] = low[v];
          px[c + 1] = static_cast<std::uint64_t>(r.signed64());
        }
      } else {
        std::fill(px, px + 6, std::uint64_t{0});
      }
    }
    if (r.failed()) return "an image frame ends early";
    images->add_tile(static_cast<std::size_t>(keys[i] / tiles), static_cast<std::size_t>(keys[i] % tiles), words.data());
  }
  if (!r.at_end()) return "bytes after an image frame's tiles";
  return std::nullopt;
}

// The connector frame, added to `connectors`.
BadBody add_connector_counts(Reader& r, std::vector<ConnectorStats>* connectors) {
  const std::uint64_t n = r.u();
  if (r.failed()) return "the connector section ends early";
  if (n != connectors->size())
    return "it counts " + std::to_string(n) + " connector strategies; its header names " + std::to_string(connectors->size());
  std::array<std::uint64_t, ConnectorStats::kCounts> counts;
  for (ConnectorStats& c : *connectors) {
    for (std::uint64_t& k : counts) k = r.u();
    if (r.failed()) return "the connector section ends early";
    const auto to = ConnectorStats::counts_of(c);
    for (std::size_t i = 0; i < counts.size(); ++i) *to[i] += counts[i];
  }
  if (!r.at_end()) return "bytes after the connector section";
  return std::nullopt;
}

}  // namespace

Result<bool> add_shard_sums(const ShardFile& f, RenderSums* state, std::size_t files) {
  const RenderIdentity& id = f.header.identity;
  Histogram* h = &state->histogram;
  ClassImages* images = &state->images;
  if (h->num_batches() != id.batches || h->layout().replicates() != id.replicates || h->layout().strategies != id.strategies)
    return file_error(f.path, "the shard's histogram layout (batches, replicates, strategies) is not the merge's");
  const auto same_connectors = [&] {
    if (state->connectors.size() != id.connectors.size()) return false;
    for (std::size_t i = 0; i < id.connectors.size(); ++i)
      if (state->connectors[i].strategy != id.connectors[i].strategy || state->connectors[i].connector != id.connectors[i].connector)
        return false;
    return true;
  };
  if (!same_connectors()) return file_error(f.path, "the shard's connector strategies are not the merge's");
  const auto bad = [&](const std::string& what) { return file_error(f.path, "malformed shard body: " + what); };
  // --- the index: every frame's place, and the image frames' key ranges ---
  const std::size_t at = f.body_offset, size = f.body_size;
  if (size < 4) return bad("no index");
  const std::uint64_t frames = get_le<std::uint32_t>(f.bytes, at);
  if (body_index_bytes(frames) > size) return bad("its index is longer than the body");
  const std::uint64_t key_end = static_cast<std::uint64_t>(images->num_planes()) * images->num_tiles();
  std::vector<std::uint64_t> starts, keys;  // each frame's offset in the file; each image frame's first key
  std::uint64_t offset = at + body_index_bytes(frames);
  for (std::uint64_t i = 0; i < frames + 2; ++i) {
    starts.push_back(offset);
    const std::uint64_t n = get_le<std::uint64_t>(f.bytes, at + 4 + 8 * i);
    if (n > at + size - offset) return bad("its frames are longer than the body");
    offset += n;
  }
  if (offset != at + size) return bad("bytes after its last frame");
  starts.push_back(offset);
  for (std::uint64_t i = 0; i < frames; ++i) {
    keys.push_back(get_le<std::uint64_t>(f.bytes, at + 4 + 8 * (frames + 2) + 8 * i));
    if (keys.back() >= key_end || (i > 0 && keys.back() <= keys[i - 1])) return bad("its image frames' keys are not increasing");
  }
  keys.push_back(key_end);
  const auto frame = [&](std::size_t i) { return Reader(f.bytes.data() + starts[i], starts[i + 1] - starts[i]); };
  // --- the histogram, and the image frames at once (on other threads: disjoint tiles) ---
  BadBody histogram_error;
  std::vector<BadBody> image_errors(frames);
  tbb::task_group group;
  group.run([&] {
    Reader r = frame(0);
    histogram_error = add_histogram(r, h, files);
  });
  tbb::parallel_for(std::size_t{0}, static_cast<std::size_t>(frames), [&](std::size_t i) {
    Reader r = frame(1 + i);
    image_errors[i] = add_image_frame(r, images, keys[i], keys[i + 1]);
  });
  group.wait();
  if (histogram_error) return bad(*histogram_error);
  for (const BadBody& e : image_errors)
    if (e) return bad(*e);
  Reader r = frame(frames + 1);
  if (BadBody e = add_connector_counts(r, &state->connectors)) return bad(*e);
  return true;
}

}  // namespace pathex
