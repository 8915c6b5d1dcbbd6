// Issue 17 (engine half) and two check-file items of issue 15: every reproducer of the stress
// run, run through the real binary, with its exact message and exit code. Each used to abort, hang
// or run past 10 s; each now answers or stops with a located error (exit 2) naming the option.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <utility>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "scene/scene.h"
#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;

fs::path scratch(const std::string& name) { return pathex::test::scratch_dir() / name; }
void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }
CliRun pathex(const std::vector<std::string>& args, const std::string& input = "") {
  return pathex::test::run_pathex_args(args, input);
}

// --- crashes ---

// --max-bounces 997..1000 compiled L[SD]{4,N+4}E under --max-repeat 1000 and dereferenced the
// failed result (std::bad_variant_access). The bounded universe is now built directly.
TEST(Issue17Crashes, MaxBouncesUpToTheRepeatLimitWork) {
  for (const char* n : {"996", "997", "1000"}) {
    const CliRun r = pathex({"query", "--json", "--renderer", "bdpt", "--max-bounces", n, "L.*DD.*E"});
    ASSERT_EQ(r.code, 0) << n << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j[0]["verdict"], "reachable") << n;
    EXPECT_EQ(j[0]["max_bounces"], std::stoi(n));
  }
  // The same bound in a profile and in a check file.
  write(scratch("bounded.json"),
        R"({"name": "bounded", "max_bounces": 1000, "strategies": [{"s": "0..", "chain": "DD", "t": "0.."}]})");
  // (partial: the class is unbounded, the profile stops at 1000 bounces)
  const CliRun q = pathex({"query", "--renderer", scratch("bounded.json").string(), "L.*DD.*E"});
  EXPECT_EQ(q.code, 0) << q.err;
  EXPECT_EQ(q.out.substr(0, q.out.find('\n', q.out.find('\n') + 1)), "class     bounded      \nL.*DD.*E  partial      ");
  write(scratch("bounded-check.json"),
        R"({"cases": [{"name": "deep", "renderer": "bdpt", "max_bounces": 1000, "require": [{"class": "L.*DD.*E", "verdict": "reachable"}]}]})");
  const CliRun c = pathex({"check", scratch("bounded-check.json").string()});
  EXPECT_EQ(c.code, 0) << c.out << c.err;
  EXPECT_EQ(c.out, "PASS  deep: L.*DD.*E is reachable (reachable)\ncheck: 1 passed, 0 failed\n");
}

// A number beyond a double (1e400) aborted with nlohmann's out_of_range.406 in every reader but
// the scene's. All JSON goes through one reader now, which names the value's pointer.
TEST(Issue17Crashes, NumberBeyondADoubleIsALocatedError) {
  write(scratch("classes.json"), R"({"classes": [{"name": "x", "expr": "L.*E", "weight": 1e400}]})");
  const CliRun c = pathex({"explain", "--classes", scratch("classes.json").string(), "$x"});
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err, "pathex: error: " + scratch("classes.json").string() +
                       ":/classes/0/weight: not valid JSON: number overflow parsing '1e400' at line 1, column 58 "
                       "(beyond the range of a double)\n");
  write(scratch("profile.json"), R"({"name": "p", "max_bounces": 1e400, "strategies": []})");
  const CliRun p = pathex({"query", "--renderer", scratch("profile.json").string(), "L.*E"});
  EXPECT_EQ(p.code, 2);
  EXPECT_EQ(p.err, "pathex: error: " + scratch("profile.json").string() +
                       ":/max_bounces: not valid JSON: number overflow parsing '1e400' at line 1, column 34 "
                       "(beyond the range of a double)\n");
  write(scratch("check.json"), R"({"cases": [{"name": "c", "renderer": "pt", "max_bounces": -1e400, "require": []}]})");
  const CliRun k = pathex({"check", scratch("check.json").string()});
  EXPECT_EQ(k.code, 2);
  EXPECT_EQ(k.err, "pathex: error: " + scratch("check.json").string() +
                       ":/cases/0/max_bounces: not valid JSON: number overflow parsing '-1e400' at line 1, column 64 "
                       "(beyond the range of a double)\n");
}

// classify --json aborted (type_error.316) on any non-ASCII byte; the plain message split a
// multi-byte character. Both report the line, whole characters, and exit 2.
TEST(Issue17Crashes, ClassifyReportsNonAsciiLines) {
  const std::string input = "LDDDDE\nLDéDDE\nLD\xff" "DDE\n";
  const CliRun plain = pathex({"classify"}, input);
  EXPECT_EQ(plain.code, 2);
  EXPECT_EQ(plain.err,
            "pathex: error: stdin:2: column 3: unexpected character 'é', expected one of L E S D\n  LDéDDE\n    ^\n"
            "pathex: error: stdin:3: column 3: unexpected byte 0xFF, expected one of L E S D\n  LD\xff" "DDE\n    ^\n");
  const CliRun json = pathex({"classify", "--json"}, input);
  EXPECT_EQ(json.code, 2);
  std::vector<nlohmann::json> lines;
  std::istringstream in(json.out);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[1]["path"], "LDéDDE");
  EXPECT_EQ(lines[1]["error"], "stdin:2: column 3: unexpected character 'é', expected one of L E S D\n  LDéDDE\n    ^");
  EXPECT_EQ(lines[2]["path"], "LD\xef\xbf\xbd" "DDE");  // the stray byte as U+FFFD
}

// Negative limits wrapped around (--max-depth -1 meant 2^64 - 1) and there was no ceiling, so
// --max-depth 1e8 let 10,000 '(' overflow the stack. Each limit now has a floor and a ceiling.
TEST(Issue17Crashes, LimitsHaveAFloorAndACeiling) {
  const CliRun neg = pathex({"explain", "--max-depth", "-1", "LDDDDE"});
  EXPECT_EQ(neg.code, 2);
  EXPECT_EQ(neg.err, "--max-depth: expected a non-negative integer, got '-1'\nRun with --help for more information.\n");
  const CliRun huge = pathex({"explain", "--max-states", "100000000", "LDDDDE"});
  EXPECT_EQ(huge.code, 2);
  EXPECT_EQ(huge.err, "--max-states: Value 100000000 not in range 1 to 10000000\nRun with --help for more information.\n");
  const CliRun work = pathex({"query", "--max-work", "-5", "LDDDDE"});
  EXPECT_EQ(work.code, 2);
  const CliRun bounces = pathex({"query", "--max-bounces", "-1", "LDDDDE"});
  EXPECT_EQ(bounces.code, 2);
}

// At the depth ceiling, 10,000 '(' and 100,000 '*' or '~' stop with a located error; the
// recursion over the tree is at most --max-depth deep.
TEST(Issue17Crashes, DeepNestingStopsAtTheCeiling) {
  const CliRun parens = pathex({"explain", "--max-depth", "1000", std::string(10000, '(') + "S"});
  EXPECT_EQ(parens.code, 2);
  EXPECT_EQ(parens.err.substr(0, parens.err.find('\n')),
            "pathex: error: column 1000: nesting depth exceeds the limit of 1000 levels (raise it with --max-depth)");
  const CliRun stars = pathex({"explain", "--max-depth", "1000", "S" + std::string(100000, '*')});
  EXPECT_EQ(stars.code, 2);
  EXPECT_EQ(stars.err.substr(0, stars.err.find('\n')),
            "pathex: error: column 1001: nesting depth exceeds the limit of 1000 levels (raise it with --max-depth)");
  const CliRun nots = pathex({"explain", "--max-depth", "1000", std::string(100000, '~') + "S"});
  EXPECT_EQ(nots.code, 2);
  EXPECT_EQ(nots.err.substr(0, nots.err.find('\n')),
            "pathex: error: column 1000: nesting depth exceeds the limit of 1000 levels (raise it with --max-depth)");
  // Just within the ceiling, the deepest tree compiles, prints and counts.
  const CliRun deep = pathex({"explain", "--max-depth", "1000", "L" + std::string(997, '(') + "S" + std::string(997, ')') + "DDDE"});
  EXPECT_EQ(deep.code, 0) << deep.err.substr(0, 300);
  const CliRun deep_not = pathex({"explain", "--max-depth", "1000", "L(" + std::string(996, '~') + "S)DDDE"});
  EXPECT_EQ(deep_not.code, 0) << deep_not.err.substr(0, 300);
}

// --- hangs: each finishes with its answer, or stops naming the option ---

TEST(Issue17Hangs, ExpressionsThatTookSeconds) {
  const CliRun a = pathex({"explain", "(S{1000}&D*){1000}"});
  EXPECT_EQ(a.code, 0);
  EXPECT_NE(a.out.find("language      empty\n"), std::string::npos) << a.out;
  const CliRun b = pathex({"explain", "--members", "0", "L(.{7}){1000}E"});
  EXPECT_EQ(b.code, 0);
  EXPECT_NE(b.out.find("language      finite\n"), std::string::npos) << b.out.substr(0, 500);
  const CliRun c = pathex({"explain", "$direct{1000}"});
  EXPECT_EQ(c.code, 0);
  EXPECT_NE(c.out.find("language      empty\n"), std::string::npos) << c.out.substr(0, 500);
  const CliRun d = pathex({"match", "L" + std::string(30000, 'D') + "E", "L" + std::string(30000, 'D') + "E"});
  EXPECT_EQ(d.code, 0) << d.err.substr(0, 300);
}

TEST(Issue17Hangs, ProfilesThatTookSeconds) {
  std::string many = R"({"name": "many", "strategies": [)";
  for (int i = 0; i < 400; ++i) many += std::string(i ? "," : "") + R"({"s": )" + std::to_string(i) + R"(, "t": "0.."})";
  write(scratch("many.json"), many + "]}");
  const CliRun m = pathex({"query", "--renderer", scratch("many.json").string(), "L.*DD.*E"});
  EXPECT_EQ(m.code, 0) << m.err;
  EXPECT_EQ(m.out.substr(0, m.out.find('\n', m.out.find('\n') + 1)), "class     many         \nL.*DD.*E  partial      ");
  // A 5,000-letter chain: its shortest witness is 5,004 letters, and listing witnesses needs a
  // table of (length x states) cells past the budget: the query stops naming --max-work.
  write(scratch("chain.json"), R"({"name": "long", "strategies": [{"s": 1, "chain": "D)" + std::string(4998, 'S') +
                                    R"(D", "t": "1..", "connector": "manifold"}]})");
  const CliRun c = pathex({"query", "--renderer", scratch("chain.json").string(), "L.*E"});
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err,
            "pathex: error: renderer long: column 1: the work of this operation exceeds the limit of 20000000 units "
            "(raise it with --max-work)\n  L.*E\n  ^\n");
}

// --- input sizes ---

TEST(Issue17Inputs, FilesAreReadUpToTheSizeCap) {
  const CliRun check = pathex({"check", "/dev/zero"});
  EXPECT_EQ(check.code, 2);
  EXPECT_EQ(check.err,
            "pathex: error: /dev/zero: the file exceeds the limit of 67108864 bytes (raise it with --max-file-size)\n");
  const CliRun classes = pathex({"classify", "--max-file-size", "1000", "--classes", "/dev/zero"});
  EXPECT_EQ(classes.code, 2);
  EXPECT_EQ(classes.err, "pathex: error: /dev/zero: the file exceeds the limit of 1000 bytes (raise it with --max-file-size)\n");
  const std::string scene = pathex::test::read_file(fs::path(PATHEX_SOURCE_DIR) / "samples/scenes/cornell.json");
  nlohmann::json j = nlohmann::json::parse(scene);
  j["shapes"][0] = {{"type", "mesh"}, {"file", "/dev/zero"}, {"material", j["shapes"][0]["material"]}};
  write(scratch("zero-mesh.json"), j.dump());
  const CliRun mesh = pathex({"query", "--max-file-size", "100000", "--scene", scratch("zero-mesh.json").string(), "L.*E"});
  EXPECT_EQ(mesh.code, 2);
  EXPECT_EQ(mesh.err, "pathex: error: /dev/zero: the file exceeds the limit of 100000 bytes (raise it with --max-file-size)\n");
}

// One face of 200,000 corners took tinyobjloader over 30 s to triangulate: faces are limited.
TEST(Issue17Inputs, ObjFacesHaveACornerLimit) {
  std::string obj;
  for (int i = 0; i < 2000; ++i) obj += "v " + std::to_string(i) + " 0 " + std::to_string(i % 7) + "\n";
  obj += "f";
  for (int i = 0; i < 200000; ++i) obj += " " + std::to_string(1 + i % 2000);
  write(scratch("big-face.obj"), obj + "\n");
  const std::string scene = pathex::test::read_file(fs::path(PATHEX_SOURCE_DIR) / "samples/scenes/cornell.json");
  nlohmann::json j = nlohmann::json::parse(scene);
  j["shapes"][0] = {{"type", "mesh"}, {"file", scratch("big-face.obj").string()}, {"material", j["shapes"][0]["material"]}};
  write(scratch("big-face.json"), j.dump());
  const CliRun r = pathex({"query", "--scene", scratch("big-face.json").string(), "L.*E"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + scratch("big-face.obj").string() +
                       ":2001:1: a face of 200000 corners exceeds the limit of 1024 (split or triangulate it in the modeller)\n");
}

// `query --scene` and `check` need the scene's types, not its triangles: the meshes keep their
// vertices (for the camera check) and are not triangulated.
TEST(Issue17Inputs, SceneTypesLoadNoTriangles) {
  const std::string path = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-glass.json";
  pathex::Result<pathex::Scene> full = pathex::load_scene_file(path);
  pathex::Result<pathex::Scene> types = pathex::load_scene_file(path, pathex::SceneLoadOptions{1 << 26, /*triangles=*/false});
  ASSERT_TRUE(full.ok());
  ASSERT_TRUE(types.ok());
  // (triangles, vertices) over the scene's meshes
  auto mesh_sizes = [](const pathex::Scene& scene) {
    std::pair<std::size_t, std::size_t> n{0, 0};
    for (const pathex::Shape& s : scene.shapes)
      if (const auto* m = std::get_if<pathex::MeshShape>(&s.geometry)) {
        n.first += m->triangles.size();
        n.second += m->positions.size();
      }
    return n;
  };
  EXPECT_GT(mesh_sizes(*full).first, 0u);
  EXPECT_EQ(mesh_sizes(*types).first, 0u);
  EXPECT_EQ(mesh_sizes(*types).second, mesh_sizes(*full).second);
  EXPECT_EQ(pathex::describe(pathex::scene_types(*types)), pathex::describe(pathex::scene_types(*full)));
}

// --- check files (issue 15) ---

TEST(Issue15CheckFiles, UnknownRendererAndMissingSceneNameTheirPointer) {
  write(scratch("renderer.json"),
        R"({"cases": [{"name": "a", "renderer": "pathtracer", "require": [{"class": "L.*E", "verdict": "reachable"}]}]})");
  const CliRun r = pathex({"check", scratch("renderer.json").string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + scratch("renderer.json").string() +
                       ":/cases/0/renderer: unknown renderer 'pathtracer': not a built-in profile (pt, pt-nee, lt, bdpt, "
                       "bdpt+mirror, bdpt+ortho, bdpt+manifold, pt-nee+distant, pt-nee+mirror, pt-nee+manifold, pbrt-v4-path, pbrt-v4-bdpt, "
                       "pbrt-v4-lightpath, mitsuba3-path, mitsuba3-ptracer) nor a profile file\n");
  write(scratch("scene.json"),
        R"({"cases": [{"name": "a", "renderer": "pt", "scene": "nowhere.json", "require": [{"covers-scene": true}]}]})");
  const CliRun s = pathex({"check", scratch("scene.json").string()});
  EXPECT_EQ(s.code, 2);
  EXPECT_EQ(s.err, "pathex: error: " + scratch("scene.json").string() +
                       ":/cases/0/scene: nowhere.json: cannot open the scene file\n");
}

TEST(Issue15CheckFiles, BadCheckFileStillWritesJUnit) {
  write(scratch("bad.json"), R"({"cases": [{"name": "a", "renderer": "pathtracer", "require": [{"covers-scene": true}]}]})");
  const fs::path xml = scratch("report.xml");
  const CliRun r = pathex({"check", scratch("bad.json").string(), "--junit", xml.string()});
  EXPECT_EQ(r.code, 2);
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(xml.c_str()));
  const pugi::xml_node suite = doc.child("testsuites").child("testsuite");
  EXPECT_STREQ(suite.attribute("tests").value(), "1");
  EXPECT_STREQ(suite.attribute("errors").value(), "1");
  EXPECT_STREQ(suite.attribute("failures").value(), "0");
  const pugi::xml_node error = suite.child("testcase").child("error");
  ASSERT_TRUE(error);
  EXPECT_STREQ(error.attribute("message").value(), "the check file could not be run");
  EXPECT_EQ(std::string(error.text().get()) + "\n", r.err.substr(std::string("pathex: error: ").size()));
}

}  // namespace
