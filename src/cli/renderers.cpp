// pathex renderers: the built-in profiles, their strategies and what they can reach.
#include <iostream>

#include "automata/ops.h"
#include "cli/common.h"
#include "io/profile_json.h"
#include "io/reach_json.h"
#include "reach/query.h"

namespace pathex::cli {
namespace {

struct RenderersArgs {
  bool json = false;
  int witnesses = 3;
  Limits limits;
};

int run(const RenderersArgs& a) {
  const Dfa& local = ClassTable::builtins().find("local")->dfa;  // L.*DD.*E ∩ U
  Result<std::vector<Profile>> profiles = builtin_profiles(a.limits);
  if (!profiles) return report(profiles.error());
  std::vector<ProfileReach> reach;
  for (const Profile& p : *profiles) {
    Result<CompiledProfile> cp = compile_profile(p, std::nullopt, a.limits);
    if (!cp) return report(cp.error());
    const Dfa missed = dfa_difference(dfa_universe(), cp->reachable);
    const std::vector<std::string> misses = enumerate_members(missed, 16, static_cast<std::size_t>(a.witnesses));
    const bool is_local = is_equivalent(cp->reachable, local);
    const bool within_local = is_subset(cp->reachable, local);
    const std::string relation = is_local ? "exactly the local paths L.*DD.*E"
                                 : within_local ? "a proper subset of the local paths L.*DD.*E"
                                                : "beyond local sampling (uses connectors)";
    if (a.json) {
      reach.push_back({&p, cp->reachable.num_states, relation, is_local, misses});
      continue;
    }
    std::cout << p.name << (p.max_bounces ? "   (max_bounces " + std::to_string(*p.max_bounces) + ")" : "") << "\n  "
              << p.description << "\n";
    for (const Strategy& s : p.strategies) std::cout << "    " << s.name << " " << s.describe() << "\n";
    std::cout << "  reaches " << relation << " (minimal DFA " << cp->reachable.num_states << " states)\n";
    std::cout << "  shortest unreachable paths:";
    for (const std::string& m : misses) std::cout << " " << m;
    std::cout << (misses.empty() ? " none" : "") << "\n\n";
  }
  if (a.json) std::cout << renderers_json_text(reach);
  return kExitOk;
}

}  // namespace

Command add_renderers(CLI::App& app) {
  auto args = std::make_shared<RenderersArgs>();
  CLI::App* sub = app.add_subcommand("renderers", "List the built-in renderer profiles, their strategies and reachable languages");
  sub->footer("Example:\n  pathex renderers\n  pathex renderers --json | jq '.[].name'\n"
              "Profiles are the JSON files in samples/renderers (schema: grammar/profile.schema.json).");
  sub->add_flag("--json", args->json, "Machine-readable output");
  sub->add_option("--witnesses", args->witnesses, "Shortest unreachable paths to list per profile")->capture_default_str()
      ->check(CLI::Range(0, 1000));
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
