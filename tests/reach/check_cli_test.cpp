// `pathex check` end to end: exit codes, failure messages with counterexamples, JSON report, and
// the JUnit XML parsed back with pugixml and validated against the structure CI readers expect.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "support/cli_run.h"

namespace {

using pathex::test::CliRun;

// Standard output, then standard error, as one text.
CliRun run(const std::string& args) {
  CliRun r = pathex::test::run_pathex(args);
  r.out += r.err;
  return r;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("pathex-check-" + std::to_string(::getpid()) + "-" + name)).string();
}

TEST(CheckCli, PassingFileExitsZero) {
  const CliRun r = run("check tests/reach/checks/pass.json");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("PASS  ortho-connector: LSDSDE is reachable (reachable)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("check: 6 passed, 0 failed\n"), std::string::npos) << r.out;
}

TEST(CheckCli, FailingFileExitsOneWithCounterexamples) {
  const CliRun r = run("check tests/reach/checks/fail.json");
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("FAIL  ptnee-caustics: LSDSDE is reachable (unreachable)\n"
                       "      shortest counterexample LSDSDE, chains SD(0..1) DSD(1..3); no DD join: the point light "
                       "fixes x0 and the orthographic sensor fixes the last direction\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("FAIL  ptnee-caustics: covers the scene (partial)\n"
                       "      shortest counterexample LDSDDE, chains DSD(0..2) DD(2..3); its DD joins (c2..c3) are not "
                       "where pt-nee joins: (0, DD, 2..), (1, DD, 2..)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("check: 1 passed, 3 failed\n"), std::string::npos) << r.out;
}

TEST(CheckCli, BadFileExitsTwoNamingThePointer) {
  const CliRun r = run("check tests/reach/checks/bad.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out,
            "pathex: error: tests/reach/checks/bad.json:/cases/0/require/0/verdict: unknown verdict 'reachible', "
            "expected reachable, not-unreachable, unreachable, partial or empty\n");
  EXPECT_EQ(run("check does/not/exist.json").code, 2);
}

TEST(CheckCli, JsonReport) {
  const CliRun r = run("check --json tests/reach/checks/fail.json");
  EXPECT_EQ(r.code, 1);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["passed"], 1);
  EXPECT_EQ(j["failed"], 3);
  ASSERT_EQ(j["requirements"].size(), 4u);
  const auto& first = j["requirements"][0];
  EXPECT_EQ(first["case"], "ptnee-caustics");
  EXPECT_EQ(first["passed"], false);
  EXPECT_EQ(first["verdict"], "unreachable");
  EXPECT_EQ(first["max_bounces"], 8);
  EXPECT_EQ(first["counterexample"]["path"], "LSDSDE");
  EXPECT_EQ(first["counterexample"]["chains"][1]["letters"], "DSD");
  EXPECT_EQ(first["counterexample"]["chains"][1]["connectors"][0], "ortho-projection");
  EXPECT_EQ(j["requirements"][3]["counterexample"]["strategies"][0], "bdpt");
}

TEST(CheckCli, JUnitParsesBackAndValidates) {
  const std::string out = temp_path("junit.xml");
  const CliRun r = run("check tests/reach/checks/fail.json --junit '" + out + "'");
  EXPECT_EQ(r.code, 1);
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_file(out.c_str());
  ASSERT_TRUE(parsed) << parsed.description();
  const pugi::xml_node suites = doc.child("testsuites");
  ASSERT_TRUE(suites);
  EXPECT_EQ(suites.attribute("tests").as_int(), 4);
  EXPECT_EQ(suites.attribute("failures").as_int(), 3);
  const pugi::xml_node suite = suites.child("testsuite");
  ASSERT_TRUE(suite);
  EXPECT_STREQ(suite.attribute("name").value(), "tests/reach/checks/fail.json");
  int cases = 0, failures = 0;
  for (pugi::xml_node tc : suite.children("testcase")) {
    ++cases;
    EXPECT_TRUE(tc.attribute("classname"));
    EXPECT_TRUE(tc.attribute("name"));
    EXPECT_GE(tc.attribute("time").as_double(-1.0), 0.0);
    if (pugi::xml_node f = tc.child("failure")) {
      ++failures;
      EXPECT_FALSE(std::string(f.attribute("message").value()).empty());
      EXPECT_NE(std::string(f.child_value()).find("shortest counterexample"), std::string::npos);
    }
  }
  EXPECT_EQ(cases, 4);
  EXPECT_EQ(failures, 3);
  const pugi::xml_node second = suite.find_child_by_attribute("testcase", "name", "$direct is not-unreachable");
  ASSERT_TRUE(second);
  EXPECT_FALSE(second.child("failure"));
  std::filesystem::remove(out);
}

TEST(CheckCli, JUnitToAnUnwritablePlaceFailsWithoutPartialFile) {
  const CliRun r = run("check tests/reach/checks/pass.json --junit /nonexistent-dir/report.xml");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("/nonexistent-dir/report.xml: cannot create a temporary file beside the output"), std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists("/nonexistent-dir/report.xml"));
}

TEST(QueryCli, JsonKeysAndSideBySide) {
  const CliRun r = run("query --json --renderer pt-nee --renderer bdpt+ortho LSDSDE");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 2u);
  for (const char* key : {"expression", "renderer", "verdict", "reachable_witnesses", "unreachable_witnesses",
                          "counts_by_length", "finite"})
    EXPECT_TRUE(j[0].contains(key)) << key;
  EXPECT_EQ(j[0]["renderer"], "pt-nee");
  EXPECT_EQ(j[0]["verdict"], "unreachable");
  EXPECT_EQ(j[0]["unreachable_witnesses"][0]["path"], "LSDSDE");
  EXPECT_EQ(j[0]["unreachable_witnesses"][0]["reason"],
            "no DD join: the point light fixes x0 and the orthographic sensor fixes the last direction");
  EXPECT_EQ(j[1]["renderer"], "bdpt+ortho");
  EXPECT_EQ(j[1]["verdict"], "reachable");
  EXPECT_EQ(j[1]["reachable_witnesses"][0]["strategies"][0], "ortho-splat");
  EXPECT_EQ(j[1]["counts_by_length"][0]["length"], 6);
  EXPECT_EQ(j[1]["counts_by_length"][0]["reachable"], 1);
}

TEST(QueryCli, TableTextAndErrors) {
  const CliRun r = run("query --renderer pt-nee --renderer bdpt LSDSDE LDDDDSE");
  ASSERT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("class     pt-nee       bdpt         \n"
                       "LSDSDE    unreachable  unreachable  \n"
                       "LDDDDSE   reachable    reachable    \n"),
            std::string::npos)
      << r.out;
  const CliRun bad = run("query --renderer nosuch LSDSDE");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.out.find("unknown renderer 'nosuch': not a built-in profile (pt, pt-nee, lt, bdpt,"), std::string::npos);
  const CliRun badexpr = run("query 'LSD(SDE'");
  EXPECT_EQ(badexpr.code, 2);
  EXPECT_EQ(badexpr.out, "pathex: error: column 4: missing ')' to close this '('\n  LSD(SDE\n     ^\n");
}

TEST(RenderersCli, ListsEveryBuiltinWithItsLanguage) {
  const CliRun r = run("renderers --json");
  ASSERT_EQ(r.code, 0);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_GE(j.size(), 13u);
  EXPECT_EQ(j[3]["name"], "bdpt");
  EXPECT_EQ(j[3]["reachable"]["equals_local"], true);
  EXPECT_EQ(j[0]["name"], "pt");
  EXPECT_EQ(j[0]["reachable"]["shortest_unreachable"][0], "LDSDDE");
  const CliRun t = run("renderers");
  EXPECT_NE(t.out.find("bdpt\n  Bidirectional path tracing"), std::string::npos);
  EXPECT_NE(t.out.find("  reaches exactly the local paths L.*DD.*E"), std::string::npos);
}

}  // namespace
