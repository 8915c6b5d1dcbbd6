// The man page and the bash completion script, generated from the command-line definitions
// themselves (the CLI11 tree every subcommand registers into), so that neither can drift from
// --help. The build runs `pathex --man` and `pathex --bash-completion`, and `cmake --install`
// installs the results as share/man/man1/pathex.1 and share/bash-completion/completions/pathex.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pathex::cli {

// A roff man page (section 1): every subcommand with its positionals, options, defaults,
// choices and example, then the top-level footer (exit codes).
std::string man_page(const CLI::App& app, const std::string& version);

// A bash completion script: subcommand names, each subcommand's options, the choices of options
// that list them ({a,b} in their type), `renderers` for --renderer, files elsewhere.
std::string bash_completion(const CLI::App& app, const std::vector<std::string>& renderers);

}  // namespace pathex::cli
