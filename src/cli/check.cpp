// pathex check: the CI gate. A check file lists cases (renderer, optional scene and bound) and
// their requirements; every requirement is decided exactly, and a failure names the verdict
// found and the shortest counterexample with its chains.
#include <chrono>
#include <filesystem>
#include <iostream>

#include "check/check_file.h"
#include "check/check_json.h"
#include "cli/bias_common.h"
#include "cli/common.h"
#include "cli/witness_text.h"
#include "io/atomic_file.h"
#include "io/estimate_text.h"
#include "io/input_file.h"
#include "io/junit.h"

namespace pathex::cli {
namespace {

struct CheckArgs {
  std::string file;
  bool json = false;
  std::string junit;
  Limits limits;
};

// Reports a check that could not be run; with --junit, the report holds it as an <error>.
int fail(const CheckArgs& a, const Error& e) {
  if (!a.junit.empty()) {
    const JUnitCase error_case{"pathex check", a.file, 0.0, false, true, "the check file could not be run", e.render()};
    Result<bool> w = write_file_atomic(a.junit, junit_xml(a.file, {error_case}));
    if (!w) report(w.error());
  }
  return report(e);
}

int run(const CheckArgs& a) {
  Result<std::string> text = read_input_file(a.file, a.limits.max_file_bytes);
  if (!text) return fail(a, text.error());
  Result<std::vector<Case>> cases = parse_check(*text, a.file);
  if (!cases) return fail(a, cases.error());
  Result<std::vector<Outcome>> decided = decide_check(a.file, *cases, a.limits);
  if (!decided) return fail(a, decided.error());
  const std::vector<Outcome>& outcomes = *decided;

  int failed = 0;
  std::vector<JUnitCase> junit;
  for (const Outcome& o : outcomes) {
    failed += o.passed ? 0 : 1;
    std::string message = o.r->describe() + ": found " + o.verdict;
    std::string details;
    if (o.counterexample) {
      const Witness& w = *o.counterexample;
      details = "shortest counterexample " + w.path + ", chains " + chains_text(w.chains, /*connectors=*/false) +
                (w.reason.empty() ? "; sampled by " + [&] {
                  std::string s;
                  for (const std::string& st : w.strategies) s += (s.empty() ? "" : ", ") + st;
                  return s;
                }() : "; " + w.reason);
    } else if (!o.passed && o.verdict == "empty") {
      details = "the class has no path in this universe";
    }
    if (!o.passed && o.missed && o.missed->undersampled) {
      const std::vector<std::string> lines = undersampled_lines(*o.missed, 3);
      for (std::size_t i = 1; i < lines.size(); ++i) details += (details.empty() ? "" : "\n      ") + lines[i].substr(2);
    } else if (!o.passed && o.missed && !o.missed->paths.empty()) {
      const MissedPath& p = o.missed->paths.front();
      details += "\n      largest missed path " + p.estimate.path + ", " + percent(p.share, 2) + " of the image, chains " +
                 chains_text(p.chains, /*connectors=*/false) + "; " + p.reason;
    }
    junit.push_back({o.c->name, o.r->describe(), o.time_s, !o.passed, false, message, details});
    if (!a.json) {
      std::cout << (o.passed ? "PASS  " : "FAIL  ") << o.c->name << ": " << o.r->describe() << " (" << o.verdict << ")\n";
      if (!o.passed && !details.empty()) std::cout << "      " << details << "\n";
    }
  }
  const int passed = static_cast<int>(outcomes.size()) - failed;
  if (a.json) {
    std::cout << check_json(a.file, outcomes) << "\n";
  } else {
    std::cout << "check: " << passed << " passed, " << failed << " failed\n";
  }
  if (!a.junit.empty()) {
    Result<bool> w = write_file_atomic(a.junit, junit_xml(a.file, junit));
    if (!w) return report(w.error());
  }
  return failed ? kExitNo : kExitOk;
}

}  // namespace

Command add_check(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* sub = app.add_subcommand("check", "CI gate: decide every requirement of a check file; exit 1 if any fails");
  sub->footer("Example:\n  pathex check samples/checks/samples.json --junit report.xml\n"
              "Check file: {\"cases\": [{\"name\": \"ptnee-ortho\", \"renderer\": \"pt-nee\", \"scene\": \"samples/scenes/mirror-ortho.json\",\n"
              "  \"max_bounces\": 8, \"require\": [{\"class\": \"LSDSDE\", \"verdict\": \"reachable\"}, {\"covers-scene\": true}]}]}\n"
              "Verdicts: reachable, not-unreachable, unreachable (also partial, empty). Exit 0 all pass, 1 a failure, 2 bad input.");
  sub->add_option("FILE", args->file, "Check file (grammar/check.schema.json)")->required();
  sub->add_flag("--json", args->json, "Machine-readable report");
  sub->add_option("--junit", args->junit, "Also write a JUnit XML report here");
  add_limit_options(sub, &args->limits);
  add_scene_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
