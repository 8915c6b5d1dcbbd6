// The pathex command line: each subcommand lives in its own file and registers itself here; this
// only parses the command line and maps the outcome to the exit code. main.cpp (pathex) and
// mpi/main.cpp (pathex-mpi) call it.
#include <iostream>
#include <vector>

#include "cli/common.h"
#include "core/version.h"

namespace pathex::cli {

int run_command_line(int argc, char** argv) {
  CLI::App app{"pathex: full-path regular expressions for light transport (Heckbert/Veach)\n"
               "Example: pathex explain 'L.*DD.*E'"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("pathex ") + pathex::pathex_version());
  std::vector<Command> commands = {add_explain(app), add_match(app), add_classify(app),
                                   add_query(app), add_check(app), add_renderers(app), add_trace(app),
                                   add_merge(app)};
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
  for (const Command& c : commands)
    if (c.app->parsed()) return c.run();
  return kExitBadInput;
}

}  // namespace pathex::cli
