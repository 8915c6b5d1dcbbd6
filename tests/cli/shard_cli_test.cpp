// Sharded, merged, resumed and MPI renders end to end (issue 16): the outputs are the bytes of one
// uninterrupted process, and every refusal of `pathex merge` is one exact message with exit 2.
#include <gtest/gtest.h>
#include <zlib.h>

#include "support/cli_run.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;
using pathex::test::read_file;
using pathex::test::run_pathex;

std::string dir(const std::string& name) {
  const fs::path d = pathex::test::scratch_dir() / name;
  fs::remove_all(d);
  return d.string();
}

// Every output a user compares: histogram.json, classes.exr and the PNG previews, byte for byte.
void expect_same_outputs(const std::string& expected, const std::string& actual, const std::string& what) {
  std::vector<std::string> names = {"histogram.json"};
  for (const auto& e : fs::directory_iterator(expected))
    if (e.path().extension() == ".png" || e.path().extension() == ".exr") names.push_back(e.path().filename().string());
  ASSERT_GE(names.size(), 3u) << expected;
  for (const std::string& n : names) {
    ASSERT_TRUE(fs::exists(actual + "/" + n)) << what << ": no " << n;
    EXPECT_TRUE(read_file(expected + "/" + n) == read_file(actual + "/" + n)) << what << ": " << n << " differs";
  }
}

nlohmann::json histogram(const std::string& d) { return nlohmann::json::parse(read_file(d + "/histogram.json")); }

// --- 1, 2, 3 and 7 shards of every sample scene with two profiles ---

struct Case {
  std::string scene;
  std::string renderer;
  bool connector = false;  // the profile runs a connector on this scene: its statistics merge too
  std::string options = "";  // more options of the render
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.scene << " " << c.renderer << c.options; }

// A render's connector statistics, which must be nonzero for their merge to test anything.
void expect_connector_work(const std::string& d, const std::string& what) {
  const nlohmann::json h = histogram(d);
  ASSERT_TRUE(h.contains("connectors")) << what;
  ASSERT_FALSE(h["connectors"].empty()) << what;
  for (const auto& c : h["connectors"]) {
    EXPECT_GT(c["attempts"].get<std::uint64_t>(), 0u) << what << " " << c.dump();
    EXPECT_GT(c["successes"].get<std::uint64_t>(), 0u) << what << " " << c.dump();
  }
}

// The connector table of `pathex trace`'s terminal output (from its "connectors" line to the
// blank line after it): the render's statistics, whatever parts it was rendered in.
std::string connector_table(const std::string& out) {
  const std::size_t at = out.find("\nconnectors ");
  if (at == std::string::npos) return "(no connector table)";
  return out.substr(at, out.find("\n\n", at + 1) - at);
}

class ShardsMerge : public testing::TestWithParam<Case> {};

TEST_P(ShardsMerge, IntoTheBytesOfOneRender) {
  const Case& c = GetParam();
  const std::string args = "trace samples/scenes/" + c.scene + ".json --renderer " + c.renderer + " --spp 7 --seed 3 --quiet" + c.options;
  const std::string single = dir("single");
  const CliRun s = run_pathex(args + " --out " + single);
  ASSERT_EQ(s.code, 0) << s.err;
  if (c.connector) expect_connector_work(single, c.scene + " " + c.renderer);
  for (int n : {1, 2, 3, 7}) {
    std::string shards;
    for (int i = 0; i < n; ++i) {
      const std::string d = dir("shard-" + std::to_string(i));
      const CliRun r = run_pathex(args + " --threads " + std::to_string(1 + i % 2) + " --shard " + std::to_string(i) + "/" +
                                  std::to_string(n) + " --out " + d);
      ASSERT_EQ(r.code, 0) << r.err;
      // A shard's own histogram is an estimate of the image from its passes alone.
      EXPECT_EQ(histogram(d)["spp"], (7 * (i + 1)) / n - (7 * i) / n);
      EXPECT_EQ(histogram(d)["complete"], true);
      shards += " " + d;
    }
    const std::string merged = dir("merged");
    const CliRun m = run_pathex("merge" + shards + " --quiet --out " + merged);
    ASSERT_EQ(m.code, 0) << m.err;
    expect_same_outputs(single, merged, c.scene + " " + c.renderer + ", " + std::to_string(n) + " shards");
  }
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const char* scene : {"closed-sphere-emitting", "closed-sphere-point", "cornell", "laser", "mirror-ortho", "point-glass",
                            "point-mirror-caustic", "point-plane", "spotmeter-caustic", "sun-window"})
    for (const char* renderer : {"bdpt", "pt-nee"}) out.push_back({scene, renderer});
  // Every connector, and a real integrator's profile that uses one (histogram.json "connectors").
  out.push_back({"point-mirror-caustic", "pt-nee+mirror", true});
  out.push_back({"mirror-ortho", "bdpt+ortho", true});
  out.push_back({"sun-window", "pt-nee+distant", true});
  out.push_back({"sun-window", "pbrt-v4-path", true});
  out.push_back({"point-glass", "pt-nee+manifold", true, " --resolution 24x24"});  // the manifold walks: 4x the cost per pixel
  // Issue 39: --splits auto's counts come from a pilot every shard runs alike (trace/accel/split_plan.h).
  out.push_back({"cornell", "pt-nee", false, " --splits auto"});
  out.push_back({"cornell", "bdpt", false, " --splits auto --resolution 48x48"});
  return out;
}

INSTANTIATE_TEST_SUITE_P(SampleScenes, ShardsMerge, testing::ValuesIn(cases()), [](const auto& test) {
  std::string name = test.param.scene + "_" + test.param.renderer;
  if (test.param.options.find("--splits auto") != std::string::npos) name += "_splits_auto";
  for (char& ch : name)
    if (ch == '-' || ch == '+') ch = '_';
  return name;
});

// A finished render keeps its sums (render.shard), so it can be extended: a 4-spp render and the
// second half of an 8-spp split merge into the 8-spp render (why complete runs write the file).
TEST(Merge, AFinishedRenderExtendedByTheNextPassesIsTheLongerRender) {
  const std::string args = "trace samples/scenes/cornell.json --resolution 24x16 --quiet";
  const std::string first = dir("first"), next = dir("next"), merged = dir("merged"), single = dir("single");
  ASSERT_EQ(run_pathex(args + " --spp 4 --out " + first).code, 0);
  ASSERT_EQ(run_pathex(args + " --spp 8 --shard 1/2 --out " + next).code, 0);
  const CliRun m = run_pathex("merge " + first + " " + next + " --quiet --out " + merged);
  ASSERT_EQ(m.code, 0) << m.err;
  ASSERT_EQ(run_pathex(args + " --spp 8 --out " + single).code, 0);
  expect_same_outputs(single, merged, "a 4-spp render extended to 8");
  EXPECT_EQ(histogram(merged)["spp"], 8);
}

// --- resume ---

TEST(Resume, AnInterruptedRenderResumedIsTheUninterruptedRender) {
  const std::string args = "trace samples/scenes/point-mirror-caustic.json --renderer bdpt --spp 16 --quiet";
  const std::string full = dir("full"), cut = dir("cut");
  ASSERT_EQ(run_pathex(args + " --out " + full).code, 0);
  // A time limit stops after the chunk in progress: one chunk of four passes.
  const CliRun r = run_pathex(args + " --time 0.000001 --out " + cut);
  ASSERT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(histogram(cut)["complete"], false);
  EXPECT_EQ(histogram(cut)["spp"], 4);
  EXPECT_NE(r.out.find("interrupted: 'pathex trace --resume " + cut + "' renders the missing passes 4-15\n"), std::string::npos)
      << r.out;
  // Resumed in steps (again cut short, then to the end), on another thread count.
  const CliRun again = run_pathex("trace --resume " + cut + " --time 0.000001 --threads 1 --quiet");
  ASSERT_EQ(again.code, 1) << again.err;
  EXPECT_EQ(histogram(cut)["spp"], 8);
  const CliRun rest = run_pathex("trace --resume " + cut + " --quiet");
  ASSERT_EQ(rest.code, 0) << rest.err;
  expect_same_outputs(full, cut, "resumed");
  EXPECT_EQ(histogram(cut)["complete"], true);
}

// The connector statistics (histogram.json and the terminal table) are the whole render's too.
TEST(Resume, ARenderWithAConnectorResumedIsTheUninterruptedRender) {
  const std::string args = "trace samples/scenes/point-glass.json --renderer pt-nee+manifold --spp 12 --resolution 24x24";
  const std::string full = dir("full"), cut = dir("cut");
  const CliRun whole = run_pathex(args + " --out " + full);
  ASSERT_EQ(whole.code, 0) << whole.err;
  expect_connector_work(full, "uninterrupted");
  ASSERT_EQ(run_pathex(args + " --quiet --time 0.000001 --out " + cut).code, 1);
  EXPECT_EQ(histogram(cut)["spp"], 4);
  const CliRun rest = run_pathex("trace --resume " + cut + " --threads 1");
  ASSERT_EQ(rest.code, 0) << rest.err;
  expect_same_outputs(full, cut, "resumed with a connector");
  EXPECT_EQ(connector_table(rest.out), connector_table(whole.out));
  EXPECT_NE(connector_table(whole.out).find("(manifold): no solution "), std::string::npos) << whole.out;
}

// Also: the resolution and the path table's bound come back from the folder.
TEST(Resume, AShardResumedIsTheWholeShard) {
  const std::string args = "trace samples/scenes/cornell.json --spp 16 --shard 1/2 --resolution 40x30 --max-paths 5 --quiet";
  const std::string whole = dir("whole"), cut = dir("cut");
  ASSERT_EQ(run_pathex(args + " --out " + whole).code, 0);
  ASSERT_EQ(run_pathex(args + " --time 0.000001 --out " + cut).code, 1);
  EXPECT_EQ(histogram(cut)["spp"], 4);
  ASSERT_EQ(run_pathex("trace --resume " + cut + " --quiet").code, 0);
  expect_same_outputs(whole, cut, "resumed shard");
  EXPECT_EQ(histogram(cut)["max_paths"], 5);
  EXPECT_EQ(histogram(cut)["paths"].back()["path"], "other");
}

TEST(Resume, TakesItsSettingsFromTheFolder) {
  const std::string d = dir("settings");
  ASSERT_EQ(run_pathex("trace --spp 4 --quiet --out " + d).code, 0);
  const CliRun r = run_pathex("trace --resume " + d + " --spp 8");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --resume takes the render's settings from " + d + "; --spp cannot be given with it\n");
}

// --- merge refusals: one exact message, exit 2 ---

struct Header {
  nlohmann::ordered_json json;
  std::string head, body;
};

// The documented layout (output/shard.h): magic, version, H, header, N, body, CRC-32.
Header read_header(const std::string& path) {
  const std::string b = read_file(path);
  std::uint32_t h = 0;
  for (int i = 0; i < 4; ++i) h |= static_cast<std::uint32_t>(static_cast<unsigned char>(b[12 + static_cast<std::size_t>(i)])) << (8 * i);
  Header out;
  out.head = b.substr(16, h);
  out.json = nlohmann::ordered_json::parse(out.head);
  out.body = b.substr(16 + h, b.size() - 16 - h - 4);  // N and the body
  return out;
}

// Rewrites a shard file with a changed header, with a correct checksum.
void write_header(const std::string& path, const nlohmann::ordered_json& j) {
  const Header old = read_header(path);
  const std::string head = j.dump(1) + "\n";
  std::string out = read_file(path).substr(0, 12);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((head.size() >> (8 * i)) & 0xff));
  out += head + old.body;
  const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(out.data()), static_cast<uInt>(out.size())));
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((crc >> (8 * i)) & 0xff));
  std::ofstream(path, std::ios::binary) << out;
}

class MergeRefuses : public testing::Test {
 protected:
  // Shards 0/2 and 1/2 of the Cornell box, 8 spp.
  void SetUp() override {
    a_ = dir("a");
    b_ = dir("b");
    ASSERT_EQ(run_pathex("trace --spp 8 --shard 0/2 --quiet --out " + a_).code, 0);
    ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --quiet --out " + b_).code, 0);
  }
  void expect_refusal(const std::string& args, const std::string& message) {
    const CliRun r = run_pathex("merge " + args + " --out " + dir("out"));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err, "pathex: error: " + message + "\n");
    EXPECT_FALSE(fs::exists(pathex::test::scratch_dir() / "out" / "histogram.json"));
  }
  std::string shard(const std::string& d) const { return d + "/render.shard"; }
  std::string a_, b_;
};

TEST_F(MergeRefuses, AnotherScene) {
  ASSERT_EQ(run_pathex("trace samples/scenes/point-plane.json --spp 8 --shard 1/2 --quiet --out " + b_).code, 0);
  const std::string ha = read_header(shard(a_)).json["scene"]["hash"], hb = read_header(shard(b_)).json["scene"]["hash"];
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) + " are not of one render: another scene (content hash " + hb +
                                    ", samples/scenes/point-plane.json against content hash " + ha + ", default (embedded cornell))");
}

TEST_F(MergeRefuses, NothingWhenTheSameSceneComesFromAnotherFile) {
  // The hash is of the scene's content: the embedded default and samples/scenes/cornell.json are
  // one scene (as the same file on two machines is); the merge names it as its first input does.
  ASSERT_EQ(run_pathex("trace samples/scenes/cornell.json --spp 8 --shard 1/2 --quiet --out " + b_).code, 0);
  EXPECT_EQ(read_header(shard(a_)).json["scene"]["hash"], read_header(shard(b_)).json["scene"]["hash"]);
  const std::string merged = dir("merged"), single = dir("single");
  ASSERT_EQ(run_pathex("merge " + a_ + " " + b_ + " --quiet --out " + merged).code, 0);
  ASSERT_EQ(run_pathex("trace --spp 8 --quiet --out " + single).code, 0);
  expect_same_outputs(single, merged, "the same scene from two files");
}

TEST_F(MergeRefuses, AnotherSeed) {
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --seed 2 --quiet --out " + b_).code, 0);
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) + " are not of one render: another seed (2 against 1)");
}

// Issue 39: bdpt's join roulette changes the estimates, so shards rendered with two thresholds are two renders.
TEST_F(MergeRefuses, AnotherJoinRouletteThreshold) {
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --rr-join-threshold 1 --quiet --out " + b_).code, 0);
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) +
                                    " are not of one render: another rr_join_threshold (1.000000 against auto)");
}

TEST_F(MergeRefuses, AnotherEyeRouletteThreshold) {
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --rr-threshold 0.3 --quiet --out " + b_).code, 0);
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) +
                                    " are not of one render: another rr_threshold (0.300000 against auto)");
}

TEST_F(MergeRefuses, AnotherProfile) {
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --renderer pt-nee --quiet --out " + b_).code, 0);
  const std::string ha = read_header(shard(a_)).json["renderer"]["hash"], hb = read_header(shard(b_)).json["renderer"]["hash"];
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) + " are not of one render: another renderer profile (pt-nee, hash " +
                                    hb + " against bdpt, hash " + ha + ")");
}

TEST_F(MergeRefuses, AnotherClassFile) {
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --classes samples/classes/basic.json --quiet --out " + b_).code, 0);
  const std::string ha = read_header(shard(a_)).json["classes"]["hash"], hb = read_header(shard(b_)).json["classes"]["hash"];
  const std::string file = read_header(shard(b_)).json["classes"]["file"];
  EXPECT_EQ(file, (fs::path(PATHEX_SOURCE_DIR) / "samples/classes/basic.json").string());
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) + " are not of one render: another class file (" + file +
                                    ", hash " + hb + " against the built-in classes, hash " + ha + ")");
}

TEST_F(MergeRefuses, AnotherPathexVersion) {
  nlohmann::ordered_json j = read_header(shard(b_)).json;
  const std::string mine = j["pathex"];
  j["pathex"] = "0.0.1 (elsewhere)";
  write_header(shard(b_), j);
  expect_refusal(a_ + " " + b_, shard(b_) + " was rendered by another pathex version (0.0.1 (elsewhere) against " + mine + ")");
}

// A render's connector strategies follow from its profile and scene (both hashed), so only a
// hand-made file has others; its statistics could not be added to the merge's.
TEST_F(MergeRefuses, AnotherConnectorLayout) {
  nlohmann::ordered_json j = read_header(shard(b_)).json;
  ASSERT_TRUE(j["connectors"].empty());
  j["connectors"] = {{{"strategy", j["strategies"][0]}, {"connector", "mirror"}}};
  write_header(shard(b_), j);
  expect_refusal(a_ + " " + b_, shard(b_) + " and " + shard(a_) +
                                    " are not of one render: another render description (strategies, connectors, end types or class text)");
}

TEST_F(MergeRefuses, OverlappingPasses) {
  const std::string c = dir("c");
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/4 --quiet --out " + c).code, 0);  // passes 2-3, also in a
  expect_refusal(a_ + " " + b_ + " " + c, "passes 2-3 are in both " + shard(a_) + " and " + shard(c) +
                                              ": the renders to merge must hold disjoint passes");
}

TEST_F(MergeRefuses, MissingPassesUnlessPartial) {
  expect_refusal(a_, "passes 4-7 of 0-7 are in no shard; give --partial to merge what there is (marked \"complete\": false)");
  const std::string out = dir("partial");
  const CliRun r = run_pathex("merge " + a_ + " --partial --out " + out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.out, "merged 1 shard file: 4 of 8 spp (missing passes 4-7)\nwrote " + out +
                       "/histogram.json, classes.exr and PNG previews, render.shard\n");
  EXPECT_EQ(histogram(out)["complete"], false);
  EXPECT_EQ(histogram(out)["spp"], 4);
  // A partial merge is a render folder like any other: resuming it renders the missing passes.
  const std::string single = dir("single");
  ASSERT_EQ(run_pathex("trace --spp 8 --quiet --out " + single).code, 0);
  ASSERT_EQ(run_pathex("trace --resume " + out + " --quiet").code, 0);
  expect_same_outputs(single, out, "partial merge resumed");
}

TEST_F(MergeRefuses, ACorruptedShard) {
  std::string bytes = read_file(shard(b_));
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
  std::ofstream(shard(b_), std::ios::binary) << bytes;
  expect_refusal(a_ + " " + b_, shard(b_) + ": corrupted shard file: its CRC-32 does not match its contents");
}

TEST_F(MergeRefuses, ATruncatedShard) {
  const std::string bytes = read_file(shard(b_));
  std::ofstream(shard(b_), std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  const Header h = read_header(shard(a_));
  expect_refusal(a_ + " " + b_, shard(b_) + ": truncated shard file: " + std::to_string(bytes.size() - 100) +
                                    " bytes, its header says at least " + std::to_string(bytes.size()));
}

TEST_F(MergeRefuses, NamingTheFirstBadFileInTheOrderGiven) {
  // merge reports the error of the first bad file in the order of the command line (and reads
  // no further), whatever kind of error a later file has.
  const std::string c = dir("c");
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --seed 2 --quiet --out " + b_).code, 0);
  ASSERT_EQ(run_pathex("trace --spp 8 --shard 1/2 --quiet --out " + c).code, 0);
  std::string bytes = read_file(shard(c));
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
  std::ofstream(shard(c), std::ios::binary) << bytes;
  expect_refusal(a_ + " " + b_ + " " + c, shard(b_) + " and " + shard(a_) + " are not of one render: another seed (2 against 1)");
  expect_refusal(a_ + " " + c + " " + b_, shard(c) + ": corrupted shard file: its CRC-32 does not match its contents");
}

TEST_F(MergeRefuses, AFolderWithoutShards) {
  const std::string empty = dir("empty");
  fs::create_directories(empty);
  expect_refusal(a_ + " " + empty, empty + ": no shard file (*.shard) in the folder: is it a pathex trace output folder?");
}

// --- MPI ---

#ifndef PATHEX_MPI_BINARY
#define PATHEX_MPI_BINARY ""
#endif

using pathex::test::run_mpirun;

TEST(Mpi, ThreeRanksWriteTheBytesOfOneProcess) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  const std::string args = " trace samples/scenes/cornell.json --classes samples/classes/basic.json --spp 10 --quiet --out ";
  const std::string single = dir("single"), ranks = dir("ranks");
  ASSERT_EQ(run_pathex(args + single).code, 0);
  const CliRun r = run_mpirun("-n 3 " + pathex::test::shell_quote(PATHEX_MPI_BINARY) + args + ranks + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_same_outputs(single, ranks, "3 MPI ranks");
  // The ranks' own shard files are gone once rank 0 has written render.shard, which holds them all.
  std::vector<std::string> shards;
  for (const auto& e : fs::directory_iterator(ranks))
    if (e.path().extension() == ".shard") shards.push_back(e.path().filename().string());
  EXPECT_EQ(shards, std::vector<std::string>{"render.shard"});
}

// The reduction sends only the sums some rank holds (one bit per batch cell, row sum and image
// tile, or-reduced first). Twenty classes on the Cornell box at 3 spp leave most batches empty,
// six class layers empty (no point, distant or lens paths) and one nearly so (specular-only, 4
// samples since issue 39's two replicates per pixel; 3 with issue 36's 32; 1 before), and with 2 or 3 ranks many paths, rows and tiles are held by one rank alone.
class MpiSparse : public ::testing::TestWithParam<int> {};
TEST_P(MpiSparse, RanksWriteTheBytesOfOneProcess) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  const std::string n = std::to_string(GetParam());
  const std::string args =
      " trace samples/scenes/cornell.json --classes samples/classes/twenty.json --resolution 40x40 --spp 3 --quiet --out ";
  const std::string single = dir("single"), ranks = dir("ranks-" + n);
  ASSERT_EQ(run_pathex(args + single).code, 0);
  std::vector<std::string> empty, sparse;
  const nlohmann::json classes = histogram(single)["classes"];
  for (const auto& c : classes) {
    if (c["samples"] == 0) empty.push_back(c["name"]);
    if (c["samples"] >= 1 && c["samples"] <= 4) sparse.push_back(c["name"]);
  }
  EXPECT_EQ(empty, (std::vector<std::string>{"caustic-hard", "from-point", "from-distant", "to-lens", "to-ortho", "not-local"}));
  EXPECT_EQ(sparse, std::vector<std::string>{"specular-only"});
  const CliRun r = run_mpirun("-n " + n + " " + pathex::test::shell_quote(PATHEX_MPI_BINARY) + args + ranks + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_same_outputs(single, ranks, n + " MPI ranks, twenty classes");
}
INSTANTIATE_TEST_SUITE_P(Ranks, MpiSparse, ::testing::Values(2, 3),
                         [](const ::testing::TestParamInfo<int>& p) { return std::to_string(p.param) + "ranks"; });

// The ranks share a deal of the passes (src/cli/mpi/mpi_deal.h): whoever is free takes the next
// chunk, so a rank's passes can be any set, and which set does not change a byte. The test's shim
// (support/mpi_deal_shim.cpp) holds ranks back: the last rank asks for its first chunk only once
// rank 0 has written its rank file, after the deal is done, so it renders nothing; with 3 ranks,
// rank 1 also asks 20 ms late for every chunk, so it takes fewer chunks than rank 0, scattered
// among rank 0's (where, varies from run to run).
#ifndef PATHEX_MPI_DEAL_SHIM
#define PATHEX_MPI_DEAL_SHIM ""
#endif
class MpiUnevenDeal : public ::testing::TestWithParam<int> {};
TEST_P(MpiUnevenDeal, RanksWriteTheBytesOfOneProcess) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  const int n = GetParam();
  const std::string args =
      " trace samples/scenes/cornell.json --classes samples/classes/twenty.json --resolution 40x40 --spp 64 --quiet --threads 1 --out ";
  const std::string single = dir("single"), ranks = dir("uneven-" + std::to_string(n));
  fs::remove_all(ranks + ".ranks");
  ASSERT_EQ(run_pathex(args + single).code, 0);
  using pathex::test::shell_quote;
  const std::string preload =
      "LD_PRELOAD=" + shell_quote(PATHEX_MPI_DEAL_SHIM) + " ASAN_OPTIONS=\"${ASAN_OPTIONS:-}:verify_asan_link_order=0\"";
  std::string cases = std::to_string(n - 1) + ") export " + preload + " PATHEX_DEAL_AWAIT=" + shell_quote(ranks + ".ranks/rank-0.shard") + ";; ";
  if (n == 3) cases += "1) export " + preload + " PATHEX_DEAL_SLEEP_MS=20;; ";
  const std::string body = "case \"$OMPI_COMM_WORLD_RANK\" in " + cases + "esac; exec " + shell_quote(PATHEX_MPI_BINARY) + args + ranks;
  const CliRun r = run_mpirun("-n " + std::to_string(n) + " sh -c " + shell_quote(body));
  ASSERT_EQ(r.code, 0) << r.out;
  expect_same_outputs(single, ranks, std::to_string(n) + " MPI ranks dealt unevenly");
}
INSTANTIATE_TEST_SUITE_P(Ranks, MpiUnevenDeal, ::testing::Values(2, 3),
                         [](const ::testing::TestParamInfo<int>& p) { return std::to_string(p.param) + "ranks"; });

// The ranks' connector statistics are reduced too: histogram.json and rank 0's table.
TEST(Mpi, ThreeRanksWithAConnectorWriteTheBytesOfOneProcess) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  const std::string args = " trace samples/scenes/point-glass.json --renderer pt-nee+manifold --resolution 24x24 --spp 9 --out ";
  const std::string single = dir("single"), ranks = dir("ranks");
  const CliRun one = run_pathex(args + single);
  ASSERT_EQ(one.code, 0) << one.err;
  expect_connector_work(single, "one process");
  const CliRun r = run_mpirun("-n 3 " + pathex::test::shell_quote(PATHEX_MPI_BINARY) + args + ranks + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.out;
  expect_same_outputs(single, ranks, "3 MPI ranks with a connector");
  EXPECT_EQ(connector_table(r.out), connector_table(one.out));
}

TEST(Mpi, ADyingRankFailsTheRunAndTheOthersWorkIsKept) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  const std::string args = " trace samples/scenes/point-plane.json --spp 48 --quiet --threads 1 --out ";
  const std::string single = dir("single"), ranks = dir("ranks");
  fs::remove_all(ranks + ".ranks");
  ASSERT_EQ(run_pathex(args + single).code, 0);
  // Rank 1 dies by SIGKILL at a point the test controls, with no clock involved: it renders its
  // passes, and at its first call to write its rank file (the test's signal shim, loaded into rank 1
  // alone) it waits until ranks 0 and 2 have written theirs, then kills itself. Ranks 0 and 2 then
  // wait in the reduction for rank 1, which never comes, until mpirun stops them.
  const std::string rank_file = ranks + ".ranks/rank-";
  const std::string shim = "LD_PRELOAD=" + pathex::test::shell_quote(PATHEX_SIGNAL_SHIM) +
                           " ASAN_OPTIONS=\"${ASAN_OPTIONS:-}:verify_asan_link_order=0\" PATHEX_SHIM_AT=1 PATHEX_SHIM_SIGNAL=9" +
                           " PATHEX_SHIM_DIR=" + pathex::test::shell_quote(rank_file + "1.shard") +
                           " PATHEX_SHIM_AWAIT=" + pathex::test::shell_quote(rank_file + "0.shard:" + rank_file + "2.shard");
  const std::string body = "if [ \"$OMPI_COMM_WORLD_RANK\" = 1 ]; then export " + shim + "; fi; exec " +
                           pathex::test::shell_quote(PATHEX_MPI_BINARY) + args + ranks;
  const CliRun r = run_mpirun("-n 3 sh -c " + pathex::test::shell_quote(body));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.out.find("process rank 1"), std::string::npos) << r.out;  // mpirun's message
  EXPECT_FALSE(fs::exists(ranks + "/histogram.json"));
  // Ranks 0 and 2 kept their passes; rank 1 left nothing behind, not even a temporary file.
  ASSERT_TRUE(fs::is_directory(ranks + ".ranks")) << r.out;
  std::vector<std::string> kept;
  for (const auto& e : fs::directory_iterator(ranks + ".ranks")) kept.push_back(e.path().filename().string());
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, (std::vector<std::string>{"rank-0.shard", "rank-2.shard"})) << r.out;
  // Resuming renders rank 1's passes and gives the bytes of one run.
  const CliRun resumed = run_pathex("trace --resume " + ranks + " --quiet");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  expect_same_outputs(single, ranks, "resumed after a dead rank");
}

}  // namespace
