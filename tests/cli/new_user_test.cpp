// What a new user hit (issue 15), each as the user meets it: the real `pathex` binary, run from
// the source directory, with its exact messages and exit codes. Two tests draw on a
// pseudo-terminal (forkpty), as a user's shell does: the progress line on a narrow terminal and
// Ctrl-C in the middle of a render.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;

CliRun pathex_cli(const std::vector<std::string>& args) { return pathex::test::run_pathex_args(args); }

std::string out_dir(const std::string& name) {
  const fs::path d = pathex::test::scratch_dir() / name;
  fs::remove_all(d);
  return d.string();
}

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(pathex::test::read_file(path)); }

// Runs pathex with `args` and its standard error on a pseudo-terminal `columns` wide (standard
// output to /dev/null). `on_output` sees everything drawn so far after each read and may act on
// the child (whose pid it gets). Returns what was drawn and the exit status.
struct TerminalRun {
  std::string drawn;
  int status = 0;
};
TerminalRun run_on_terminal(const std::vector<std::string>& args, int columns,
                            const std::function<void(const std::string&, pid_t)>& on_output = {}) {
  winsize size{};
  size.ws_col = static_cast<unsigned short>(columns);
  size.ws_row = 24;
  int master = -1;
  const pid_t child = ::forkpty(&master, nullptr, nullptr, &size);
  if (child < 0) return {};
  if (child == 0) {
    if (::chdir(PATHEX_SOURCE_DIR) != 0) ::_exit(126);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    std::vector<char*> argv{const_cast<char*>(PATHEX_BINARY)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(PATHEX_BINARY, argv.data());
    ::_exit(127);
  }
  TerminalRun r;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(master, buf, sizeof buf);
    if (n > 0) {
      r.drawn.append(buf, static_cast<std::size_t>(n));
      if (on_output) on_output(r.drawn, child);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      break;  // EIO once the child has exited
    }
  }
  ::waitpid(child, &r.status, 0);
  ::close(master);
  return r;
}

// --- the command line ---

TEST(NewUser, UnknownCommandIsNamedAndTheCommandsListed) {
  const CliRun r = pathex_cli({"render", "scene.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err,
            "pathex: error: unknown command 'render'; the commands are explain, match, classify, query, check, "
            "renderers, trace, merge, converge, bias, report (pathex --help describes them)\n");
  const CliRun none = pathex_cli({});
  EXPECT_EQ(none.code, 2);
  EXPECT_EQ(none.err,
            "pathex: error: a command is required; the commands are explain, match, classify, query, check, "
            "renderers, trace, merge, converge, bias, report (pathex --help describes them)\n");
  EXPECT_EQ(pathex_cli({"--version"}).code, 0);
}

TEST(NewUser, NegativeValuesOfUnsignedOptionsAreRefused) {
  const CliRun seed = pathex_cli({"trace", "--seed", "-1", "--out", out_dir("seed")});
  EXPECT_EQ(seed.code, 2);
  EXPECT_EQ(seed.err, "--seed: expected a non-negative integer, got '-1'\nRun with --help for more information.\n");
  EXPECT_FALSE(fs::exists(out_dir("seed")));
  const CliRun states = pathex_cli({"explain", "--max-states", "-5", "LDDE"});
  EXPECT_EQ(states.code, 2);
  EXPECT_EQ(states.err, "--max-states: expected a non-negative integer, got '-5'\nRun with --help for more information.\n");
  EXPECT_EQ(pathex_cli({"trace", "--max-paths", "-3"}).code, 2);
  // The largest seed is still accepted.
  const std::string dir = out_dir("seed-max");
  const CliRun max = pathex_cli({"trace", "--seed", "18446744073709551615", "--spp", "1", "--no-images", "--quiet", "--out", dir});
  EXPECT_EQ(max.code, 0) << max.err;
  EXPECT_EQ(read_json(dir + "/histogram.json")["seed"], 18446744073709551615ull);
}

TEST(NewUser, LightListsAreCommaSeparatedAndTheMessageSaysSo) {
  const CliRun spaced = pathex_cli({"query", "--notation", "heckbert", "--light", "point", "area", "LSDE"});
  EXPECT_EQ(spaced.code, 2);
  EXPECT_EQ(spaced.out, "");
  EXPECT_EQ(spaced.err,
            "pathex: error: --light takes one comma-separated list, such as --light point,area; 'area' after it "
            "would be read as an expression\n");
  const CliRun sensors = pathex_cli({"explain", "--notation", "heckbert", "--sensor", "pinhole", "lens", "LDE"});
  EXPECT_EQ(sensors.code, 2);
  EXPECT_EQ(sensors.err,
            "pathex: error: --sensor takes one comma-separated list, such as --sensor pinhole,lens; 'lens' after it "
            "would be read as an expression\n");
  const CliRun listed = pathex_cli({"query", "--notation", "heckbert", "--light", "point,area", "--renderer", "bdpt", "LSDE"});
  EXPECT_EQ(listed.code, 0) << listed.err;
  EXPECT_EQ(listed.out.substr(0, listed.out.find('\n', listed.out.find('\n') + 1)),
            "class     bdpt         \nLSDE      partial      ");
}

TEST(NewUser, AClassNamedTotalIsRefusedWhenTheClassFileLoads) {
  const fs::path file = pathex::test::scratch_dir() / "total.json";
  std::ofstream(file) << R"({"classes": [{"name": "mine", "expr": "$direct"}, {"name": "total", "expr": "$all"}]})";
  const std::string expected = "pathex: error: " + file.string() +
                               ":/classes/1/name: the class name 'total' is reserved for the image's total layer, "
                               "expected another name\n";
  const std::string dir = out_dir("total");
  const CliRun trace = pathex_cli({"trace", "--classes", file.string(), "--spp", "64", "--out", dir});
  EXPECT_EQ(trace.code, 2);
  EXPECT_EQ(trace.err, expected);
  EXPECT_FALSE(fs::exists(dir));  // refused before rendering
  const CliRun classify = pathex_cli({"classify", "--classes", file.string()});
  EXPECT_EQ(classify.code, 2);
  EXPECT_EQ(classify.err, expected);
}

// --- pathex trace ---

// "direct: 76.6 %" with pt-nee and "23.4 %" with bdpt are shares of different totals (pt-nee
// cannot reach the caustics and the light seen in the mirror); the absolute luminance printed
// beside them is the same light. Tolerance: 4 standard errors of the difference (fixed seeds).
TEST(NewUser, SharesComeWithAbsoluteEstimatesThatAgreeBetweenRenderers) {
  std::map<std::string, std::pair<double, double>> direct;  // renderer -> (luminance, stderr)
  for (const std::string renderer : {"pt-nee", "bdpt"}) {
    const std::string dir = out_dir("absolute-" + renderer);
    const CliRun r = pathex_cli({"trace", "samples/scenes/point-mirror-caustic.json", "--renderer", renderer, "--spp",
                                 "16", "--no-images", "--out", dir});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("(shares are of this render's total; luminances are absolute, comparable between renderers)\n"),
              std::string::npos)
        << r.out;
    const std::regex line("\ndirect: ([0-9.]+) % of the image, ±[0-9.]+ %; " + renderer +
                          ": partial; luminance ([0-9.]+) ± ([0-9.]+)\n");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, line)) << r.out;
    // The printed figures are histogram.json's, rounded.
    const nlohmann::json j = read_json(dir + "/histogram.json");
    const nlohmann::json& c = j["classes"][2];
    ASSERT_EQ(c["name"], "direct");
    EXPECT_NEAR(std::stod(m[1]), 100 * c["share"].get<double>(), 0.05);
    EXPECT_NEAR(std::stod(m[2]), c["luminance"].get<double>(), 5e-6);
    EXPECT_NEAR(std::stod(m[3]), c["stderr"].get<double>(), 5e-6);
    direct[renderer] = {c["luminance"].get<double>(), c["stderr"].get<double>()};
    if (renderer == "pt-nee") EXPECT_NEAR(c["share"].get<double>(), 0.766, 0.01);
    else EXPECT_NEAR(c["share"].get<double>(), 0.234, 0.01);
  }
  const auto [a, sa] = direct["pt-nee"];
  const auto [b, sb] = direct["bdpt"];
  EXPECT_LT(std::abs(a - b), 4 * std::sqrt(sa * sa + sb * sb)) << a << " vs " << b;
}

TEST(NewUser, PtOnAPointLightSceneNamesTheUnreachableLight) {
  const std::string dir = out_dir("pt-point");
  const CliRun r = pathex_cli({"trace", "samples/scenes/point-mirror-caustic.json", "--renderer", "pt", "--spp", "1",
                               "--no-images", "--quiet", "--out", dir});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err,
            "pathex: warning: pt cannot sample any path from the point light at (0.6, 0.8, 0) (LSD…E), so its light "
            "is missing from the image; renderers that reach it: pt-nee, lt, bdpt, bdpt+mirror, bdpt+ortho, bdpt+manifold, pt-nee+distant, pt-nee+mirror, "
            "pt-nee+manifold, "
            "pbrt-v4-path, pbrt-v4-bdpt, pbrt-v4-lightpath, mitsuba3-path, mitsuba3-ptracer (--renderer NAME)\n");
  EXPECT_EQ(read_json(dir + "/histogram.json")["total"]["luminance"], 0.0);
  // The area light of the default scene is reachable by pt: no warning.
  const CliRun cornell = pathex_cli({"trace", "--renderer", "pt", "--spp", "1", "--no-images", "--quiet", "--out", dir});
  EXPECT_EQ(cornell.code, 0);
  EXPECT_EQ(cornell.err, "");
}

TEST(NewUser, ResolutionSetsTheImageSize) {
  const std::string dir = out_dir("resolution");
  const CliRun r = pathex_cli({"trace", "--resolution", "24x10", "--spp", "1", "--quiet", "--out", dir});
  ASSERT_EQ(r.code, 0) << r.err;
  pathex::Result<pathex::ExrChannels> exr = pathex::read_exr(dir + "/classes.exr");
  ASSERT_TRUE(exr) << exr.error().render();
  EXPECT_EQ(exr->width, 24);
  EXPECT_EQ(exr->height, 10);
  for (const std::string bad : {"0x10", "24", "24x", "x10", "24x10x2", "-24x10", "16385x1", "24X10"}) {
    const CliRun b = pathex_cli({"trace", "--resolution", bad, "--out", out_dir("bad-resolution")});
    EXPECT_EQ(b.code, 2) << bad;
    EXPECT_EQ(b.err, "pathex: error: --resolution: expected WIDTHxHEIGHT with each from 1 to 16384, such as 640x480; "
                     "got '" + bad + "'\n");
  }
  const CliRun meter = pathex_cli({"trace", "samples/scenes/spotmeter-caustic.json", "--resolution", "2x2"});
  EXPECT_EQ(meter.code, 2);
  EXPECT_EQ(meter.err,
            "pathex: error: --resolution: the scene's sensor is a spot meter, which measures one pixel (1x1); got "
            "'2x2'\n");
}

TEST(NewUser, MaxPathsBoundsTheHistogramAndSumsTheRest) {
  const std::string dir = out_dir("max-paths");
  const CliRun r = pathex_cli({"trace", "--spp", "4", "--max-paths", "5", "--no-images", "--quiet", "--out", dir});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = read_json(dir + "/histogram.json");
  EXPECT_EQ(j["max_paths"], 5);
  const std::uint64_t distinct = j["distinct_paths"];
  ASSERT_GT(distinct, 5u);
  ASSERT_EQ(j["paths"].size(), 6u);
  const nlohmann::json& other = j["paths"][5];
  EXPECT_EQ(other["path"], "other");
  EXPECT_EQ(other["paths"], distinct - 5);
  EXPECT_EQ(other["note"], "the sum of the " + std::to_string(distinct - 5) + " paths past the first 5 (--max-paths)");
  // Every path is in a row or in "other": the rows add up to the total (exact sums, rounded once each).
  double sum = 0;
  for (const auto& p : j["paths"]) sum += p["luminance"].get<double>();
  EXPECT_NEAR(sum, j["total"]["luminance"].get<double>(), 1e-12);
  // The default is 1000.
  const CliRun d = pathex_cli({"trace", "--spp", "1", "--no-images", "--quiet", "--out", dir});
  ASSERT_EQ(d.code, 0);
  EXPECT_EQ(read_json(dir + "/histogram.json")["max_paths"], 1000);
}

// --- on a terminal ---

TEST(NewUser, ProgressOnANarrowTerminalRedrawsInPlace) {
  const std::string dir = out_dir("narrow");
  const TerminalRun r = run_on_terminal({"trace", "--spp", "64", "--threads", "1", "--no-images", "--out", dir}, 40);
  ASSERT_TRUE(WIFEXITED(r.status) && WEXITSTATUS(r.status) == 0) << r.drawn;
  EXPECT_NE(r.drawn.find('%'), std::string::npos) << "no progress was drawn: " << r.drawn;
  EXPECT_EQ(r.drawn.find('\n'), std::string::npos) << r.drawn;  // no line was ever left behind
  std::size_t start = 0;
  for (;;) {
    const std::size_t cr = r.drawn.find('\r', start);
    const std::string segment = r.drawn.substr(start, cr == std::string::npos ? std::string::npos : cr - start);
    EXPECT_LE(segment.size(), 39u) << segment;
    if (cr == std::string::npos) break;
    start = cr + 1;
  }
}

// Ctrl-C once the progress line shows: the render stops, histogram.json says what was done and
// what was asked, and the exit code is 1.
TEST(NewUser, AnInterruptedRenderRecordsTheRequestedSpp) {
  const std::string dir = out_dir("interrupted");
  bool sent = false;
  const TerminalRun r = run_on_terminal({"trace", "--spp", "1000000", "--threads", "1", "--no-images", "--out", dir}, 80,
                                        [&](const std::string& drawn, pid_t child) {
                                          if (!sent && drawn.find('%') != std::string::npos) {
                                            ::kill(child, SIGINT);
                                            sent = true;
                                          }
                                        });
  ASSERT_TRUE(sent) << r.drawn;
  ASSERT_TRUE(WIFEXITED(r.status)) << r.drawn;
  EXPECT_EQ(WEXITSTATUS(r.status), 1);
  const nlohmann::json j = read_json(dir + "/histogram.json");
  EXPECT_EQ(j["complete"], false);
  EXPECT_EQ(j["spp_requested"], 1000000);
  EXPECT_LT(j["spp"].get<std::uint64_t>(), 1000000u);
  EXPECT_EQ(j["spp"].get<std::uint64_t>() % 4, 0u);  // whole chunks of passes
}

TEST(NewUser, ACompleteRenderRecordsTheRequestedSppToo) {
  const std::string dir = out_dir("complete");
  ASSERT_EQ(pathex_cli({"trace", "--spp", "3", "--no-images", "--quiet", "--out", dir}).code, 0);
  const nlohmann::json j = read_json(dir + "/histogram.json");
  EXPECT_EQ(j["spp"], 3);
  EXPECT_EQ(j["spp_requested"], 3);
}

}  // namespace
