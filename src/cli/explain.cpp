// pathex explain EXPR: everything the engine knows about one path class.
#include <iostream>

#include "automata/ops.h"
#include "language/lpe_emit.h"
#include "cli/common.h"
#include "io/class_file.h"
#include "io/class_json.h"

namespace pathex::cli {
namespace {

struct ExplainArgs {
  std::string expr;
  std::string classes_file;
  int max_len = 12;
  int members = 5;
  bool json = false;
  bool dot = false;
  std::string emit;
  NotationOptions notation;
  Limits limits;
};

std::string path_chains_text(const std::string& path) {
  Result<FullPath> p = parse_full_path(path, path.size());
  if (!p) return "";
  std::string s;
  for (const Chain& c : chains(*p)) {
    if (!s.empty()) s += ' ';
    s += c.letters + "(" + std::to_string(c.from) + ".." + std::to_string(c.to) + ")";
  }
  return s;
}

// `explain --emit lpe`: the LPE on the first line (to paste), then exact or approximate and why.
int run_emit_lpe(const ExplainArgs& a, const PathClass& pc) {
  Result<LpeEmission> e = emit_lpe(pc.dfa, a.limits);
  if (!e) return report(e.error());
  if (a.json) {
    std::cout << lpe_json_text(a.expr, a.notation.notation, *e);
    return kExitOk;
  }
  if (e->empty) {
    std::cout << "no LPE: the class is empty, there is no path to select\n";
    return kExitOk;
  }
  std::cout << e->lpe << "\n";
  if (e->exact) {
    std::cout << "exact: read back with --notation lpe it is the same class\n";
    return kExitOk;
  }
  std::cout << "approximate: the LPE matches more paths than the class\n";
  for (const std::string& l : e->losses) std::cout << "  " << l << "\n";
  if (e->example) std::cout << "  for example " << *e->example << " matches the LPE but not the class\n";
  return kExitOk;
}

int run(const ExplainArgs& a) {
  ClassTable table;
  Result<PathClass> pc = compile_cli_expression(a.expr, a.notation, a.limits, a.classes_file, &table);
  if (!pc) return report(pc.error());
  const Dfa& d = pc->dfa;
  if (a.dot) {
    std::cout << to_dot(d, a.expr);
    return kExitOk;
  }
  if (a.emit == "lpe") return run_emit_lpe(a, *pc);
  const bool finite = is_finite(d);
  const bool empty = is_empty(d);
  const std::vector<BigUint> counts = count_by_length(d, a.max_len);
  const std::vector<std::string> members = enumerate_members(d, std::max(a.max_len, 64), static_cast<std::size_t>(a.members));
  // An LPE's own tree is an eye-first intermediate; what the user wants to see is the full-path
  // expression it became, written from the class's automaton.
  std::string normal = to_string(pc->ast);
  if (pc->notation == Notation::kLpe) {
    Result<std::string> x = full_path_expression(d, a.limits);
    normal = x ? *x : "(too large to print: " + x.error().message + ")";
  }

  if (a.json) {
    ClassFacts f;
    f.expression = a.expr;
    f.normal_form = normal;
    f.notation = a.notation.notation;
    f.eye_first = pc->eye_first;
    f.dfa_states = d.num_states;
    f.live_states = d.live_count();
    f.empty = empty;
    f.finite = finite;
    f.counts = counts;
    f.max_len = a.max_len;
    f.shortest_members = members;
    std::cout << explain_json_text(f);
    return kExitOk;
  }
  std::cout << "expression    " << a.expr << "\n";
  if (pc->notation == Notation::kLpe)
    std::cout << "full-path form " << (normal.empty() ? "(none: the class is empty)" : normal) << "\n";
  else
    std::cout << "normal form   " << normal << (pc->eye_first ? "   (eye-first: denotes the reversed paths)" : "") << "\n";
  std::cout << "notation      " << a.notation.notation << "\n";
  std::cout << "minimal DFA   " << d.num_states << " states (" << d.live_count() << " live)\n";
  std::cout << "language      " << (empty ? "empty" : finite ? "finite" : "infinite") << "\n";
  std::cout << "members by length (letters: count, up to " << a.max_len << ")\n ";
  bool any = false;
  for (std::size_t n = 0; n < counts.size(); ++n) {
    if (counts[n].is_zero()) continue;
    std::cout << " " << n << ": " << counts[n].to_string();
    any = true;
  }
  std::cout << (any ? "" : " none") << "\n";
  std::cout << "shortest members\n";
  if (members.empty()) std::cout << "  none\n";
  for (const std::string& m : members) std::cout << "  " << m << "   chains " << path_chains_text(m) << "\n";
  return kExitOk;
}

}  // namespace

Command add_explain(CLI::App& app) {
  auto args = std::make_shared<ExplainArgs>();
  CLI::App* sub = app.add_subcommand("explain", "Show a path class: normal form, minimal DFA, counts, shortest members");
  sub->footer("Example:\n  pathex explain 'L.*DD.*E'\n  pathex explain --notation heckbert --light point --sensor pinhole 'LS+DE'\n"
              "  pathex explain --notation lpe 'C<RD>S+L'\n  pathex explain --emit lpe '$caustic'\n"
              "  pathex explain --dot 'LDS*DE' | dot -Tsvg > dfa.svg");
  sub->add_option("EXPR", args->expr, "Path expression (see grammar/pathex.ebnf)")->required();
  sub->add_option("--classes", args->classes_file, "Class file whose names ($name) the expression may use");
  sub->add_option("--max-len", args->max_len, "Count members up to this many letters")->capture_default_str()
      ->check(CLI::Range(0, 10000));
  sub->add_option("--members", args->members, "How many shortest members to list")->capture_default_str()
      ->check(CLI::Range(0, 100000));
  sub->add_flag("--json", args->json, "Machine-readable output");
  sub->add_flag("--dot", args->dot, "Print the minimal DFA as Graphviz instead");
  sub->add_option("--emit", args->emit,
                  "Print the class in another notation instead: lpe (the closest OSL light path expression, for an "
                  "Arnold, RenderMan or Karma AOV, marked exact or approximate)")
      ->check(CLI::IsMember({"lpe"}));
  add_notation_options(sub, &args->notation);
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
