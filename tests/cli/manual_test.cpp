// The man page and the bash completion, both generated from the command-line definitions: every
// subcommand and every option of its --help appears in the man page, groff reads the page without
// a warning, the build's copies are what the binary prints, and bash completes subcommands,
// options and their choices with the generated script.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using pathex::test::CliRun;
using pathex::test::shell_quote;

CliRun pathex_cli(const std::vector<std::string>& args) { return pathex::test::run_pathex_args(args); }

// The subcommands, as the binary lists them when none is given.
std::vector<std::string> subcommands() {
  const std::string err = pathex_cli({}).err;
  const std::string list = err.substr(err.find("the commands are ") + 17);
  std::vector<std::string> out;
  std::regex word("[a-z]+");
  for (auto it = std::sregex_iterator(list.begin(), list.begin() + static_cast<long>(list.find(" (")), word);
       it != std::sregex_iterator(); ++it)
    out.push_back(it->str());
  return out;
}

// The man page's section for one subcommand: from its .SS line to the next section.
std::string section(const std::string& man, const std::string& sub) {
  const std::size_t start = man.find(".SS \"pathex " + sub + " ");
  if (start == std::string::npos) return "";
  const std::size_t end = std::min(man.find("\n.SS ", start + 1), man.find("\n.SH ", start + 1));
  return man.substr(start, end - start);
}

// `pathex SUB --help`'s option names (--long), from the lines that list options.
std::set<std::string> help_options(const std::string& sub) {
  const std::string help = pathex_cli({sub, "--help"}).out;
  std::set<std::string> out;
  std::regex option(R"(^\s+(--[a-z][a-z-]*))");
  std::istringstream lines(help.substr(0, help.find("Example:")));
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, option) && m[1] != "--help") out.insert(m[1]);
  }
  return out;
}

std::string roff_name(const std::string& option) {
  std::string out;
  for (char c : option) out += c == '-' ? std::string("\\-") : std::string(1, c);
  return "\\fB" + out + "\\fR";
}

TEST(ManPage, DocumentsEverySubcommandAndEveryOptionOfItsHelp) {
  const CliRun man = pathex_cli({"--man"});
  ASSERT_EQ(man.code, 0) << man.err;
  EXPECT_EQ(man.out.rfind(".TH PATHEX 1 \"\" \"pathex ", 0), 0u);
  EXPECT_NE(man.out.find(".SH NAME\npathex \\- full\\-path regular expressions for light transport"), std::string::npos);
  EXPECT_NE(man.out.find(".SH EXIT STATUS\n.nf\nExit codes: 0 success;"), std::string::npos);
  const std::vector<std::string> subs = subcommands();
  ASSERT_EQ(subs.size(), 11u);  // explain … merge, converge, bias, report
  for (const std::string& sub : subs) {
    const std::string text = section(man.out, sub);
    ASSERT_FALSE(text.empty()) << sub;
    const std::set<std::string> options = help_options(sub);
    EXPECT_GE(options.size(), 4u) << sub;  // every subcommand has at least the four limits
    for (const std::string& o : options) EXPECT_NE(text.find(roff_name(o)), std::string::npos) << sub << " " << o;
  }
  // Defaults and choices come along.
  EXPECT_NE(section(man.out, "trace").find("\\fB\\-\\-max\\-paths\\fR \\fIUINT\\fR\n"), std::string::npos);
  EXPECT_NE(section(man.out, "trace").find("(default: 1000)"), std::string::npos);
  EXPECT_NE(section(man.out, "query").find("\\fB\\-\\-light\\fR \\fILIST:{area,distant,point,laser}\\fR"), std::string::npos);
}

TEST(ManPage, GroffReadsItWithoutAWarning) {
  const fs::path page = pathex::test::scratch_dir() / "pathex.1";
  std::ofstream(page) << pathex_cli({"--man"}).out;
  const fs::path err = pathex::test::scratch_dir() / "groff.err";
  const int status = std::system(("groff -man -Tutf8 -ww -z " + shell_quote(page.string()) + " 2> " + shell_quote(err.string())).c_str());
  EXPECT_EQ(status, 0);
  EXPECT_EQ(pathex::test::read_file(err), "");
}

TEST(ManPage, TheBuildGeneratesWhatTheBinaryPrints) {
  const fs::path share = fs::path(PATHEX_BINARY).parent_path() / "share";
  EXPECT_EQ(pathex::test::read_file(share / "pathex.man"), pathex_cli({"--man"}).out);
  EXPECT_EQ(pathex::test::read_file(share / "pathex.bash-completion"), pathex_cli({"--bash-completion"}).out);
}

// What bash offers for the command line `words` (the last one being completed), with the generated
// script loaded, in an empty folder (so that no file names join the offers).
std::string complete(const std::string& words) {
  const fs::path dir = pathex::test::scratch_dir() / "empty";
  fs::create_directories(dir);
  const fs::path script = pathex::test::scratch_dir() / "completion.bash";
  std::ofstream(script) << pathex_cli({"--bash-completion"}).out;
  const std::string program = "source " + shell_quote(script.string()) + "; COMP_WORDS=(" + words +
                              "); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _pathex; printf '%s\\n' \"${COMPREPLY[@]}\"";
  const std::string cmd = "cd " + shell_quote(dir.string()) + " && bash -c " + shell_quote(program);
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  for (std::size_t n; p != nullptr && (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  if (p != nullptr) pclose(p);
  return out;
}

TEST(BashCompletion, CompletesCommandsOptionsAndChoices) {
  EXPECT_EQ(complete("pathex tr"), "trace\n");
  EXPECT_EQ(complete("pathex c"), "classify\ncheck\nconverge\n");
  EXPECT_EQ(complete("pathex trace --re"), "--renderer\n--replicates\n--resolution\n--reference\n--report\n--resume\n");
  EXPECT_EQ(complete("pathex trace --renderer pt"), "pt\npt-nee\npt-nee+distant\npt-nee+mirror\npt-nee+manifold\n");
  EXPECT_EQ(complete("pathex query --notation ''"), "full\nheckbert\nlpe\n");
  EXPECT_EQ(complete("pathex explain --light p"), "point\n");
  EXPECT_EQ(complete("pathex query --sensor ''"), "lens\npinhole\northographic\nspotmeter\n");
  EXPECT_EQ(complete("pathex explain --max-s"), "--max-states\n");
  // A flag takes no value: after --json come options again.
  EXPECT_EQ(complete("pathex explain --json --d"), "--dot\n");
}

}  // namespace
