// The README as a user reads it (issue 38): every `$ build/pathex …` example of the README and of
// the docs/ files it links runs as printed and prints what the text shows, the check-file example is the file it names, and the README's
// test command is the one CI runs. The README is read here and nowhere else among the tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;
using pathex::test::shell_quote;

std::string source_file(const std::string& name) {
  return pathex::test::read_file(fs::path(PATHEX_SOURCE_DIR) / name);
}

std::string readme() { return source_file("README.md"); }

// The manual: the README and the files it sends the reader to for the explanations.
std::vector<std::string> manual_files() {
  std::vector<std::string> out = {"README.md", "CONTRIBUTING.md"};
  for (const fs::directory_entry& e : fs::directory_iterator(fs::path(PATHEX_SOURCE_DIR) / "docs"))
    if (e.path().extension() == ".md") out.push_back("docs/" + e.path().filename().string());
  return out;
}

// The lines of `text`, each without trailing spaces (a table's padding, which a README line does
// not keep).
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line.substr(0, line.find_last_not_of(' ') + 1));
  return out;
}

// The README's indented blocks (four spaces), each without its indentation. As in Markdown, an
// empty line between two indented lines belongs to the block.
std::vector<std::vector<std::string>> indented_blocks(const std::string& text) {
  std::vector<std::vector<std::string>> blocks;
  std::vector<std::string> block;
  const auto end_block = [&] {
    while (!block.empty() && block.back().empty()) block.pop_back();
    if (!block.empty()) blocks.push_back(block);
    block.clear();
  };
  for (const std::string& line : lines_of(text)) {
    if (line.rfind("    ", 0) == 0) {
      block.push_back(line.substr(4));
    } else if (line.empty() && !block.empty()) {
      block.push_back("");
    } else {
      end_block();
    }
  }
  end_block();
  return blocks;
}

// The indented block that follows `first_line` in the README, without the indentation.
std::string readme_block_after(const std::string& first_line) {
  for (const std::vector<std::string>& block : indented_blocks(readme()))
    for (std::size_t i = 0; i < block.size(); ++i)
      if (block[i] == first_line) {
        std::string out;
        for (std::size_t j = i + 1; j < block.size() && block[j].rfind("$ ", 0) != 0; ++j) out += block[j] + "\n";
        return out;
      }
  return "";
}

// One example: a command as printed after `$ `, the lines the manual shows it printing, and the
// file it is in.
struct Example {
  std::string command;
  std::vector<std::string> shown;
  std::string file;
};

// Every `$ ` line of the manual that runs `build/pathex` from the source directory (not the ones
// that first write a file of their own: they name /tmp), with the lines under it up to the next
// `$ ` line or the end of the block.
std::vector<Example> manual_examples() {
  std::vector<Example> out;
  for (const std::string& file : manual_files())
    for (const std::vector<std::string>& block : indented_blocks(source_file(file))) {
      bool in_example = false;
      for (const std::string& line : block) {
        if (line.rfind("$ ", 0) == 0) {
          out.push_back({line.substr(2), {}, file});
          in_example = true;
        } else if (in_example) {
          out.back().shown.push_back(line);
        }
      }
    }
  std::vector<Example> runnable;
  for (const Example& e : out) {
    const bool pathex_first = e.command.rfind("build/pathex ", 0) == 0 ||
                              (e.command.rfind("printf ", 0) == 0 && e.command.find("| build/pathex ") != std::string::npos);
    if (pathex_first && e.command.find("/tmp/") == std::string::npos) runnable.push_back(e);
  }
  return runnable;
}

// `lines` match `shown` where a shown line `…` stands for any number of lines (none included).
bool matches(const std::vector<std::string>& lines, std::size_t i, const std::vector<std::string>& shown, std::size_t j) {
  if (j == shown.size()) return i == lines.size();
  if (shown[j] == "…") {
    for (std::size_t k = i; k <= lines.size(); ++k)
      if (matches(lines, k, shown, j + 1)) return true;
    return false;
  }
  return i < lines.size() && lines[i] == shown[j] && matches(lines, i + 1, shown, j + 1);
}

// The command as the README prints it, with `build/pathex` the binary under test and, for the
// commands that write an output set, `--out` a scratch folder (the README's user writes into the
// current directory; the test must not write into the source tree).
std::string runnable_command(const std::string& command, int n) {
  std::string cmd;
  const std::string name = "build/pathex ";
  std::size_t at = 0;
  for (std::size_t next; (next = command.find(name, at)) != std::string::npos; at = next + name.size()) {
    cmd += command.substr(at, next - at) + shell_quote(PATHEX_BINARY) + " ";
    for (const char* sub : {"trace ", "bias ", "converge ", "merge "}) {
      const std::string s = sub;
      if (command.compare(next + name.size(), s.size(), s) == 0 && command.find("--out") == std::string::npos)
        cmd += s + "--out " + shell_quote((pathex::test::scratch_dir() / ("readme-" + std::to_string(n))).string()) + " ",
            next += s.size();
    }
  }
  return cmd + command.substr(at);
}

TEST(ReadmeExamples, QuickCommandsPrintWhatTheReadmeShows) {
  const std::vector<Example> examples = manual_examples();
  // The quick start's commands are among the README's, each with output shown.
  std::set<std::string> subcommands;
  for (const Example& e : examples) {
    if (e.file != "README.md") continue;
    const std::size_t at = e.command.find("build/pathex ") + 13;
    subcommands.insert(e.command.substr(at, e.command.find(' ', at) - at));
    EXPECT_FALSE(e.shown.empty()) << e.command;
  }
  for (const char* sub : {"explain", "match", "classify", "query", "check", "renderers", "trace", "bias"})
    EXPECT_TRUE(subcommands.count(sub)) << sub;
  EXPECT_GE(examples.size(), 12u);
  int n = 0;
  for (const Example& e : examples) {
    const std::string cmd = "cd " + shell_quote(PATHEX_SOURCE_DIR) + " && (" + runnable_command(e.command, n++) + ") 2>&1";
    const CliRun r = pathex::test::run_shell(cmd);
    const std::vector<std::string> lines = lines_of(r.out);
    std::string shown;
    for (const std::string& s : e.shown) shown += s + "\n";
    EXPECT_TRUE(matches(lines, 0, e.shown, 0)) << e.file << ": $ " << e.command << "\nthe README shows\n" << shown << "it prints\n" << r.out;
  }
}

// The README's check-file example fails on purpose, says so, and prints what the README shows.
TEST(ReadmeExamples, CheckFileFailsAsShown) {
  const std::string shown = readme_block_after("$ build/pathex check samples/checks/fails-on-purpose.json; echo \"exit $?\"");
  ASSERT_FALSE(shown.empty());
  const CliRun r = pathex::test::run_pathex_args({"check", "samples/checks/fails-on-purpose.json"});
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.out + "exit " + std::to_string(r.code) + "\n", shown);
  EXPECT_NE(readme().find("**fails on purpose (exit 1)**"), std::string::npos);
  // The JSON shown is the file's cases.
  const std::string text = readme();
  const std::size_t json_at = text.find("    {\"cases\": [{\"name\": \"ptnee-ortho\"");
  ASSERT_NE(json_at, std::string::npos);
  const nlohmann::json file = nlohmann::json::parse(source_file("samples/checks/fails-on-purpose.json"));
  EXPECT_EQ(nlohmann::json::parse(text.substr(json_at, text.find("\n\n", json_at) - json_at))["cases"], file["cases"]);
  // And the passing gate passes.
  EXPECT_EQ(pathex::test::run_pathex_args({"check", "samples/checks/samples.json"}).code, 0);
}

TEST(ReadmeExamples, TheUnreachableLightWarningIsTheOneShown) {
  const std::string block =
      readme_block_after("$ build/pathex trace samples/scenes/point-mirror-caustic.json --renderer pt");
  const std::string shown = block.substr(0, block.find("…\n"));
  ASSERT_FALSE(shown.empty());
  const CliRun r = pathex::test::run_pathex_args({"trace", "samples/scenes/point-mirror-caustic.json", "--renderer", "pt",
                                                  "--spp", "1", "--no-images", "--quiet", "--out",
                                                  (pathex::test::scratch_dir() / "readme-warning").string()});
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, shown);
}

// The two commands of the quick start, and CI's first stage runs the second verbatim.
TEST(ReadmeExamples, CiRunsTheReadmesTestCommand) {
  const std::string main_job = "bash setup.sh && build/pathex trace";
  const std::string test_command =
      "bash setup.sh && cmake --build build -j\"$(nproc)\" && ctest --test-dir build --output-on-failure -j2";
  const std::string text = readme();
  const std::size_t start = text.find("## Quick start");
  ASSERT_NE(start, std::string::npos);
  const std::string quick = text.substr(start, text.find("\n## ", start) - start);
  EXPECT_NE(quick.find("\n    " + main_job + "\n"), std::string::npos);
  EXPECT_NE(quick.find("\n    " + test_command + "\n"), std::string::npos);
  EXPECT_NE(source_file(".ci/run").find("\n" + test_command + "\n"), std::string::npos);
  // Its failure ends the run: errexit ignores a failed setup or build inside the && list.
  EXPECT_NE(source_file(".ci/run").find("\n" + test_command + "\n} || exit 1\n"), std::string::npos);
  // setup.sh builds `pathex` alone (the first render comes before the tests are built).
  EXPECT_NE(source_file("setup.sh").find("--target pathex pathex_docs\n"), std::string::npos);
}

}  // namespace
