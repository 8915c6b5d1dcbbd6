// Runs the pathex binary the way the README's user does (from the source tree, through the
// shell), for the tests of the command line. Header-only: PATHEX_SOURCE_DIR and PATHEX_BINARY are
// compile definitions of each test executable (tests/CMakeLists.txt).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace pathex::test {

struct CliRun {
  int code = -1;       // the exit code; -1 when the process did not exit normally
  std::string out;     // standard output
  std::string err;     // standard error
  // No wall time on purpose: a limit is tested on the work budget's counters
  // (tests/automata/budget_test.cpp), never on a clock (issue 17: a timed test is not a limit test).
};

// `s` single-quoted for the shell.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The test process's scratch directory (ctest runs test processes in parallel), removed at exit.
inline std::filesystem::path scratch_dir() {
  struct Dir {
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("pathex-test-" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A shell command line; its standard output (stderr is the caller's to redirect).
inline CliRun run_shell(const std::string& cmd) {
  CliRun r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// `pathex ARGS` in the source directory, ARGS being shell text (the caller quotes what needs
// it), with `input` on standard input.
inline CliRun run_pathex(const std::string& args, const std::string& input = "") {
  const std::filesystem::path in = scratch_dir() / "stdin.txt", err = scratch_dir() / "stderr.txt";
  std::ofstream(in, std::ios::binary) << input;
  const std::string cmd = "cd " + shell_quote(PATHEX_SOURCE_DIR) + " && " + shell_quote(PATHEX_BINARY) + " " + args +
                          " < " + shell_quote(in.string()) + " 2> " + shell_quote(err.string());
  CliRun r = run_shell(cmd);
  r.err = read_file(err);
  return r;
}

// `mpirun --oversubscribe ARGS` in the source directory (as root too, as CI runs), ARGS being shell
// text; standard output and error together in `out`.
inline CliRun run_mpirun(const std::string& args) {
  return run_shell("cd " + shell_quote(PATHEX_SOURCE_DIR) + " && mpirun --oversubscribe --allow-run-as-root " + args + " 2>&1");
}

// The same with each argument quoted.
inline CliRun run_pathex_args(const std::vector<std::string>& args, const std::string& input = "") {
  std::string text;
  for (const std::string& a : args) text += (text.empty() ? "" : " ") + shell_quote(a);
  return run_pathex(text, input);
}

}  // namespace pathex::test
