// The LPE notation as a user meets it: `--notation lpe` on explain, match and query, `"notation":
// "lpe"` in class and check files, `explain --emit lpe` and its read-back, the located errors of
// the LPE corpus, and the Heckbert hint. Runs the real executable from the source directory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;

CliRun pathex(const std::vector<std::string>& args) { return pathex::test::run_pathex_args(args); }

// The README's translation example.
TEST(LpeCli, ExplainShowsTheFullPathForm) {
  const CliRun r = pathex({"explain", "--notation", "lpe", "C<RD>S+L"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\nfull-path form L..S+D..E\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("notation      lpe\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(LpeCli, ErrorsPointAtTheCharacterAndExitTwo) {
  const nlohmann::json corpus =
      nlohmann::json::parse(pathex::test::read_file(fs::path(PATHEX_SOURCE_DIR) / "grammar/corpus/lpe.json"));
  for (const auto& e : corpus["invalid"]) {
    const std::string l = e["lpe"];
    const CliRun r = pathex({"explain", "--notation", "lpe", l});
    EXPECT_EQ(r.code, 2) << l;
    EXPECT_EQ(r.out, "") << l;
    const int column = e["column"];
    std::string expected = "pathex: error: column " + std::to_string(column) + ": " + e["message"].get<std::string>();
    if (!l.empty()) expected += "\n  " + l + "\n  " + std::string(static_cast<std::size_t>(column - 1), ' ') + "^";
    expected += "\n";
    EXPECT_EQ(r.err, expected) << l;
  }
}

TEST(LpeCli, MatchAndQueryReadLpes) {
  EXPECT_EQ(pathex({"match", "--notation", "lpe", "C<RD>L", "LSDDDSE"}).code, 0);
  EXPECT_EQ(pathex({"match", "--notation", "lpe", "C<RD>L", "LSDSDSE"}).code, 1);
  // Light and sensor types apply to LPEs as to Heckbert strings.
  EXPECT_EQ(pathex({"match", "--notation", "lpe", "--light", "area", "C<RD>L", "LSDDDSE"}).code, 1);
  const CliRun q = pathex({"query", "--notation", "lpe", "--renderer", "pt", "--renderer", "bdpt", "--json", "C<RS>L"});
  ASSERT_EQ(q.code, 0) << q.err;
  const nlohmann::json j = nlohmann::json::parse(q.out);
  EXPECT_EQ(j[0]["verdict"], "partial");  // pt reaches the area-light paths only
  EXPECT_EQ(j[1]["verdict"], "partial");  // bdpt misses point light -> mirror -> pinhole
}

TEST(LpeCli, ClassAndCheckFilesSayNotationLpe) {
  const fs::path dir = pathex::test::scratch_dir();
  std::ofstream(dir / "lpe-classes.json")
      << R"({"classes": [{"name": "diffuse_direct", "expr": "C<RD>L", "notation": "lpe"},
                          {"name": "seen", "expr": "$diffuse_direct & L....+E"}]})";
  const CliRun c = pathex({"match", "--classes", (dir / "lpe-classes.json").string(), "$seen", "LDDDDDE"});
  EXPECT_EQ(c.code, 0) << c.err;
  std::ofstream(dir / "lpe-check.json")
      << R"({"cases": [{"name": "caustics", "renderer": "bdpt", "notation": "lpe",
                        "require": [{"class": "C.*DS+L", "verdict": "partial"}]}]})";
  const CliRun k = pathex({"check", (dir / "lpe-check.json").string()});
  EXPECT_EQ(k.code, 0) << k.out << k.err;
  std::ofstream(dir / "bad-check.json")
      << R"({"cases": [{"name": "x", "renderer": "bdpt", "notation": "osl", "require": [{"class": "CL", "verdict": "reachable"}]}]})";
  const CliRun b = pathex({"check", (dir / "bad-check.json").string()});
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.err.find("/cases/0/notation"), std::string::npos) << b.err;
  EXPECT_NE(b.err.find(R"(expected "full", "heckbert" or "lpe")"), std::string::npos) << b.err;
}

TEST(LpeCli, EmitLpeIsExactOrSaysWhatItLoses) {
  const CliRun exact = pathex({"explain", "--emit", "lpe", "L..S+D..E"});
  EXPECT_EQ(exact.code, 0);
  EXPECT_EQ(exact.out, "C[DG]S+[LO]\nexact: read back with --notation lpe it is the same class\n");
  // Paste the LPE back in: the same class, so the same minimal DFA (DOT titles aside).
  const std::string lpe = exact.out.substr(0, exact.out.find('\n'));
  auto dot = [](std::string text, const std::string& title) {
    for (std::size_t at; (at = text.find(title)) != std::string::npos;) text.replace(at, title.size(), "TITLE");
    return text;
  };
  EXPECT_EQ(dot(pathex({"explain", "--dot", "--notation", "lpe", lpe}).out, lpe),
            dot(pathex({"explain", "--dot", "L..S+D..E"}).out, "L..S+D..E"));

  const CliRun approx = pathex({"explain", "--emit", "lpe", "LSDSDE"});
  EXPECT_EQ(approx.out,
            "CL\napproximate: the LPE matches more paths than the class\n"
            "  light types: the class has only point lights; an LPE's L is every light\n"
            "  sensor types: the class has only orthographic sensors; an LPE's C is every sensor\n"
            "  for example LDDDDE matches the LPE but not the class\n");
  const nlohmann::json j = nlohmann::json::parse(pathex({"explain", "--emit", "lpe", "--json", "LSDSDE"}).out);
  EXPECT_EQ(j["lpe"], "CL");
  EXPECT_EQ(j["exact"], false);
  EXPECT_EQ(j["example"], "LDDDDE");
  EXPECT_EQ(j["losses"].size(), 2u);

  EXPECT_EQ(pathex({"explain", "--emit", "lpe", "LDDE"}).out, "no LPE: the class is empty, there is no path to select\n");
  EXPECT_EQ(pathex({"explain", "--emit", "dot", "LDDE"}).code, 2);
}

TEST(LpeCli, HeckbertHintOnStderr) {
  const CliRun r = pathex({"explain", "LSDE"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err,
            "pathex: hint: 'LSDE' matches no path in full notation, which writes two letters for each light and sensor; "
            "for Heckbert's classic L…E add --notation heckbert\n");
  const CliRun q = pathex({"query", "--renderer", "bdpt", "LS+DE"});
  EXPECT_EQ(q.err,
            "pathex: hint: 'LS+DE' matches only paths from a laser (LSS…) in full notation, which writes two letters for "
            "each light and sensor; for Heckbert's classic L…E add --notation heckbert\n");
  EXPECT_EQ(pathex({"explain", "--notation", "heckbert", "LSDE"}).err, "");
  EXPECT_EQ(pathex({"explain", "LSDSDE"}).err, "");
}

}  // namespace
