// pathex match EXPR PATH...: membership, one line per path.
#include <iostream>

#include "cli/common.h"
#include "io/class_file.h"

namespace pathex::cli {
namespace {

struct MatchArgs {
  std::string expr;
  std::vector<std::string> paths;
  std::string classes_file;
  NotationOptions notation;
  Limits limits;
};

int run(const MatchArgs& a) {
  ClassTable table;
  Result<PathClass> pc = compile_cli_expression(a.expr, a.notation, a.limits, a.classes_file, &table);
  if (!pc) return report(pc.error());
  bool all = true;
  bool bad = false;
  for (const std::string& p : a.paths) {
    Result<FullPath> fp = parse_full_path(p, a.limits.max_length);
    if (!fp) {
      report(fp.error());
      bad = true;
      continue;
    }
    const bool m = pc->dfa.accepts(fp->text);
    all = all && m;
    std::cout << (m ? "match     " : "no match  ") << p << "\n";
  }
  return bad ? kExitBadInput : all ? kExitOk : kExitNo;
}

}  // namespace

Command add_match(CLI::App& app) {
  auto args = std::make_shared<MatchArgs>();
  CLI::App* sub = app.add_subcommand("match", "Say for each full path whether it matches; exit 0 only if all match");
  sub->footer("Example:\n  pathex match 'L.*DD.*E' LDDDDE LSDSDE    # prints match / no match, exits 1");
  sub->add_option("EXPR", args->expr, "Path expression")->required();
  sub->add_option("PATH", args->paths, "Full-path strings such as LDSDDSSDSE")->required();
  sub->add_option("--classes", args->classes_file, "Class file whose names ($name) the expression may use");
  add_notation_options(sub, &args->notation);
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
