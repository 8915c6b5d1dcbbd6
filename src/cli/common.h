// What every subcommand shares: limit options, notation options, error reporting and the
// exit-code convention (0 success, 1 a negative answer, 2 bad input or usage).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "trace/joins/manifold.h"

namespace pathex::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitNo = 1;
inline constexpr int kExitBadInput = 2;

struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

struct NotationOptions {
  std::string notation = "full";
  std::vector<std::string> lights;
  std::vector<std::string> sensors;
};

void add_limit_options(CLI::App* app, Limits* limits);
// The limits of an imported scene (--max-scene-size, --max-scene-depth, --max-material-nodes,
// --max-mesh-elements), for the commands that read scenes.
void add_scene_limit_options(CLI::App* app, Limits* limits);
// Refuses a value with a minus sign: CLI11 reads "-1" into an unsigned option as 2^64 - 1.
const CLI::Validator& non_negative();
// An option that takes `auto` or a value: `auto` reaches the option as `sentinel`; any other value
// must pass `accepts`, else "expected auto or `expected`, got 'VALUE'".
CLI::Validator auto_or(std::string sentinel, std::function<bool(const std::string&)> accepts, std::string expected, std::string name);
void add_notation_options(CLI::App* app, NotationOptions* n);
// The manifold connector's limits (trace/joins/manifold.h), group "Manifold connector", each with
// its default and its range: --manifold-iterations, --manifold-threshold, --manifold-min-segment,
// --manifold-singular, --manifold-trials, --manifold-seeds, --manifold-biased-trials,
// --manifold-rate.
void add_manifold_options(CLI::App* app, ManifoldOptions* o);
// The names of those options, in that order (for commands that refuse them in some modes).
const std::vector<std::string>& manifold_option_names();
// `--light point area` reads `area` as an expression, because --light takes one comma-separated
// list. Returns the message for such a command line (a type name right after the value of --light
// or --sensor), else nothing.
std::optional<std::string> misused_list_option(int argc, char** argv);
// Turns the notation options into ClassOptions, or an error naming the bad value.
Result<ClassOptions> class_options(const NotationOptions& n, const Limits& limits);

// The class of a command-line expression: notation options, then the optional class file's
// names (into *table, which must outlive the result's use), then the expression itself.
Result<PathClass> compile_cli_expression(const std::string& expr, const NotationOptions& n, const Limits& limits,
                                         const std::string& classes_file, ClassTable* table);

// Prints "pathex: hint: …" on stderr when a full-notation expression reads like a Heckbert string
// (language/notation_hint.h). compile_cli_expression() calls it.
void print_notation_hint(const std::string& expr, const PathClass& pc, const ClassOptions& options,
                         const ClassTable* table);

// Prints "pathex: error: <rendered error>" to stderr and returns kExitBadInput.
int report(const Error& e);

// Parses the command line, runs the subcommand and returns the exit code (cli/app.cpp).
int run_command_line(int argc, char** argv);

// Ending the process without freeing (a compiler's -disable-free): a command that has written,
// synced and renamed all its outputs calls finish_command(code), which flushes stdout and stderr
// and ends the process at once when the process allows it, so that a render's tables and images
// are not freed page by page (munmap's TLB flushes) just before the kernel drops the address
// space anyway; otherwise it returns code. Only the pathex binary's main allows it: tests run
// commands in-process, and pathex-mpi must finalise MPI. Under AddressSanitizer it always returns, so
// that LeakSanitizer's check at exit runs on the pathex binary too.
void allow_fast_exit();
int finish_command(int code);

// Registration of each subcommand (one file each).
Command add_explain(CLI::App& app);
Command add_match(CLI::App& app);
Command add_classify(CLI::App& app);
Command add_query(CLI::App& app);
Command add_check(CLI::App& app);
Command add_renderers(CLI::App& app);
Command add_trace(CLI::App& app);
Command add_merge(CLI::App& app);
Command add_converge(CLI::App& app);
Command add_bias(CLI::App& app);
Command add_report(CLI::App& app);

}  // namespace pathex::cli
