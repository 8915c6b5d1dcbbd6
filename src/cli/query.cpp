// pathex query: "can this renderer sample that kind of path?" — verdicts and evidence.
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli/common.h"
#include "cli/witness_text.h"
#include "cli/reach_common.h"
#include "io/class_file.h"
#include "io/reach_json.h"

namespace pathex::cli {
namespace {

struct QueryArgs {
  std::vector<std::string> exprs;
  std::vector<std::string> renderers;
  std::string scene;
  std::string classes_file;
  std::optional<int> max_bounces;
  int witnesses = 3;
  int max_len = -1;
  bool json = false;
  NotationOptions notation;
  Limits limits;
};

std::string size_text(bool empty, bool finite) {
  return empty ? "none" : finite ? "finite" : "infinite";
}

void print_result(const QueryResult& q) {
  std::cout << "\n" << q.expression << " — " << q.renderer << ": " << to_string(q.verdict);
  if (q.max_bounces) std::cout << "   (max_bounces " << *q.max_bounces << ")";
  const bool none = q.verdict == Verdict::kEmpty;
  std::cout << "\n  paths: class " << size_text(none, q.finite_class) << ", reachable "
            << size_text(none || q.verdict == Verdict::kUnreachable, q.finite_reachable) << ", unreachable "
            << size_text(none || q.verdict == Verdict::kReachable, q.finite_unreachable) << "\n  counts by length (letters: reachable/unreachable):";
  for (std::size_t n = 0; n < q.counts_class.size(); ++n) {
    if (q.counts_class[n].is_zero()) continue;
    std::cout << " " << n << ": " << q.counts_reachable[n].to_string() << "/" << q.counts_unreachable[n].to_string();
  }
  std::cout << "\n";
  if (!q.unreachable.empty()) std::cout << "  unreachable witnesses\n";
  for (const Witness& w : q.unreachable)
    std::cout << "    " << std::left << std::setw(14) << w.path << " chains " << chains_text(w.chains) << "\n"
              << "    " << std::setw(14) << "" << " " << w.reason << "\n";
  if (!q.reachable.empty()) std::cout << "  reachable witnesses\n";
  for (const Witness& w : q.reachable) {
    std::string via;
    for (std::size_t i = 0; i < w.strategies.size(); ++i) via += (i ? ", " : "") + w.strategies[i];
    std::cout << "    " << std::left << std::setw(14) << w.path << " sampled by " << via << "\n";
  }
}

int run(const QueryArgs& a) {
  Result<ClassOptions> opts = class_options(a.notation, a.limits);
  if (!opts) return report(opts.error());
  ReachCache cache(a.limits);
  ReachSetup setup;
  if (int rc = prepare_reach(cache, a.renderers.empty() ? std::vector<std::string>{"pt", "pt-nee", "lt", "bdpt"} : a.renderers,
                             a.scene, a.max_bounces, &setup))
    return rc;
  ClassOptions copts = *opts;
  if (setup.scene_ends) copts.ends = *setup.scene_ends;  // Heckbert ends default to the scene's types
  ClassTable table;
  if (!a.classes_file.empty()) {
    Result<bool> r = read_class_file(a.classes_file, copts, &table);
    if (!r) return report(r.error());
  }
  QueryOptions qo;
  qo.max_bounces = a.max_bounces;
  qo.universe = setup.universe;
  qo.witnesses = a.witnesses;
  qo.max_len = a.max_len;
  qo.limits = a.limits;

  std::vector<std::vector<QueryResult>> results;
  for (const std::string& e : a.exprs) {
    Result<PathClass> pc = compile_class(e, copts, &table);
    if (!pc) return report(pc.error());
    print_notation_hint(e, *pc, copts, &table);
    pc->text = e;
    std::vector<QueryResult> row;
    for (const CompiledProfile& cp : setup.compiled) {
      Result<QueryResult> q = query(*pc, cp, qo);
      if (!q) {
        // The query as a whole exceeded a limit: name the expression and the renderer.
        Error err = q.error();
        err.where = "renderer " + cp.profile->name;
        err.source = e;
        err.column = 1;
        return report(err);
      }
      q->expression = e;
      row.push_back(std::move(*q));
    }
    results.push_back(std::move(row));
  }
  if (a.json) {
    std::cout << query_json_text(results, a.scene);
    return kExitOk;
  }
  // Side-by-side table, then the evidence.
  std::size_t w = 10;
  for (const std::string& e : a.exprs) w = std::max(w, e.size() + 2);
  if (!a.scene.empty()) std::cout << "scene: " << a.scene << "\n";
  std::cout << std::left << std::setw(static_cast<int>(w)) << "class";
  for (const CompiledProfile& cp : setup.compiled) std::cout << std::setw(static_cast<int>(std::max<std::size_t>(13, cp.profile->name.size() + 2))) << cp.profile->name;
  std::cout << "\n";
  for (const auto& row : results) {
    std::cout << std::setw(static_cast<int>(w)) << row.front().expression;
    for (std::size_t i = 0; i < row.size(); ++i)
      std::cout << std::setw(static_cast<int>(std::max<std::size_t>(13, setup.compiled[i].profile->name.size() + 2))) << to_string(row[i].verdict);
    std::cout << "\n";
  }
  for (const auto& row : results)
    for (const QueryResult& q : row) print_result(q);
  return kExitOk;
}

}  // namespace

Command add_query(CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  CLI::App* sub = app.add_subcommand("query", "Can these renderers sample these path classes? Verdicts with witnesses");
  sub->footer("Example:\n  pathex query --renderer pt-nee 'LSDSDE'\n"
              "  pathex query --renderer bdpt --renderer bdpt+ortho --json 'L.*E'\n"
              "  pathex query --scene samples/scenes/mirror-ortho.json --renderer bdpt '$caustic'\n"
              "Without --renderer, pt, pt-nee, lt and bdpt are compared side by side.");
  sub->add_option("EXPR", args->exprs, "Path expressions (full notation unless --notation heckbert)")->required();
  sub->add_option("--renderer", args->renderers, "Built-in profile name (see `pathex renderers`) or profile file; repeatable")
      ->allow_extra_args(false);
  sub->add_option("--scene", args->scene, "Restrict the universe to this scene's lights, sensor and materials");
  sub->add_option("--max-bounces", args->max_bounces, "Only paths with at most N interior vertices; overrides the profiles' bound")
      ->check(CLI::Range(0, kMaxBouncesCeiling));
  sub->add_option("--witnesses", args->witnesses, "Witnesses per side")->capture_default_str()->check(CLI::Range(0, 1000));
  sub->add_option("--max-len", args->max_len, "Count members up to this many letters (default: max-bounces + 6, or 14)")
      ->check(CLI::Range(0, 10000));
  sub->add_option("--classes", args->classes_file, "Class file whose names ($name) the expressions may use");
  sub->add_flag("--json", args->json, "An array with one object per expression and renderer");
  add_notation_options(sub, &args->notation);
  add_limit_options(sub, &args->limits);
  add_scene_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
