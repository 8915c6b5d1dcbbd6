// pathex classify: full paths on stdin, their classes on stdout. One automaton, one pass per path.
#include <iostream>

#include "classify/classifier.h"
#include "cli/common.h"
#include "io/class_file.h"
#include "io/class_json.h"

namespace pathex::cli {
namespace {

struct ClassifyArgs {
  std::string classes_file;
  bool json = false;
  NotationOptions notation;
  Limits limits;
};

int run(const ClassifyArgs& a) {
  Result<ClassOptions> opts = class_options(a.notation, a.limits);
  if (!opts) return report(opts.error());
  ClassTable table;
  std::vector<const PathClass*> classes;
  if (!a.classes_file.empty()) {
    Result<bool> r = read_class_file(a.classes_file, *opts, &table);
    if (!r) return report(r.error());
    for (const auto& c : table.user_classes()) classes.push_back(c.get());
  } else {
    for (const auto& c : ClassTable::builtins().builtin_classes()) classes.push_back(c.get());
  }
  Result<Classifier> cl = Classifier::build(classes, a.limits);
  if (!cl) return report(cl.error());

  std::string line;
  std::size_t line_no = 0;
  bool bad = false;
  while (std::getline(std::cin, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;  // blank lines separate nothing
    Result<FullPath> p = parse_full_path(line, a.limits.max_length);
    if (!p) {
      Error e = p.error();
      e.where = "stdin:" + std::to_string(line_no);
      bad = true;
      if (a.json) {
        std::cout << classify_error_json_line(line_no, line, e.render()) << "\n";
      } else {
        report(e);
      }
      continue;
    }
    const std::vector<int>& members = cl->members(cl->classify(p->text));
    if (a.json) {
      std::vector<std::string> names;
      for (int m : members) names.push_back(cl->name(m));
      std::cout << classify_json_line(line_no, p->text, names) << "\n";
    } else {
      std::cout << p->text << "\t";
      if (members.empty()) std::cout << "-";
      for (std::size_t i = 0; i < members.size(); ++i) std::cout << (i ? " " : "") << cl->name(members[i]);
      std::cout << "\n";
    }
  }
  return bad ? kExitBadInput : kExitOk;
}

}  // namespace

Command add_classify(CLI::App& app) {
  auto args = std::make_shared<ClassifyArgs>();
  CLI::App* sub = app.add_subcommand("classify", "Read full paths from stdin, one per line, and print each one's classes");
  sub->footer("Example:\n  printf 'LDDDDE\\nLSDSDDSE\\n' | pathex classify --classes samples/classes/basic.json\n"
              "Without --classes the built-in classes are used. Malformed lines are reported with their line\n"
              "number and skipped; the exit code is then 2.");
  sub->add_option("--classes", args->classes_file, "Class file (grammar/classes.schema.json)");
  sub->add_flag("--json", args->json, "One JSON object per line: {line, path, classes} or {line, path, error}");
  add_notation_options(sub, &args->notation);
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
