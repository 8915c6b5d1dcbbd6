// The `pathex` binary end to end for the expression commands (explain, match, classify): exact
// stdout, stderr and exit codes, JSON keys and values, counts against their closed form, every
// --help, and the located errors of the grammar corpus as the user sees them (caret and all).
// Runs the real executable (PATHEX_BINARY) from the source directory, so sample paths are
// relative as in the README.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;

using pathex::test::CliRun;

fs::path temp_dir() { return pathex::test::scratch_dir(); }
void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }
std::string slurp(const fs::path& p) { return pathex::test::read_file(p); }

// Runs pathex with `args` (each passed as one argument) and `input` on stdin.
CliRun pathex(const std::vector<std::string>& args, const std::string& input = "") {
  return pathex::test::run_pathex_args(args, input);
}

nlohmann::json load_json(const std::string& relative) {
  return nlohmann::json::parse(slurp(fs::path(PATHEX_SOURCE_DIR) / relative));
}

// Strings of m scattering letters with no two adjacent D: Fibonacci F(m + 2).
std::uint64_t no_dd(int m) {
  std::uint64_t a = 1, b = 2;  // m = 0, m = 1
  for (int i = 0; i < m; ++i) {
    const std::uint64_t c = a + b;
    a = b;
    b = c;
  }
  return a;
}

// --- explain ---

TEST(CliExplain, LocalClassText) {
  const CliRun r = pathex({"explain", "L.*DD.*E"});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out,
            "expression    L.*DD.*E\n"
            "normal form   L.*DD.*E\n"
            "notation      full\n"
            "minimal DFA   12 states (11 live)\n"
            "language      infinite\n"
            "members by length (letters: count, up to 12)\n"
            "  6: 8 7: 19 8: 43 9: 94 10: 201 11: 423 12: 880\n"
            "shortest members\n"
            "  LDDDDE   chains DD(0..1) DD(1..2) DD(2..3)\n"
            "  LDDDSE   chains DD(0..1) DD(1..2) DS(2..3)\n"
            "  LDDSDE   chains DD(0..1) DSD(1..3)\n"
            "  LDDSSE   chains DD(0..1) DSS(1..3)\n"
            "  LDSDDE   chains DSD(0..2) DD(2..3)\n");
}

TEST(CliExplain, LocalClassJson) {
  const CliRun r = pathex({"explain", "--json", "L.*DD.*E"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"counts_by_length", "dfa_states", "empty", "expression", "eye_first",
                                            "finite", "live_states", "max_len", "normal_form", "notation",
                                            "shortest_members"}));
  EXPECT_EQ(j["expression"], "L.*DD.*E");
  EXPECT_EQ(j["normal_form"], "L.*DD.*E");
  EXPECT_EQ(j["notation"], "full");
  EXPECT_EQ(j["eye_first"], false);
  EXPECT_EQ(j["dfa_states"], 12);
  EXPECT_EQ(j["live_states"], 11);
  EXPECT_EQ(j["empty"], false);
  EXPECT_EQ(j["finite"], false);
  EXPECT_EQ(j["max_len"], 12);
  // Lengths 6, 7, 8 by hand; every length against 2^m minus the strings without DD.
  const auto& counts = j["counts_by_length"];
  ASSERT_EQ(counts.size(), 7u);
  EXPECT_EQ(counts[0], (nlohmann::json{{"length", 6}, {"count", 8}}));
  EXPECT_EQ(counts[1], (nlohmann::json{{"length", 7}, {"count", 19}}));
  EXPECT_EQ(counts[2], (nlohmann::json{{"length", 8}, {"count", 43}}));
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const int m = static_cast<int>(i) + 4;  // scattering letters
    EXPECT_EQ(counts[i]["length"], m + 2);
    EXPECT_EQ(counts[i]["count"].get<std::uint64_t>(), (std::uint64_t{1} << m) - no_dd(m)) << "m = " << m;
  }
  const auto& members = j["shortest_members"];
  ASSERT_EQ(members.size(), 5u);
  EXPECT_EQ(members[0]["path"], "LDDDDE");
  EXPECT_EQ(members[0]["chains"], nlohmann::json::parse(R"([{"letters":"DD","from":0,"to":1},
      {"letters":"DD","from":1,"to":2},{"letters":"DD","from":2,"to":3}])"));
  EXPECT_EQ(members[4]["path"], "LDSDDE");
  EXPECT_EQ(members[4]["chains"],
            nlohmann::json::parse(R"([{"letters":"DSD","from":0,"to":2},{"letters":"DD","from":2,"to":3}])"));
}

TEST(CliExplain, EyeFirstDenotesTheReversedPaths) {
  // ED*SL reversed is LSD*E: the universe asks for at least three D, one path per length.
  const CliRun r = pathex({"explain", "--members", "2", "ED*SL"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "expression    ED*SL\n"
            "normal form   ED*SL   (eye-first: denotes the reversed paths)\n"
            "notation      full\n"
            "minimal DFA   8 states (7 live)\n"
            "language      infinite\n"
            "members by length (letters: count, up to 12)\n"
            "  6: 1 7: 1 8: 1 9: 1 10: 1 11: 1 12: 1\n"
            "shortest members\n"
            "  LSDDDE   chains SD(0..1) DD(1..2) DD(2..3)\n"
            "  LSDDDDE   chains SD(0..1) DD(1..2) DD(2..3) DD(3..4)\n");
  const nlohmann::json j = nlohmann::json::parse(pathex({"explain", "--json", "E.*DD.*L"}).out);
  EXPECT_EQ(j["eye_first"], true);
  EXPECT_EQ(j["dfa_states"], 12);  // the same class as L.*DD.*E
  EXPECT_EQ(j["shortest_members"][0]["path"], "LDDDDE");
}

TEST(CliExplain, DotIsGraphviz) {
  const CliRun r = pathex({"explain", "--dot", "LDS*DE"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("digraph pathex {\n", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("label=\"LDS*DE\""), std::string::npos) << r.out;
  ASSERT_GE(r.out.size(), 2u);
  EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n");
}

TEST(CliExplain, HeckbertWithPointLightAndPinhole) {
  // Classic L w E becomes L xy w yx E: point light SD, pinhole DS.
  const CliRun one = pathex({"explain", "--json", "--notation", "heckbert", "--light", "point", "--sensor", "pinhole", "LSDE"});
  ASSERT_EQ(one.code, 0) << one.err;
  const nlohmann::json j = nlohmann::json::parse(one.out);
  EXPECT_EQ(j["notation"], "heckbert");
  EXPECT_EQ(j["finite"], true);
  EXPECT_EQ(j["counts_by_length"], nlohmann::json::parse(R"([{"length":8,"count":1}])"));
  ASSERT_EQ(j["shortest_members"].size(), 1u);
  EXPECT_EQ(j["shortest_members"][0]["path"], "LSDSDDSE");

  const CliRun plus =
      pathex({"explain", "--members", "3", "--notation", "heckbert", "--light", "point", "--sensor", "pinhole", "LS+DE"});
  ASSERT_EQ(plus.code, 0) << plus.err;
  // L SD S+ D DS E: the start, one state after each of its eight letters (the S+ one loops), dead.
  EXPECT_EQ(plus.out,
            "expression    LS+DE\n"
            "normal form   LS+DE\n"
            "notation      heckbert\n"
            "minimal DFA   10 states (9 live)\n"
            "language      infinite\n"
            "members by length (letters: count, up to 12)\n"
            "  8: 1 9: 1 10: 1 11: 1 12: 1\n"
            "shortest members\n"
            "  LSDSDDSE   chains SD(0..1) DSD(1..3) DD(3..4) DS(4..5)\n"
            "  LSDSSDDSE   chains SD(0..1) DSSD(1..4) DD(4..5) DS(5..6)\n"
            "  LSDSSSDDSE   chains SD(0..1) DSSSD(1..5) DD(5..6) DS(6..7)\n");

  // All four light and sensor types by default: 16 full paths for one classic one.
  const nlohmann::json all = nlohmann::json::parse(pathex({"explain", "--json", "--notation", "heckbert", "LSDE"}).out);
  EXPECT_EQ(all["counts_by_length"], nlohmann::json::parse(R"([{"length":8,"count":16}])"));
}

TEST(CliExplain, NamesFromAClassFile) {
  const CliRun r = pathex({"explain", "--members", "1", "--classes", "samples/classes/basic.json", "$caustic-hard"});
  ASSERT_EQ(r.code, 0) << r.err;
  // Length 8 (k = 3): c2 c3 = SD; c0 c1 is DS, SD or SS (no DD), c4 = S after the D, c5 free: 3 * 2.
  EXPECT_EQ(r.out,
            "expression    $caustic-hard\n"
            "normal form   L..S+D.*..E&~(L.*DD.*E)\n"
            "notation      full\n"
            "minimal DFA   12 states (11 live)\n"
            "language      infinite\n"
            "members by length (letters: count, up to 12)\n"
            "  8: 6 9: 15 10: 30 11: 54 12: 93\n"
            "shortest members\n"
            "  LDSSDSDE   chains DSSD(0..3) DSD(3..5)\n");
}

// Every entry of the invalid corpus, as the user sees it: the message, then the expression and a
// caret under the column the corpus names, exit code 2, nothing on stdout.
TEST(CliExplain, CorpusErrorsWithCaret) {
  const nlohmann::json corpus = load_json("grammar/corpus/invalid.json");
  for (const auto& entry : corpus) {
    const std::string expr = entry["expr"];
    const int column = entry["column"];
    const CliRun r = pathex({"explain", expr});
    EXPECT_EQ(r.code, 2) << expr;
    EXPECT_EQ(r.out, "") << expr;
    std::string want = "pathex: error: column " + std::to_string(column) + ": " + entry["message"].get<std::string>() + "\n";
    if (!expr.empty()) {
      std::string caret;
      for (int i = 1; i < column; ++i) caret += expr[static_cast<std::size_t>(i - 1)] == '\t' ? '\t' : ' ';
      want += "  " + expr + "\n  " + caret + "^\n";
    }
    EXPECT_EQ(r.err, want) << expr;
  }
}

TEST(CliExplain, ParseErrorExactly) {
  const CliRun r = pathex({"explain", "L(DD"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err,
            "pathex: error: column 2: missing ')' to close this '('\n"
            "  L(DD\n"
            "   ^\n");
}

TEST(CliExplain, LimitOptionsAreHonouredAndNamed) {
  const CliRun repeat = pathex({"explain", "--max-repeat", "5", "LS{6}E"});
  EXPECT_EQ(repeat.code, 2);
  EXPECT_EQ(repeat.err,
            "pathex: error: column 4: repetition count exceeds the limit of 5 repetitions (raise it with --max-repeat)\n"
            "  LS{6}E\n"
            "     ^\n");
  EXPECT_EQ(pathex({"explain", "--max-repeat", "6", "LS{6}E"}).code, 0);

  const CliRun depth = pathex({"explain", "--max-depth", "3", "~~~S"});
  EXPECT_EQ(depth.code, 2);
  EXPECT_EQ(depth.err,
            "pathex: error: column 3: nesting depth exceeds the limit of 3 levels (raise it with --max-depth)\n"
            "  ~~~S\n"
            "    ^\n");

  const CliRun states = pathex({"explain", "--max-states", "10", "L.*DD.*E"});
  EXPECT_EQ(states.code, 2);
  EXPECT_EQ(states.err,
            "pathex: error: column 7: the automaton exceeds the limit of 10 states (raise it with --max-states)\n"
            "  L.*DD.*E\n"
            "        ^\n");
}

// (S|D)*S(S|D){40} is "the 41st letter from the end is S": its DFA has 2^41 states. The subset
// construction must stop at --max-states and say so (how much work that takes is asserted on the
// budget's counter in tests/automata/budget_test.cpp, not on a clock).
TEST(CliLimits, ExponentialDfaStopsAtMaxStatesNamingIt) {
  const CliRun r = pathex({"explain", "(S|D)*S(S|D){40}"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err,
            "pathex: error: column 1: the DFA exceeds the limit of 100000 states (raise it with --max-states)\n"
            "  (S|D)*S(S|D){40}\n"
            "  ^\n");
}

TEST(CliExplain, NotationAndUsageErrors) {
  const CliRun mixed = pathex({"explain", "--notation", "heckbert", "LS+DE|$local"});
  EXPECT_EQ(mixed.code, 2);
  EXPECT_EQ(mixed.err,
            "pathex: error: column 7: '$local' is written in full notation and cannot be used in a Heckbert-notation "
            "expression\n"
            "  LS+DE|$local\n"
            "        ^\n");
  // The caret goes under the reference in the other notation, not under the first '$'.
  const fs::path mixed_file = temp_dir() / "mixed.json";
  write(mixed_file, R"({"classes": [{"name": "h", "expr": "LSDE", "notation": "heckbert"}]})");
  const CliRun second = pathex({"explain", "--notation", "heckbert", "--classes", mixed_file.string(), "$h | $local"});
  EXPECT_EQ(second.code, 2);
  EXPECT_EQ(second.err,
            "pathex: error: column 6: '$local' is written in full notation and cannot be used in a Heckbert-notation "
            "expression\n"
            "  $h | $local\n"
            "       ^\n");
  EXPECT_EQ(pathex({"explain", "--notation", "heckbert", "--classes", mixed_file.string(), "$h|LS+DE"}).code, 0);

  const CliRun light = pathex({"explain", "--light", "point", "LSDE"});
  EXPECT_EQ(light.code, 2);
  EXPECT_EQ(light.err, "pathex: error: --light and --sensor apply to --notation heckbert and lpe only\n");
  const CliRun bad_light = pathex({"explain", "--notation", "heckbert", "--light", "candle", "LSDE"});
  EXPECT_EQ(bad_light.code, 2);
  EXPECT_EQ(bad_light.err,
            "pathex: error: --light: unknown light type 'candle', expected area, distant, point or laser\n");
}

// --- class files ---

TEST(CliClassFile, ErrorsNameTheFileAndPointer) {
  const fs::path bad_expr = temp_dir() / "bad-expr.json";
  write(bad_expr, R"({"classes": [{"name": "a", "expr": "LD+E"}, {"name": "b", "expr": "$a & L(DS"}]})");
  const CliRun r = pathex({"explain", "--classes", bad_expr.string(), "LDE"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + bad_expr.string() +
                       ":/classes/1/expr: column 7: missing ')' to close this '('\n"
                       "  $a & L(DS\n"
                       "        ^\n");

  const fs::path later = temp_dir() / "later.json";
  write(later, R"({"classes": [{"name": "a", "expr": "$b | LDDDDE"}, {"name": "b", "expr": "LD+E"}]})");
  const CliRun order = pathex({"explain", "--classes", later.string(), "LDE"});
  EXPECT_EQ(order.code, 2);
  EXPECT_EQ(order.err, "pathex: error: " + later.string() +
                           ":/classes/0/expr: column 1: unknown class name '$b', expected a built-in name or one "
                           "defined earlier in the class file\n"
                           "  $b | LDDDDE\n"
                           "  ^\n");

  const fs::path bad_key = temp_dir() / "bad-key.json";
  write(bad_key, R"({"classes": [{"name": "a", "exp": "LD+E"}]})");
  const CliRun key = pathex({"explain", "--classes", bad_key.string(), "LDE"});
  EXPECT_EQ(key.code, 2);
  EXPECT_EQ(key.err, "pathex: error: " + bad_key.string() +
                         ":/classes/0/exp: unknown key 'exp', expected one of name, expr, notation, description, render\n");
}

TEST(CliClassFile, TwentyHasTwentyClassesThatAllCompile) {
  const nlohmann::json twenty = load_json("samples/classes/twenty.json");
  EXPECT_EQ(twenty["classes"].size(), 20u);
  const CliRun r = pathex({"classify", "--classes", "samples/classes/twenty.json"}, "LDDDDE\nLSDSDDSE\nLSDDSDDSSSDE\n");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out,
            "LDDDDE\tlight-visible from-area to-lens\n"
            "LSDSDDSE\tmulti-bounce caustics caustic-local from-point to-pinhole\n"
            "LSDDSDDSSSDE\tmulti-bounce seen-in-mirror from-point to-ortho\n");
}

// --- match ---

TEST(CliMatch, ExitCodes) {
  const CliRun all = pathex({"match", "L.*DD.*E", "LDDDDE", "LSDSDDSE"});
  EXPECT_EQ(all.code, 0);
  EXPECT_EQ(all.out, "match     LDDDDE\nmatch     LSDSDDSE\n");
  EXPECT_EQ(all.err, "");

  const CliRun some = pathex({"match", "L.*DD.*E", "LDDDDE", "LSDSDE"});
  EXPECT_EQ(some.code, 1);
  EXPECT_EQ(some.out, "match     LDDDDE\nno match  LSDSDE\n");
  EXPECT_EQ(some.err, "");

  const CliRun bad_path = pathex({"match", "L.*DD.*E", "LDDDDE", "LDXE"});
  EXPECT_EQ(bad_path.code, 2);
  EXPECT_EQ(bad_path.out, "match     LDDDDE\n");
  EXPECT_EQ(bad_path.err,
            "pathex: error: column 3: unexpected character 'X', expected one of L E S D\n"
            "  LDXE\n"
            "    ^\n");

  const CliRun bad_expr = pathex({"match", "L.*DD.*E)", "LDDDDE"});
  EXPECT_EQ(bad_expr.code, 2);
  EXPECT_EQ(bad_expr.out, "");
  EXPECT_EQ(bad_expr.err,
            "pathex: error: column 9: unmatched ')'\n"
            "  L.*DD.*E)\n"
            "          ^\n");

  // Eye-first expressions match the reversed paths.
  EXPECT_EQ(pathex({"match", "ED*SL", "LSDDDE"}).code, 0);
  EXPECT_EQ(pathex({"match", "ED*SL", "LDDDSE"}).code, 1);
}

// --- classify ---

const char* const kClassifyInput =
    "LDDSDDDE\n"
    "LSDSDDSE\n"
    "LSDxDE\n"
    "LDDDSDSDSE\n"
    "LSDSDSDE\n"
    "\n"
    "LSDSDE\r\n";

TEST(CliClassify, BasicClassesWithMalformedLines) {
  const CliRun r = pathex({"classify", "--classes", "samples/classes/basic.json"}, kClassifyInput);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out,
            "LDDSDDDE\tcaustic-local mirror-classic\n"
            "LSDSDDSE\tcaustic-local mirror-classic\n"
            "LDDDSDSDSE\tsds camera-specular\n"
            "LSDSDSDE\tcaustic-hard not-local mirror-classic\n"
            "LSDSDE\tnot-local\n");
  EXPECT_EQ(r.err,
            "pathex: error: stdin:3: column 4: unexpected character 'x', expected one of L E S D\n"
            "  LSDxDE\n"
            "     ^\n");  // line 6 is blank: skipped, not an error
}

TEST(CliClassify, JsonLines) {
  const CliRun r = pathex({"classify", "--json", "--classes", "samples/classes/basic.json"}, kClassifyInput);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "");
  std::vector<nlohmann::json> lines;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(lines.size(), 6u);  // the blank line 6 is skipped
  EXPECT_EQ(lines[0], nlohmann::json::parse(R"({"line":1,"path":"LDDSDDDE","classes":["caustic-local","mirror-classic"]})"));
  EXPECT_EQ(lines[2], nlohmann::json::parse(R"({"line":3,"path":"LSDxDE",
      "error":"stdin:3: column 4: unexpected character 'x', expected one of L E S D\n  LSDxDE\n     ^"})"));
  EXPECT_EQ(lines[3], nlohmann::json::parse(R"({"line":4,"path":"LDDDSDSDSE","classes":["sds","camera-specular"]})"));
  EXPECT_EQ(lines[5], nlohmann::json::parse(R"({"line":7,"path":"LSDSDE","classes":["not-local"]})"));
}

TEST(CliClassify, BuiltinsWithoutAClassFile) {
  const CliRun r = pathex({"classify"}, "LDDDDE\nLSDSDDSE\nLDDDDDE\nLSDSDE\n");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out,
            "LDDDDE\tall local emission\n"
            "LSDSDDSE\tall local indirect caustic\n"
            "LDDDDDE\tall local direct\n"
            "LSDSDE\tall emission\n");
}

// --- help ---

TEST(CliHelp, EverySubcommandShowsAnExample) {
  for (const char* sub : {"explain", "match", "classify", "query", "check", "renderers"}) {
    const CliRun r = pathex({sub, "--help"});
    EXPECT_EQ(r.code, 0) << sub;
    EXPECT_NE(r.out.find("Example:"), std::string::npos) << sub << ":\n" << r.out;
  }
  const CliRun top = pathex({"--help"});
  EXPECT_EQ(top.code, 0);
  EXPECT_NE(top.out.find("Example:"), std::string::npos);
  // The limits are options with their ranges and defaults shown.
  const CliRun explain = pathex({"explain", "--help"});
  for (const char* option : {"--max-states UINT:UINT in [1 - 10000000]=100000", "--max-depth INT:INT in [1 - 1000]=100",
                             "--max-repeat INT:INT in [1 - 100000]=1000", "--max-length UINT:UINT in [1 - 100000000]=100000",
                             "--max-work UINT:UINT in [1 - 4000000000]=20000000",
                             "--max-file-size UINT:UINT in [1 - 17179869184]=67108864"})
    EXPECT_NE(explain.out.find(option), std::string::npos) << option << "\n" << explain.out;
}

}  // namespace
