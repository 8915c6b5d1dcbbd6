// Pass sets, their deal (schedule/pass_deal.h) and the shard file format (output/shard.h): exact round
// trips of the sums, and every damaged file refused with its own message.
#include <gtest/gtest.h>
#include <zlib.h>

#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "schedule/pass_deal.h"
#include "schedule/pass_set.h"
#include "output/shard.h"

namespace pathex {
namespace {

TEST(PassSet, PartsAreDisjointCoverTheSetAndDifferByAtMostOne) {
  PassSet set = PassSet::range(0, 10);
  set.add(20, 27);  // 17 passes
  for (std::uint64_t n : {1u, 2u, 3u, 7u, 17u, 40u}) {
    PassSet all;
    std::uint64_t smallest = ~0ull, largest = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
      const PassSet part = set.part(i, n);
      EXPECT_TRUE(all.intersect(part).empty()) << n;
      all.add(part);
      smallest = std::min(smallest, part.count());
      largest = std::max(largest, part.count());
    }
    EXPECT_EQ(all, set) << n;
    EXPECT_LE(largest - smallest, 1u) << n;
  }
  EXPECT_EQ(set.part(1, 3).to_string(), "5-9, 20");
  EXPECT_EQ(PassSet::range(0, 8).part(1, 2).to_string(), "4-7");
}

// A deal hands out the set's chunks in order (PassSet::chunks), each once, then none; `dealt`
// counts the passes handed out.
TEST(ChunkDeal, DealsTheChunksInOrderThenNone) {
  PassSet set = PassSet::range(0, 10);
  set.add(20, 27);
  ChunkDeal deal(set, 4);
  EXPECT_EQ(deal.total(), 17u);
  EXPECT_EQ(deal.dealt(), 0u);
  std::vector<PassRange> got;
  std::vector<std::uint64_t> dealt;
  while (const std::optional<PassRange> c = deal.next()) got.push_back(*c), dealt.push_back(deal.dealt());
  EXPECT_EQ(got, set.chunks(4));
  EXPECT_EQ(dealt, (std::vector<std::uint64_t>{4, 8, 10, 14, 17}));
  EXPECT_FALSE(deal.next());
  EXPECT_EQ(deal.dealt(), 17u);
  ChunkDeal none(PassSet(), 4);
  EXPECT_FALSE(none.next());
  EXPECT_EQ(none.total(), 0u);
}

// Threads taking from one deal (MPI rank 0's render and its thread serving the other ranks)
// together get every pass once.
TEST(ChunkDeal, ThreadsTakingTogetherGetEveryPassOnce) {
  ChunkDeal deal(PassSet::range(0, 3000), 3);
  std::vector<PassSet> taken(4);
  {
    std::vector<std::jthread> takers;
    for (PassSet& mine : taken)
      takers.emplace_back([&deal, &mine] {
        while (const std::optional<PassRange> c = deal.next()) mine.add(c->first, c->last);
      });
  }
  PassSet all;
  for (const PassSet& mine : taken) {
    EXPECT_TRUE(all.intersect(mine).empty());
    all.add(mine);
  }
  EXPECT_EQ(all, PassSet::range(0, 3000));
}

// Two takers of a 32-batch render taking turns: each keeps to its half of the batches (chunks of 4
// passes: taker 0 the chunks starting at passes 0, 4, 8, 12 mod 32, round-robin), and together
// they get every pass once.
TEST(LaneDeal, TakersKeepToTheirBatches) {
  LaneDeal deal(PassSet::range(0, 128), 4, 32, 2);
  EXPECT_EQ(deal.total(), 128u);
  std::vector<PassRange> zero, one;
  for (bool done = false; !done;) {
    const std::optional<PassRange> a = deal.next(0), b = deal.next(1);
    if (a) zero.push_back(*a);
    if (b) one.push_back(*b);
    done = !a && !b;
  }
  EXPECT_EQ(zero, (std::vector<PassRange>{{0, 4}, {4, 8}, {8, 12}, {12, 16}, {32, 36}, {36, 40}, {40, 44}, {44, 48},
                                          {64, 68}, {68, 72}, {72, 76}, {76, 80}, {96, 100}, {100, 104}, {104, 108}, {108, 112}}));
  for (const PassRange& c : one) EXPECT_GE(c.first % 32, 16u) << c.first;
  EXPECT_EQ(one.size(), 16u);
  EXPECT_EQ(deal.dealt(), 128u);
  EXPECT_FALSE(deal.next(0));
}

// A taker whose lanes are done joins the lane with the most chunks left; a resumed render's
// scattered passes (ranges not aligned to chunks or batches, chunks cut short at a range's end)
// are each dealt once, whoever takes them.
TEST(LaneDeal, FasterTakerJoinsTheLaneWithMostLeftAndEveryPassIsDealtOnce) {
  LaneDeal deal(PassSet::range(0, 64), 4, 32, 2);
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(deal.next(0));  // taker 0's lanes: 8 chunks
  EXPECT_EQ(deal.next(0), (PassRange{16, 20}));            // then taker 1's first lane (the first of most left)
  EXPECT_EQ(deal.next(1), (PassRange{48, 52}));            // shared: taker 1 goes on in that lane
  EXPECT_EQ(deal.next(0), (PassRange{20, 24}));            // it is done: taker 0 joins the next

  PassSet scattered = PassSet::range(3, 50);
  scattered.add(61, 62);
  scattered.add(70, 201);
  for (const int takers : {1, 2, 3, 40}) {
    for (const std::uint64_t batches : {1u, 5u, 32u}) {
      LaneDeal d(scattered, 4, batches, takers);
      EXPECT_EQ(d.total(), scattered.count());
      PassSet all;
      std::size_t chunks = 0;
      for (int t = 0;; t = (t + 1) % takers) {  // taker 0 takes three times as often as the others
        const std::optional<PassRange> c = d.next(t == 0 ? 0 : t), c0 = d.next(0), c00 = d.next(0);
        bool any = false;
        for (const std::optional<PassRange>& x : {c, c0, c00})
          if (x) {
            EXPECT_TRUE(all.intersect(PassSet::range(x->first, x->last)).empty());
            EXPECT_LE(x->last - x->first, 4u);
            all.add(x->first, x->last), ++chunks, any = true;
          }
        if (!any) break;
      }
      EXPECT_EQ(all, scattered) << takers << " takers, " << batches << " batches";
      EXPECT_EQ(chunks, scattered.chunks(4).size());
      EXPECT_EQ(d.dealt(), scattered.count());
    }
  }
}

TEST(PassSet, SetOperationsAndText) {
  PassSet a = PassSet::range(0, 16);
  PassSet b = PassSet::range(4, 8);
  b.add(12, 13);
  EXPECT_EQ(a.minus(b).to_string(), "0-3, 8-11, 13-15");
  EXPECT_EQ(a.intersect(b), b);
  EXPECT_EQ(b.count(), 5u);
  b.add(8, 12);  // joins the neighbours
  EXPECT_EQ(b.ranges().size(), 1u);
  EXPECT_EQ(PassSet().to_string(), "none");
  EXPECT_EQ(PassSet::range(0, 10).chunks(4).size(), 3u);
  EXPECT_EQ(PassSet::range(0, 10).chunks(4).back(), (PassRange{8, 10}));
}

struct Fixture {
  Fixture() {
    header.identity.pathex = "test";
    header.identity.strategies = {"a", "b"};
    header.identity.connectors = {{"b", "mirror"}};
    header.identity.batches = 3;
    header.identity.replicates = 3;  // one group: the histogram below is HistogramLayout{3, …}
    header.spp = 8;
    header.share = PassSet::range(0, 8);
    header.passes = PassSet::range(0, 4);
    Histogram& h = sums.histogram;
    const Histogram::PathId p = h.intern("LDDDSE"), q = h.intern("LSDDSE");
    h.add(p, 0, Technique{0, 2, 2}.code(), {1.0, 2.0, 3.0});
    h.add(p, 1, Technique{1, 1, 2, true}.code(), {4.0, 2.0, 3.0});
    h.add(q, 2, Technique{1, 3, 1}.code(), {-0.5, 1e10, 1e-19});  // negative, large and tiny sums
    h.add_samples(0, 5);
    h.add_nonfinite(2);
    sums.images.add(3, 9, 0, *to_exact({0.25, 0.5, -1.0}));
    ConnectorStats mirror{"b", "mirror"};
    const auto counts = ConnectorStats::counts_of(mirror);
    for (std::size_t i = 0; i < counts.size(); ++i) *counts[i] = 3 * i + 1;
    mirror.iterations = std::uint64_t{1} << 60;  // a count needs all its bits
    sums.connectors = {mirror};
  }
  // Empty sums laid out as these.
  RenderSums empty() const {
    std::vector<ConnectorStats> c;
    for (const ConnectorStrategy& n : header.identity.connectors) c.push_back({n.strategy, n.connector});
    return {Histogram(sums.histogram.layout()), ClassImages(10, 10, nullptr, {}), c};
  }
  ShardHeader header;
  RenderSums sums{Histogram(HistogramLayout{3, {"a", "b"}}), ClassImages(10, 10, nullptr, {}), {}};
  const Histogram& histogram = sums.histogram;
  const ClassImages& images = sums.images;
};

TEST(ShardFile, RoundTripsTheExactSums) {
  Fixture f;
  const std::string bytes = encode_shard(f.header, f.sums);
  Result<ShardFile> file = parse_shard(bytes, "x.shard");
  ASSERT_TRUE(file) << file.error().render();
  EXPECT_EQ(file->header.passes, f.header.passes);
  EXPECT_EQ(file->header.identity, f.header.identity);
  RenderSums sums = f.empty();
  ASSERT_TRUE(add_shard_sums(*file, &sums));
  // Twice: the sums add, the connector counts too.
  ASSERT_TRUE(add_shard_sums(*file, &sums));
  const Histogram& h = sums.histogram;
  const ClassImages& im = sums.images;
  ASSERT_EQ(h.num_paths(), 2);
  for (int p = 0; p < 2; ++p) {
    const Histogram::PathId id = *h.find(f.histogram.path(p));
    for (int b = 0; b < 3; ++b) {
      for (int c = 0; c < 3; ++c) EXPECT_EQ(h.cell(id, b).sum[c], 2 * f.histogram.cell(p, b).sum[c]);
      EXPECT_EQ(h.cell(id, b).contributions, 2 * f.histogram.cell(p, b).contributions);
    }
    const std::vector<int> got = h.sorted_rows(id), want = f.histogram.sorted_rows(p);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(h.row(got[i]).technique, f.histogram.row(want[i]).technique);
      EXPECT_EQ(h.row(got[i]).contributions, 2 * f.histogram.row(want[i]).contributions);
      for (int b = 0; b < 3; ++b) EXPECT_EQ(h.row_sum(got[i], b), 2 * f.histogram.row_sum(want[i], b));
    }
  }
  EXPECT_EQ(h.batch_samples(0), 10u);
  EXPECT_EQ(h.nonfinite(), 4u);
  const ExactRgb one = f.images.sum(0, 3, 9);
  EXPECT_EQ(im.sum(0, 3, 9), (ExactRgb{2 * one[0], 2 * one[1], 2 * one[2]}));
  EXPECT_EQ(im.sum(0, 4, 9), ExactRgb{});
  ASSERT_EQ(sums.connectors.size(), 1u);
  EXPECT_EQ(sums.connectors[0].strategy, "b");
  EXPECT_EQ(sums.connectors[0].connector, "mirror");
  const auto got = ConnectorStats::counts_of(std::as_const(sums.connectors[0]));
  const auto want = ConnectorStats::counts_of(f.sums.connectors[0]);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(*got[i], 2 * *want[i]) << i;
  EXPECT_EQ(sums.connectors[0].iterations, std::uint64_t{1} << 61);
}

// A larger image is stored in several frames (512 tiles each), decoded at once: every tile's sums
// come back, and frames whose key ranges are not increasing (so that two could add to one tile)
// are refused.
TEST(ShardFile, ImageFramesRoundTripAndMustNotOverlap) {
  Fixture f;
  const int w = 200, h = 200;  // 625 tiles of 8 x 8: two frames
  RenderSums sums{Histogram(f.histogram.layout()), ClassImages(w, h, nullptr, {}), {{"b", "mirror"}}};
  for (int y = 0; y < h; y += 3)
    for (int x = 0; x < w; x += 5) sums.images.add(x, y, 0, *to_exact({0.5 + x, -0.25 * y, 1e-9}));
  const std::string bytes = encode_shard(f.header, sums);
  Result<ShardFile> file = parse_shard(bytes, "x.shard");
  ASSERT_TRUE(file) << file.error().render();
  const std::size_t body = file->body_offset;
  ASSERT_EQ(static_cast<unsigned char>(bytes[body]), 2u);  // K, little-endian
  RenderSums into{Histogram(f.histogram.layout()), ClassImages(w, h, nullptr, {}), {{"b", "mirror"}}};
  ASSERT_TRUE(add_shard_sums(*file, &into)) << add_shard_sums(*file, &into).error().render();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) ASSERT_EQ(into.images.sum(0, x, y), sums.images.sum(0, x, y)) << x << " " << y;
  // The second frame's first key set to the first's (the CRC made right again).
  std::string bad = bytes;
  const std::size_t keys = body + 4 + 8 * 4;
  bad.replace(keys + 8, 8, bad.substr(keys, 8));
  const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(bad.data()), static_cast<uInt>(bad.size() - 4)));
  for (std::size_t i = 0; i < 4; ++i) bad[bad.size() - 4 + i] = static_cast<char>((crc >> (8 * i)) & 0xff);
  Result<ShardFile> overlapping = parse_shard(bad, "y.shard");
  ASSERT_TRUE(overlapping) << overlapping.error().render();
  RenderSums again{Histogram(f.histogram.layout()), ClassImages(w, h, nullptr, {}), {{"b", "mirror"}}};
  Result<bool> r = add_shard_sums(*overlapping, &again);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().render(), "y.shard: malformed shard body: its image frames' keys are not increasing");
}

// The connector statistics are laid out by the header's "connectors": sums laid out for others,
// or a body that counts other connectors than its header names, are refused.
TEST(ShardFile, ConnectorStatisticsOfAnotherLayoutAreRefused) {
  Fixture f;
  Result<ShardFile> file = parse_shard(encode_shard(f.header, f.sums), "x.shard");
  ASSERT_TRUE(file) << file.error().render();
  RenderSums other = f.empty();
  other.connectors[0].connector = "manifold";
  Result<bool> r = add_shard_sums(*file, &other);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().render(), "x.shard: the shard's connector strategies are not the merge's");
  other = f.empty();
  other.connectors.clear();
  r = add_shard_sums(*file, &other);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().render(), "x.shard: the shard's connector strategies are not the merge's");
  // A (hand-made) file whose body counts no connector where its header names one.
  RenderSums none = f.empty();
  none.connectors.clear();
  Result<ShardFile> bad = parse_shard(encode_shard(f.header, none), "y.shard");
  ASSERT_TRUE(bad) << bad.error().render();
  RenderSums into = f.empty();
  r = add_shard_sums(*bad, &into);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().render(), "y.shard: malformed shard body: it counts 0 connector strategies; its header names 1");
}

TEST(ShardFile, EveryTruncationAndEveryFlippedByteIsRefused) {
  Fixture f;
  const std::string bytes = encode_shard(f.header, f.sums);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    Result<ShardFile> file = parse_shard(bytes.substr(0, n), "x.shard");
    ASSERT_FALSE(file) << n;
    EXPECT_EQ(file.error().where, "x.shard");
  }
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ 0x01);
    Result<ShardFile> file = parse_shard(bad, "x.shard");
    ASSERT_FALSE(file) << i;
  }
  const auto message = [](const std::string& b) {
    Result<ShardFile> file = parse_shard(b, "x");
    return file ? std::string("(read)") : file.error().message;
  };
  EXPECT_EQ(message("hello, world, not a shard"), "not a pathex shard file (it does not begin with \"PXSHARD\")");
  std::string v2 = bytes;
  v2[8] = 2;  // version 2 had per-strategy sums, not per-technique rows
  EXPECT_EQ(message(v2), "shard file format version 2; this pathex reads version 6");
  EXPECT_EQ(message(bytes + "x"), "corrupted shard file: 1 bytes after its checksum");
}

// The file's JSON header.
nlohmann::ordered_json header_of(const std::string& bytes) {
  std::uint32_t h = 0;
  for (std::size_t i = 0; i < 4; ++i) h |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[12 + i])) << (8 * i);
  return nlohmann::ordered_json::parse(bytes.substr(16, h));
}

// The file with its JSON header replaced by `head` (lengths and checksum made right again), as a
// newer or hand-edited writer would make it.
std::string with_header(const std::string& bytes, const std::string& head) {
  std::uint32_t h = 0;
  for (std::size_t i = 0; i < 4; ++i) h |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[12 + i])) << (8 * i);
  std::string out = bytes.substr(0, 12);
  for (std::size_t i = 0; i < 4; ++i) out.push_back(static_cast<char>((head.size() >> (8 * i)) & 0xff));
  out += head + bytes.substr(16 + h, bytes.size() - 16 - h - 4);
  const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(out.data()), static_cast<uInt>(out.size())));
  for (std::size_t i = 0; i < 4; ++i) out.push_back(static_cast<char>((crc >> (8 * i)) & 0xff));
  return out;
}

// The identity a shard with f's header reads back as, and as it reads once `option` is taken out
// of its header's "options" (a file written before that option existed).
std::pair<RenderIdentity, RenderIdentity> read_back_with_and_without(const Fixture& f, const std::string& option) {
  const std::string bytes = encode_shard(f.header, f.sums);
  Result<ShardFile> file = parse_shard(bytes, "x.shard");
  EXPECT_TRUE(file) << (file ? "" : file.error().render());
  nlohmann::ordered_json head = header_of(bytes);
  EXPECT_TRUE(head["options"].contains(option)) << option;
  head["options"].erase(option);
  Result<ShardFile> old = parse_shard(with_header(bytes, head.dump()), "x.shard");
  EXPECT_TRUE(old) << (old ? "" : old.error().render());
  return {file ? file->header.identity : RenderIdentity{}, old ? old->header.identity : RenderIdentity{}};
}

// The header goes through the one JSON reader: a wrong value is refused at its JSON pointer.
// Issue 39: the light subpaths' roulette threshold round-trips, and a shard written before it
// existed (no rr_light_threshold) reads as one threshold for both subpaths, as it was rendered.
TEST(ShardFile, LightRouletteThresholdRoundTripsAndDefaultsToTheEyeThreshold) {
  Fixture f;
  f.header.identity.rr_threshold = 0.25;
  f.header.identity.rr_light_threshold = 0.75;
  const auto [now, before] = read_back_with_and_without(f, "rr_light_threshold");
  EXPECT_EQ(now.rr_threshold, 0.25);
  EXPECT_EQ(now.rr_light_threshold, 0.75);
  EXPECT_EQ(before.rr_light_threshold, 0.25);
}

// Issue 39: the join roulette's threshold round-trips, and a shard written before it (no
// rr_join_threshold) reads as 0, every eye vertex making all its joins, as it was rendered.
TEST(ShardFile, JoinRouletteThresholdRoundTripsAndDefaultsToNone) {
  Fixture f;
  f.header.identity.rr_join_threshold = 2.5;
  const auto [now, before] = read_back_with_and_without(f, "rr_join_threshold");
  EXPECT_EQ(now.rr_join_threshold, 2.5);
  EXPECT_EQ(before.rr_join_threshold, 0.0);
  // `auto` (the default: the pilot's choice), the eye's as the joins', is written as the word and
  // read back as it.
  f.header.identity.rr_join_threshold = kJoinThresholdAuto;
  f.header.identity.rr_threshold = kEyeThresholdAuto;
  const std::string bytes = encode_shard(f.header, f.sums);
  EXPECT_EQ(header_of(bytes)["options"]["rr_join_threshold"], "auto");
  EXPECT_EQ(header_of(bytes)["options"]["rr_threshold"], "auto");
  Result<ShardFile> back = parse_shard(bytes, "x.shard");
  ASSERT_TRUE(back) << back.error().render();
  EXPECT_EQ(back->header.identity.rr_join_threshold, kJoinThresholdAuto);
  EXPECT_EQ(back->header.identity.rr_threshold, kEyeThresholdAuto);
  // Any other word is refused at its pointer.
  for (const std::string name : {"rr_join_threshold", "rr_threshold"}) {
    nlohmann::ordered_json head = header_of(bytes);
    head["options"][name] = "fast";
    Result<ShardFile> bad = parse_shard(with_header(bytes, head.dump()), "x.shard");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().render(), "x.shard:/options/" + name + ": expected auto or a number");
  }
}

// Issue 39: the runs per camera ray (--splits) round-trip, and a shard written before them (no
// "splits") reads as unsplit, as it was rendered.
TEST(ShardFile, SplitsRoundTripAndDefaultToOne) {
  Fixture f;
  f.header.identity.splits = 8;
  const auto [now, before] = read_back_with_and_without(f, "splits");
  EXPECT_EQ(now.splits, 8);
  EXPECT_EQ(before.splits, 1);
}

// Issue 39: the replicates per pixel round-trip; a shard written before them (no "replicates")
// reads as one group of `batches` replicates, as it was rendered; a count that does not divide
// the batches is refused at its pointer.
TEST(ShardFile, ReplicatesRoundTripAndDefaultToTheBatchCount) {
  Fixture f;
  const std::string bytes = encode_shard(f.header, f.sums);
  nlohmann::ordered_json head = header_of(bytes);
  EXPECT_EQ(head["options"]["replicates"], 3);
  head["options"]["batches"] = 4;
  head["options"]["replicates"] = 2;
  Result<ShardFile> grouped = parse_shard(with_header(bytes, head.dump()), "x.shard");
  ASSERT_TRUE(grouped) << grouped.error().render();
  EXPECT_EQ(grouped->header.identity.replicates, 2);
  head["options"]["replicates"] = 3;
  Result<ShardFile> bad = parse_shard(with_header(bytes, head.dump()), "x.shard");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().render(), "x.shard:/options/replicates: expected a divisor of the batch count 4");
  head["options"].erase("replicates");
  Result<ShardFile> old = parse_shard(with_header(bytes, head.dump()), "x.shard");
  ASSERT_TRUE(old) << old.error().render();
  EXPECT_EQ(old->header.identity.replicates, 4);
}

TEST(ShardFile, HeaderErrorsNameTheFileAndThePointer) {
  Fixture f;
  const std::string bytes = encode_shard(f.header, f.sums);
  std::uint32_t h = 0;
  for (std::size_t i = 0; i < 4; ++i) h |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[12 + i])) << (8 * i);
  const nlohmann::ordered_json head = nlohmann::ordered_json::parse(bytes.substr(16, h));
  const auto refusal = [&](const nlohmann::ordered_json& j) {
    Result<ShardFile> file = parse_shard(with_header(bytes, j.dump()), "x.shard");
    return file ? std::string("(read)") : file.error().render();
  };
  EXPECT_EQ(refusal(head), "(read)");  // the rewriting itself is sound
  nlohmann::ordered_json j = head;
  j["options"]["images"] = "yes";
  EXPECT_EQ(refusal(j), "x.shard:/options/images: expected true or false, found a string");
  j = head;
  j["seed"] = -1;
  EXPECT_EQ(refusal(j), "x.shard:/seed: expected an integer in [0, 18446744073709551615], found -1");
  j = head;
  j["colour"] = 1;
  EXPECT_EQ(refusal(j).rfind("x.shard:/colour: unknown key 'colour', expected one of pathex, scene,", 0), 0u) << refusal(j);
  j = head;
  j.erase("passes");
  EXPECT_EQ(refusal(j), "x.shard:/passes: missing passes");
  j = head;
  j["passes"] = {{4, 2}};
  EXPECT_EQ(refusal(j), "x.shard:/passes/0: expected [first, last) with first < last, after the previous range");
  Result<ShardFile> bad_json = parse_shard(with_header(bytes, "{\"pathex\": "), "x.shard");
  ASSERT_FALSE(bad_json);
  EXPECT_EQ(bad_json.error().message.rfind("not valid JSON: ", 0), 0u) << bad_json.error().message;
}

}  // namespace
}  // namespace pathex
