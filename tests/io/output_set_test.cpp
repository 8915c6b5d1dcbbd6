// `pathex trace --out DIR` writes one set of outputs, whole or not at all (io/output_set.h): the
// folder is checked before the render, a new set replaces exactly the files of the old one, and a
// signal at any point of the write phase leaves the old set or the new one, never a mix. The
// interruption tests signal the process at every file-system call of the write phase through an
// LD_PRELOAD library of the tests (support/signal_shim.cpp).
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <map>
#include <string>

#include "io/output_set.h"
#include "support/cli_run.h"

namespace pathex {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::read_file;
using test::shell_quote;

// The folder's files and their bytes.
std::map<std::string, std::string> contents(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out[e.path().filename().string()] = read_file(e.path());
  return out;
}

// Entries beside `dir` whose names mention pathex's staging or probe folders.
std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir.parent_path())) {
    const std::string n = e.path().filename().string();
    if (n.find(".pathex-") != std::string::npos || n.find(".tmp-") != std::string::npos) out.push_back(n);
  }
  return out;
}

// `pathex trace` of a small sample scene into `out`, with `env` before the command.
CliRun trace(const fs::path& out, const std::string& extra = "", const std::string& env = "", const std::string& spp = "1") {
  const fs::path err = test::scratch_dir() / "trace-stderr.txt";
  const std::string cmd = "cd " + shell_quote(PATHEX_SOURCE_DIR) + " && " + env + " " + shell_quote(PATHEX_BINARY) +
                          " trace samples/scenes/point-plane.json --spp " + spp + " --quiet --out " + shell_quote(out.string()) + " " +
                          extra + " 2> " + shell_quote(err.string()) + " > /dev/null";
  CliRun r;
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(err);
  return r;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path p = test::scratch_dir() / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

TEST(OutputSet, UnwritableOutIsReportedBeforeRendering) {
  // 2^24 passes would take hours: the error must come before the render.
  const CliRun r = trace("/proc/pathex-out", "", "", "16777216");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("pathex: error: --out /proc/pathex-out: cannot create the output folder in /proc: ", 0), 0u) << r.err;
}

TEST(OutputSet, OutThatIsAFileIsRefused) {
  const fs::path dir = fresh_dir("file-out");
  std::ofstream(dir / "out") << "x";
  const CliRun r = trace(dir / "out");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --out " + (dir / "out").string() + ": exists and is not a folder\n");
}

TEST(OutputSet, NewSetReplacesExactlyTheOldOnesFiles) {
  const fs::path out = fresh_dir("reuse") / "out";
  ASSERT_EQ(trace(out).code, 0);  // the built-in classes: local, emission, direct, indirect, caustic
  EXPECT_TRUE(fs::exists(out / "caustic.png"));
  EXPECT_TRUE(fs::exists(out / kManifestName));
  ASSERT_EQ(trace(out, "--classes samples/classes/basic.json").code, 0);
  const std::map<std::string, std::string> files = contents(out);
  EXPECT_EQ(files.count("caustic.png"), 0u) << "a stale layer of the first run survived";
  EXPECT_EQ(files.count("direct-diffuse.png"), 1u);
  // The manifest lists exactly the other files.
  std::string listed;
  for (const auto& [name, bytes] : files)
    if (name != kManifestName) listed += name + "\n";
  const std::string manifest = files.at(kManifestName);
  EXPECT_EQ(manifest.substr(manifest.find('\n') + 1), listed);
  EXPECT_TRUE(leftovers(out).empty());
}

TEST(OutputSet, FolderWithFilesPathexDidNotWriteIsRefused) {
  const fs::path out = fresh_dir("foreign") / "out";
  ASSERT_EQ(trace(out).code, 0);
  std::ofstream(out / "notes.txt") << "mine";
  const CliRun r = trace(out);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --out " + out.string() +
                       ": the folder holds 'notes.txt', which pathex did not write there (it is not in the folder's "
                       ".pathex-manifest); pathex replaces only its own outputs: choose another --out folder, or empty this one\n");
  EXPECT_EQ(read_file(out / "notes.txt"), "mine");
  // A folder from before manifests (or anyone's) is refused the same way, naming the first file.
  const fs::path old = fresh_dir("no-manifest");
  std::ofstream(old / "histogram.json") << "{}";
  const CliRun r2 = trace(old);
  EXPECT_EQ(r2.code, 2);
  EXPECT_NE(r2.err.find("the folder holds 'histogram.json', which pathex did not write there (the folder has no .pathex-manifest)"),
            std::string::npos)
      << r2.err;
}

TEST(OutputSet, OutThatHoldsTheCurrentFolderIsRefused) {
  const CliRun r = trace(".");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --out .: contains the current folder, which pathex would replace; name a folder of its own for the outputs\n");
}

TEST(MaxMemory, ImagesBeyondTheLimitAreRefusedBeforeRendering) {
  const fs::path out = fresh_dir("memory") / "out";
  // 32 x 32 pixels, 6 layers: 32 * 32 * 6 * 84 bytes = 0.5 MiB > 0.25 MiB.
  const CliRun r = trace(out, "--max-memory 256K");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: samples/scenes/point-plane.json:/camera: the images would take about 0.0 GiB (32 x 32 pixels, "
                   "6 layers), more than --max-memory 0.0 GiB; pass --no-images for the histogram alone, render fewer pixels or "
                   "classes, or raise --max-memory\n");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(trace(out, "--max-memory 256K --no-images").code, 0);
  EXPECT_EQ(trace(out, "--max-memory 1M").code, 0);
}

// Issue 17: 16384 x 16384 pixels (the schema's largest) were killed for want of memory after
// allocating for minutes; now refused before rendering.
TEST(MaxMemory, TheLargestImageIsRefusedUpFront) {
  std::string scene = read_file(fs::path(PATHEX_SOURCE_DIR) / "samples/scenes/point-plane.json");
  const std::string from = R"("width": 32, "height": 32)";
  ASSERT_NE(scene.find(from), std::string::npos);
  scene.replace(scene.find(from), from.size(), R"("width": 16384, "height": 16384)");
  const fs::path dir = fresh_dir("huge");
  std::ofstream(dir / "huge.json") << scene;
  const fs::path err = dir / "stderr.txt";
  const std::string cmd = shell_quote(PATHEX_BINARY) + " trace " + shell_quote((dir / "huge.json").string()) + " --quiet --out " +
                          shell_quote((dir / "out").string()) + " 2> " + shell_quote(err.string()) + " > /dev/null";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2);
  EXPECT_EQ(read_file(err), "pathex: error: " + (dir / "huge.json").string() +
                                ":/camera: the images would take about 126.0 GiB (16384 x 16384 pixels, 6 layers), more than "
                                "--max-memory 4.0 GiB; pass --no-images for the histogram alone, render fewer pixels or classes, "
                                "or raise --max-memory\n");
}

// --- interruption: a signal at every file-system call of the write phase ---

struct Interrupted {
  int runs = 0, old_sets = 0, new_sets = 0;
};

// Runs `pathex trace` into a folder holding the set of the default classes, signalling at call N
// for N = 1, 2, … until a run finishes before call N; after each, the folder must hold exactly
// the old set or exactly the new one (a single class layer, so that the sets differ in files).
Interrupted interrupt_everywhere(int sig, bool leftovers_allowed, int step = 1) {
  const fs::path base = fresh_dir("interrupt-" + std::to_string(sig));
  const fs::path pristine = base / "pristine", out = base / "out", count = base / "count";
  EXPECT_EQ(trace(pristine).code, 0);
  const auto old_set = contents(pristine);
  const fs::path fresh = base / "fresh";
  const fs::path one = base / "one.json";
  std::ofstream(one) << R"({"classes": [{"name": "direct-only", "expr": "$direct"}]})";
  const std::string classes = "--classes " + shell_quote(one.string());
  EXPECT_EQ(trace(fresh, classes).code, 0);
  const auto new_set = contents(fresh);
  Interrupted st;
  for (int n = 1; n < 200; n += step) {
    fs::remove_all(out);
    fs::copy(pristine, out);
    const std::string env = "LD_PRELOAD=" + shell_quote(PATHEX_SIGNAL_SHIM) + " ASAN_OPTIONS=verify_asan_link_order=0" +
                            " PATHEX_SHIM_AT=" + std::to_string(n) + " PATHEX_SHIM_SIGNAL=" + std::to_string(sig) +
                            " PATHEX_SHIM_DIR=" + shell_quote(base.string()) + " PATHEX_SHIM_COUNT=" + shell_quote(count.string());
    fs::remove(count);
    const CliRun r = trace(out, classes, env);
    ++st.runs;
    const auto now = contents(out);
    // run.json and render.shard record the run's time (and the histogram's new classes differ
    // from the old), so a new set is recognised by its file names and images; an old one must be
    // byte for byte the old set.
    const auto timed = [](const std::string& k) { return k == "histogram.json" || k == "run.json" || k == "render.shard"; };
    std::map<std::string, std::string> names_now, names_new;
    for (const auto& [k, v] : now) names_now[k] = timed(k) ? "" : v;
    for (const auto& [k, v] : new_set) names_new[k] = timed(k) ? "" : v;
    if (now == old_set) {
      ++st.old_sets;
    } else if (names_now == names_new) {
      ++st.new_sets;
    } else {
      ADD_FAILURE() << "signal " << sig << " at call " << n << ": a mixed set";
    }
    if (!leftovers_allowed) {
      EXPECT_EQ(leftovers(out), std::vector<std::string>()) << "signal " << sig << " at call " << n;
    }
    const bool finished = fs::exists(count) && std::stol(read_file(count)) < n;
    if (finished) {
      EXPECT_EQ(r.code, 0);
      break;
    }
  }
  // A normal run afterwards puts the new set in place and clears what a killed run left.
  EXPECT_EQ(trace(out, classes).code, 0);
  EXPECT_TRUE(leftovers(out).empty());
  return st;
}

TEST(OutputSet, SigtermAtEveryPointOfTheWritePhaseLeavesOneWholeSet) {
  const Interrupted st = interrupt_everywhere(SIGTERM, /*leftovers_allowed=*/false);
  EXPECT_GT(st.runs, 10);
  EXPECT_GT(st.old_sets, 0);
  EXPECT_GT(st.new_sets, 0);
}

// SIGINT goes through the same shield as SIGTERM: every seventh point.
TEST(OutputSet, SigintDuringTheWritesLeavesOneWholeSet) {
  const Interrupted st = interrupt_everywhere(SIGINT, /*leftovers_allowed=*/false, /*step=*/7);
  EXPECT_GT(st.new_sets, 0);
}

// SIGKILL cannot be held back: the old set stays until the exchange, and the staging folder it
// leaves behind is removed by the next run.
TEST(OutputSet, SigkillAtEveryPointLeavesTheOldSetOrTheNewOne) {
  const Interrupted st = interrupt_everywhere(SIGKILL, /*leftovers_allowed=*/true);
  EXPECT_GT(st.old_sets, 0);
  EXPECT_GT(st.new_sets, 0);
}

}  // namespace
}  // namespace pathex
