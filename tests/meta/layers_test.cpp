// Issue 38: nothing includes a module above it. The library's folders are layers, bottom to top,
// in the order src/CMakeLists.txt lists them in PATHEX_LIB_DIRS (the one place the order is
// written; a subfolder such as trace/joins belongs to its folder), with the command line, cli/, on
// top. This test reads every source file under src/ and fails on an include of a folder that comes
// later in that order, naming the file, the line and both folders; and on a folder of src/ that
// the order does not place.
#include <gtest/gtest.h>

#include <algorithm>
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

// The layers, bottom first: PATHEX_LIB_DIRS's folders (first path component, once each), then cli.
std::vector<std::string> layer_order(const std::string& cmake) {
  const std::regex line(R"(set\(PATHEX_LIB_DIRS ([^)]*)\))");
  std::smatch m;
  std::vector<std::string> order;
  if (!std::regex_search(cmake, m, line)) return order;
  std::istringstream words(m[1].str());
  std::string w;
  while (words >> w) {
    const std::string top = w.substr(0, w.find('/'));
    if (std::find(order.begin(), order.end(), top) == order.end()) order.push_back(top);
  }
  order.push_back("cli");
  return order;
}

struct UpwardInclude {
  std::string where;  // file:line
  std::string from, to;
};

// Every quoted include of a folder of src/ above the including file's folder.
std::vector<UpwardInclude> upward_includes(const fs::path& src, const std::map<std::string, int>& rank) {
  std::vector<UpwardInclude> found;
  const std::regex include(R"(^\s*#\s*include\s*"([a-z_]+)/)");
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(src)) {
    const std::string ext = e.path().extension().string();
    if (!e.is_regular_file() || (ext != ".h" && ext != ".cpp")) continue;
    const std::string rel = fs::relative(e.path(), src).generic_string();
    const std::string folder = rel.substr(0, rel.find('/'));
    const auto own = rank.find(folder);
    if (own == rank.end()) continue;  // reported by the test below
    std::istringstream lines(read_file(e.path()));
    std::string l;
    for (int n = 1; std::getline(lines, l); ++n) {
      std::smatch m;
      if (!std::regex_search(l, m, include)) continue;
      const auto to = rank.find(m[1].str());
      if (to != rank.end() && to->second > own->second)
        found.push_back({"src/" + rel + ":" + std::to_string(n), folder, m[1].str()});
    }
  }
  return found;
}

TEST(Layers, NothingIncludesAFolderAboveIt) {
  const fs::path src = fs::path(PATHEX_SOURCE_DIR) / "src";
  const std::vector<std::string> order = layer_order(read_file(src / "CMakeLists.txt"));
  ASSERT_GT(order.size(), 10u) << "PATHEX_LIB_DIRS not found in src/CMakeLists.txt";
  std::map<std::string, int> rank;
  for (std::size_t i = 0; i < order.size(); ++i) rank[order[i]] = static_cast<int>(i);
  for (const UpwardInclude& u : upward_includes(src, rank))
    ADD_FAILURE() << u.where << ": " << u.from << "/ includes " << u.to << "/, which is above it (src/CMakeLists.txt's "
                  << "PATHEX_LIB_DIRS lists the layers bottom to top)";
}

// cli/ keeps options, printing and exit codes (issue 38): every JSON document a command prints or
// writes is made by the library (io/, output/, check/, measure/), so no file of cli/ includes
// nlohmann.
TEST(Layers, TheCommandLineMakesNoJsonOfItsOwn) {
  const fs::path cli = fs::path(PATHEX_SOURCE_DIR) / "src" / "cli";
  int files = 0;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(cli)) {
    if (!e.is_regular_file()) continue;
    ++files;
    std::istringstream in(read_file(e.path()));
    std::string line;
    for (int n = 1; std::getline(in, line); ++n)
      EXPECT_EQ(line.find("#include <nlohmann/"), std::string::npos)
          << e.path().lexically_relative(fs::path(PATHEX_SOURCE_DIR)).string() << ":" << n << ": " << line;
  }
  EXPECT_GT(files, 10);
}

TEST(Layers, EveryFolderOfSrcHasItsPlace) {
  const fs::path src = fs::path(PATHEX_SOURCE_DIR) / "src";
  const std::vector<std::string> order = layer_order(read_file(src / "CMakeLists.txt"));
  const std::set<std::string> placed(order.begin(), order.end());
  for (const fs::directory_entry& e : fs::directory_iterator(src)) {
    if (e.is_directory()) {
      EXPECT_TRUE(placed.count(e.path().filename().string())) << e.path().filename() << " is not in PATHEX_LIB_DIRS";
    }
  }
}

// README.md's Layout lists the folders of src/ ("      name/  what it holds"), in the layer order:
// `ls src/` and the manual say the same thing.
TEST(Layers, TheReadmesLayoutListsTheFoldersInTheirOrder) {
  const fs::path root = fs::path(PATHEX_SOURCE_DIR);
  const std::vector<std::string> order = layer_order(read_file(root / "src" / "CMakeLists.txt"));
  const std::string readme = read_file(root / "README.md");
  const std::size_t begin = readme.find("\n## Layout\n");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = readme.find("\n## ", begin + 1);
  std::istringstream lines(readme.substr(begin, end - begin));
  const std::regex folder(R"(^      ([a-z_]+)/ )");
  std::vector<std::string> listed;
  std::string l;
  while (std::getline(lines, l)) {
    std::smatch m;
    if (std::regex_search(l, m, folder)) listed.push_back(m[1].str());
  }
  EXPECT_EQ(listed, order);
  std::set<std::string> in_src;
  for (const fs::directory_entry& e : fs::directory_iterator(root / "src"))
    if (e.is_directory()) in_src.insert(e.path().filename().string());
  EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()), in_src);
}

// The check itself: an include running up the order is found, one running down is not.
TEST(Layers, AnUpwardIncludeIsFound) {
  const fs::path dir = fs::temp_directory_path() / "pathex-layers-test";
  fs::remove_all(dir);
  fs::create_directories(dir / "low");
  fs::create_directories(dir / "high");
  std::ofstream(dir / "low" / "a.h") << "#pragma once\n#include \"low/b.h\"\n#include <vector>\n#include \"high/c.h\"\n";
  std::ofstream(dir / "high" / "c.h") << "#pragma once\n#include \"low/a.h\"\n";
  const std::vector<UpwardInclude> found = upward_includes(dir, {{"low", 0}, {"high", 1}});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].where, "src/low/a.h:4");
  EXPECT_EQ(found[0].to, "high");
  EXPECT_EQ(layer_order("set(PATHEX_LIB_DIRS core trace trace/joins io)"),
            (std::vector<std::string>{"core", "trace", "io", "cli"}));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pathex

namespace pathex {
namespace {

namespace fs = std::filesystem;
using test::read_file;

// --- unity builds (src/CMakeLists.txt, PATHEX_UNITY_BUILD): a folder is one translation unit ---
//
// In one unit the files' anonymous namespaces are one namespace, so a file-local function hides,
// in every file after it, a function of the same name declared elsewhere: cli/check.cpp's own
// chains_text (without connectors) once replaced cli/witness_text.h's in query and bias, in CI's
// unity build only. A file-local function's name is therefore never a function declared in a
// header of src/ nor defined outside an anonymous namespace in another file of its unity group.
// (File-local functions of one name in two files overload each other, as `run(const XArgs&)` in
// each command does: a call then picks by its argument types, or fails to compile.)

struct FunctionNames {
  std::set<std::string> file_local;  // defined inside `namespace {`
  std::set<std::string> other;       // defined or declared elsewhere
};

// The names of the functions a file defines or declares at column 0 (this code's style: namespace
// contents are not indented), split by whether they are inside an anonymous namespace.
FunctionNames function_names(const std::string& text) {
  static const std::regex function(R"(^(?:[A-Za-z_][\w:<>,*&]*[ *&]+)+([A-Za-z_]\w*)\()");
  static const std::set<std::string> not_names = {"if", "for", "while", "switch", "return", "operator", "TEST", "main"};
  FunctionNames names;
  std::istringstream lines(text);
  std::string l;
  bool anonymous = false;
  while (std::getline(lines, l)) {
    if (l == "namespace {") anonymous = true;
    else if (anonymous && l.rfind("}  // namespace", 0) == 0) anonymous = false;
    std::smatch m;
    if (l.empty() || l[0] == ' ' || l[0] == '/' || l[0] == '#' || !std::regex_search(l, m, function)) continue;
    if (not_names.count(m[1].str())) continue;
    (anonymous ? names.file_local : names.other).insert(m[1].str());
  }
  return names;
}

// Every file-local function of a unity group that shares its name with a function of a header of
// `src` or of another file of its group: "group/file.cpp: name (also in where)".
std::vector<std::string> unity_hiding(const fs::path& src, const std::vector<std::string>& groups, const std::set<std::string>& skip) {
  std::map<std::string, std::set<std::string>> public_names;  // name -> where
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(src))
    if (e.is_regular_file() && e.path().extension() == ".h")
      for (const std::string& n : function_names(read_file(e.path())).other)
        public_names[n].insert(fs::relative(e.path(), src).generic_string());
  std::vector<std::string> found;
  for (const std::string& g : groups) {
    std::map<std::string, FunctionNames> files;
    for (const fs::directory_entry& e : fs::directory_iterator(src / g)) {
      const std::string rel = g + "/" + e.path().filename().string();
      if (e.is_regular_file() && e.path().extension() == ".cpp" && !skip.count(rel)) files[rel] = function_names(read_file(e.path()));
    }
    for (const auto& [rel, names] : files)
      for (const std::string& n : names.file_local) {
        std::set<std::string> where = public_names.count(n) ? public_names[n] : std::set<std::string>{};
        for (const auto& [other, other_names] : files)
          if (other != rel && other_names.other.count(n)) where.insert(other);
        if (where.empty()) continue;
        std::string list;
        for (const std::string& w : where) list += (list.empty() ? "" : ", ") + w;
        found.push_back(rel + ": " + n + " (also in " + list + ")");
      }
  }
  return found;
}

// PATHEX_UNITY_DIRS and PATHEX_UNITY_SKIP of src/CMakeLists.txt, and cli (one unit of its own).
std::vector<std::string> cmake_list(const std::string& cmake, const std::string& name) {
  const std::regex line("set\\(" + name + " ([^)]*)\\)");
  std::smatch m;
  std::vector<std::string> out;
  if (!std::regex_search(cmake, m, line)) return out;
  std::istringstream words(m[1].str());
  for (std::string w; words >> w;) out.push_back(w);
  return out;
}

TEST(Layers, NoFileLocalFunctionHidesAnotherInAUnityBuild) {
  const fs::path src = fs::path(PATHEX_SOURCE_DIR) / "src";
  const std::string cmake = read_file(src / "CMakeLists.txt");
  std::vector<std::string> groups = cmake_list(cmake, "PATHEX_UNITY_DIRS");
  ASSERT_GT(groups.size(), 10u) << "PATHEX_UNITY_DIRS not found in src/CMakeLists.txt";
  groups.push_back("cli");
  const std::vector<std::string> skip = cmake_list(cmake, "PATHEX_UNITY_SKIP");
  for (const std::string& h : unity_hiding(src, groups, std::set<std::string>(skip.begin(), skip.end())))
    ADD_FAILURE() << "src/" << h << ": in a unity build this file-local function hides the other for the files after it; rename it";
}

// The check itself finds the hiding that CI's unity build once had.
TEST(Layers, AFileLocalFunctionThatHidesAHeadersIsFound) {
  const fs::path dir = fs::temp_directory_path() / "pathex-unity-test";
  fs::remove_all(dir);
  fs::create_directories(dir / "cli");
  std::ofstream(dir / "cli" / "witness_text.h") << "#pragma once\nnamespace pathex::cli {\n\ninline std::string chains_text(const Chains& c) {\n  return \"\";\n}\n\n}  // namespace pathex::cli\n";
  std::ofstream(dir / "cli" / "check.cpp") << "namespace pathex::cli {\nnamespace {\n\nstd::string chains_text(const Chains& c) {\n  return \"\";\n}\n\nint run(const CheckArgs& a) {\n  return 0;\n}\n\n}  // namespace\n}  // namespace pathex::cli\n";
  std::ofstream(dir / "cli" / "query.cpp") << "namespace pathex::cli {\nnamespace {\n\nint run(const QueryArgs& a) {\n  return 0;\n}\n\n}  // namespace\n}  // namespace pathex::cli\n";
  const std::vector<std::string> found = unity_hiding(dir, {"cli"}, {});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0], "cli/check.cpp: chains_text (also in cli/witness_text.h)");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pathex
