// Issue 36: bench/stat_sweep.py runs every statistical test over many seeds, but only the tests in
// its STATISTICAL_TESTS registry. A test that takes its seed from test::stat_seed — in its own body
// or through a function of its file that does — and is not registered would never be swept; this
// test finds such tests by reading the test sources and the registry.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_run.h"

namespace pathex {
namespace {

namespace fs = std::filesystem;

using test::read_file;  // tests/support/cli_run.h: the tests' one file reader

// A top-level block of a test file: a function or a TEST, from its first line to the `}` that
// closes it at column 0 (the project's format puts it there).
struct Block {
  std::string name;  // the function's name, or "Suite.Name" for a TEST
  bool is_test = false;
  std::string body;
};

std::vector<Block> blocks_of(const std::string& text) {
  static const std::regex test_head(R"(^(?:TEST|TEST_F|TEST_P)\((\w+),\s*(\w+)\))");
  static const std::regex function_head(R"(^[A-Za-z][\w:<>,&*\s]*?\b(\w+)\([^;]*$)");
  std::vector<Block> blocks;
  std::istringstream in(text);
  std::string line;
  Block* open = nullptr;
  std::string pending;       // a function's head whose `{` is on a later line (parameters wrapped)
  std::string pending_name;
  while (std::getline(in, line)) {
    std::smatch m;
    if (open == nullptr && !pending_name.empty()) {
      if (line.rfind(' ', 0) != 0 || line.find(';') != std::string::npos) {
        pending_name.clear();  // not a wrapped head after all (a declaration, or code at column 0)
      } else if (line.find('{') != std::string::npos) {
        blocks.push_back({pending_name, false, pending});
        open = &blocks.back();
        pending_name.clear();
      } else {
        pending += line + "\n";
        continue;
      }
    }
    if (open == nullptr) {
      const bool head_like = line.rfind("namespace", 0) != 0 && line.rfind("struct", 0) != 0 && line.rfind("class", 0) != 0;
      if (std::regex_search(line, m, test_head)) {
        blocks.push_back({m[1].str() + "." + m[2].str(), true, ""});
        open = &blocks.back();
      } else if (head_like && line.find('{') != std::string::npos && std::regex_search(line, m, function_head)) {
        blocks.push_back({m[1].str(), false, ""});
        open = &blocks.back();
      } else if (head_like && line.find('{') == std::string::npos && std::regex_search(line, m, function_head) &&
                 line.back() == ',') {
        pending_name = m[1].str();
        pending = line + "\n";
        continue;
      }
    }
    if (open != nullptr) {
      open->body += line + "\n";
      if (line == "}" || line.rfind("}  //", 0) == 0 || (line.back() == '}' && line.find('{') != std::string::npos && open->body == line + "\n"))
        open = nullptr;
    }
  }
  return blocks;
}

// test::stat_seed or test::stat_seed_from (tests/support/stat_seed.h).
bool calls_stat_seed(const std::string& body) {
  return body.find("stat_seed(") != std::string::npos || body.find("stat_seed_from(") != std::string::npos;
}

// The TESTs of `text` that reach test::stat_seed: directly, or through the file's functions.
std::set<std::string> seeded_tests(const std::string& text) {
  const std::vector<Block> blocks = blocks_of(text);
  std::set<std::string> seeded_functions;
  for (bool grew = true; grew;) {
    grew = false;
    for (const Block& b : blocks) {
      if (b.is_test || seeded_functions.count(b.name)) continue;
      bool seeded = calls_stat_seed(b.body);
      for (const std::string& f : seeded_functions)
        if (std::regex_search(b.body, std::regex("\\b" + f + "\\("))) seeded = true;
      if (seeded) grew = seeded_functions.insert(b.name).second || grew;
    }
  }
  std::set<std::string> tests;
  for (const Block& b : blocks) {
    if (!b.is_test) continue;
    bool seeded = calls_stat_seed(b.body);
    for (const std::string& f : seeded_functions)
      if (std::regex_search(b.body, std::regex("\\b" + f + "\\("))) seeded = true;
    if (seeded) tests.insert(b.name);
  }
  return tests;
}

// GoogleTest's filter pattern: `*` any run, `?` one character (one pattern, no `:` or `-`).
bool glob(const std::string& pattern, const std::string& name) {
  std::string re;
  for (char c : pattern) re += c == '*' ? std::string(".*") : c == '?' ? std::string(".") : std::regex_replace(std::string(1, c), std::regex(R"([.^$|()\[\]{}+\\])"), R"(\$&)");
  return std::regex_match(name, std::regex(re));
}

TEST(StatRegistry, ParsesTestsAndTheFunctionsTheyCall) {
  const std::string text =
      "std::uint64_t seed() { return 1; }\n"
      "RenderOptions options() {\n  RenderOptions o;\n  o.seed = test::stat_seed(35);\n  return o;\n}\n"
      "double mean() {\n  return render(options()).mean;\n}\n"
      "TEST(A, ThroughTwoFunctions) {\n  EXPECT_EQ(mean(), 1);\n}\n"
      "TEST(A, Direct) {\n  EXPECT_EQ(test::stat_seed(3), 3u);\n}\n"
      "TEST(A, NotSeeded) {\n  EXPECT_EQ(seed(), 1u);\n}\n"
      "Rendered wrapped(const std::string& scene,\n                 std::uint64_t seed = 7) {\n"
      "  return render(scene, test::stat_seed_from(seed));\n}\n"
      "TEST(A, ThroughAWrappedHead) {\n  EXPECT_EQ(wrapped(\"x\").mean, 1);\n}\n"
      "double declared(int a,\n                int b);\n"
      "TEST(A, CallsADeclarationOnly) {\n  EXPECT_EQ(declared(1, 2), 3);\n}\n";
  EXPECT_EQ(seeded_tests(text), (std::set<std::string>{"A.Direct", "A.ThroughTwoFunctions", "A.ThroughAWrappedHead"}));
  EXPECT_TRUE(glob("Sampling.*", "Sampling.EverySetting"));
  EXPECT_TRUE(glob("*", "Anything.AtAll"));
  EXPECT_FALSE(glob("Sampling.Every", "Sampling.EverySetting"));
  EXPECT_FALSE(glob("Bias.*", "BiasCli.X"));
}

TEST(StatRegistry, EverySeededTestIsSwept) {
  const fs::path root = PATHEX_SOURCE_DIR;
  const std::string registry = read_file(root / "bench/stat_sweep.py");
  std::multimap<std::string, std::string> entries;  // executable -> filter
  static const std::regex entry(R"re(\("(\w+)", "([^"]+)"\))re");
  for (auto it = std::sregex_iterator(registry.begin(), registry.end(), entry); it != std::sregex_iterator(); ++it)
    entries.emplace((*it)[1].str(), (*it)[2].str());
  ASSERT_GT(entries.size(), 10u) << "bench/stat_sweep.py: STATISTICAL_TESTS not found";

  std::vector<std::string> missing;
  std::size_t seeded = 0;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(root / "tests")) {
    const std::string name = e.path().filename().string();
    if (!e.is_regular_file() || name.size() < 9 || name.substr(name.size() - 9) != "_test.cpp") continue;
    const std::string exe = e.path().stem().string();
    if (exe == "stat_registry_test") continue;  // this file names stat_seed in its own test data
    for (const std::string& test : seeded_tests(read_file(e.path()))) {
      ++seeded;
      bool swept = false;
      for (auto [it, end] = entries.equal_range(exe); it != end; ++it) swept = swept || glob(it->second, test);
      if (!swept) missing.push_back(exe + " " + test);
    }
  }
  EXPECT_GT(seeded, 20u) << "the parser found too few seeded tests to be trusted";
  std::string list;
  for (const std::string& m : missing) list += "\n  " + m;
  EXPECT_TRUE(missing.empty()) << "seeded tests that bench/stat_sweep.py does not sweep (add them to STATISTICAL_TESTS):" << list;
}

}  // namespace
}  // namespace pathex
