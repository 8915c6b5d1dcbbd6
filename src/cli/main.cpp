// pathex: a thin front end. Each subcommand lives in its own file and registers itself here;
// main only parses the command line and maps the outcome to the exit code.
#include <iostream>
#include <vector>

#include "cli/common.h"

int main(int argc, char** argv) {
  using namespace pathex::cli;
  CLI::App app{"pathex: full-path regular expressions for light transport (Heckbert/Veach)\n"
               "Example: pathex explain 'L.*DD.*E'"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pathex 0.1.0");
  std::vector<Command> commands = {add_explain(app), add_match(app), add_classify(app),
                                   add_query(app), add_check(app), add_renderers(app), add_trace(app)};
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
