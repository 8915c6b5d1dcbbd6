// The pathex command line: each subcommand lives in its own file and registers itself here; this
// only parses the command line and maps the outcome to the exit code. main.cpp (pathex) and
// mpi/main.cpp (pathex-mpi) call it.
#include <iostream>
#include <string>
#include <vector>

#include "cli/common.h"
#include "cli/manual.h"
#include "pathex/pathex.h"

namespace pathex::cli {
namespace {

// "explain, match, classify, …": the subcommands in the order they were registered.
std::string command_list(const CLI::App& app) {
  std::string s;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    s += (s.empty() ? "" : ", ") + sub->get_name();
  return s;
}

// The first word that is not an option must name a subcommand (no top-level option takes a
// value); CLI11 alone would only say that a subcommand is required.
const char* unknown_command(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string w = argv[i];
    if (w == "--") return i + 1 < argc ? argv[i + 1] : nullptr;
    if (!w.empty() && w[0] == '-') continue;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
      if (sub->check_name(w)) return nullptr;
    return argv[i];
  }
  return nullptr;
}

}  // namespace

int run_command_line(int argc, char** argv) {
  const std::string version(pathex::api::version());
  CLI::App app{"pathex: full-path regular expressions for light transport (Heckbert/Veach)\n"
               "Parses path classes such as LDDS*DDE, compiles them to minimal automata, answers exactly whether a\n"
               "renderer can sample them (with witness paths), renders scenes with a tracer that labels every\n"
               "sampled path with its full-path string, and gates CI on renderer and scene configurations.\n"
               "Example: pathex explain 'L.*DD.*E'"};
  app.footer("Exit codes: 0 success; 1 a negative answer where one is asked for (match with a non-matching\n"
             "path, check with a failed requirement, an interrupted trace); 2 bad input or usage, with one\n"
             "message that says where and what was expected.");
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", "pathex " + version);
  bool man = false, completion = false;
  // Hidden (no group): the build generates the man page and completion script with them.
  app.add_flag("--man", man, "Print the man page (roff)")->group("");
  app.add_flag("--bash-completion", completion, "Print the bash completion script")->group("");
  std::vector<Command> commands = {add_explain(app), add_match(app),     add_classify(app), add_query(app),
                                   add_check(app),   add_renderers(app), add_trace(app),    add_merge(app),
                                   add_converge(app), add_bias(app), add_report(app)};
  if (const char* word = unknown_command(app, argc, argv)) {
    std::cerr << "pathex: error: unknown command '" << word << "'; the commands are " << command_list(app)
              << " (pathex --help describes them)\n";
    return kExitBadInput;
  }
  if (std::optional<std::string> message = misused_list_option(argc, argv)) {
    std::cerr << "pathex: error: " << *message << "\n";
    return kExitBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  if (man) {
    std::cout << man_page(app, version);
    return kExitOk;
  }
  if (completion) {
    std::cout << bash_completion(app, pathex::api::Renderer::builtin_names());
    return kExitOk;
  }
  for (const Command& c : commands)
    if (c.app->parsed()) return c.run();
  std::cerr << "pathex: error: a command is required; the commands are " << command_list(app)
            << " (pathex --help describes them)\n";
  return kExitBadInput;
}

}  // namespace pathex::cli
