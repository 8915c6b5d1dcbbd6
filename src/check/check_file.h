// Check files, the CI gate (`pathex check FILE`, grammar/check.schema.json): a list of cases (a
// renderer, an optional scene, bound, notation and class file) and their requirements, each
// decided exactly: a class's verdict, covering the scene, the light a renderer misses or
// under-samples (a reference render, bias/bias.h) and finite renders. A failure names the verdict
// found and the shortest counterexample.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bias/bias.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "io/estimate_text.h"
#include "reach/query.h"

namespace pathex {

// {"missed": {"max_share": 0.01, "spp": 64, "reference": "bdpt"}}: the renderer misses at most
// max_share of the scene's light as a reference render at spp finds it (pathex bias).
//
// {"undersampled": {"spp": 4, "reference_spp": 64, "max_flagged": 0}}: the same reference render
// and one of the renderer at spp; passes when at most max_flagged of the image, its classes and
// its listed paths hold light the renderer can sample but under-samples (BiasReport::undersampled).
struct MissedRequirement {
  double max_share = 0;
  std::uint64_t spp = 64;  // the reference's
  std::string reference;   // empty: bias's default reference
  bool undersampled = false;
  std::uint64_t renderer_spp = 16;
  std::uint64_t max_flagged = 0;
  double min_share = 0.01;
};

// {"finite": true, "spp": N, "seed": N}: a render of the case's scene with its renderer has no
// non-finite sample (DESIGN §7: any is a bug).
struct FiniteRequirement {
  std::uint64_t spp = 16, seed = 1;
};

struct Requirement {
  std::string pointer;
  bool covers_scene = false;
  std::optional<MissedRequirement> missed;
  std::optional<FiniteRequirement> finite;
  std::string cls;
  std::string verdict;  // reachable, not-unreachable, unreachable, partial, empty
  std::string describe() const {
    if (missed && missed->undersampled)
      return "under-samples at most " + std::to_string(missed->max_flagged) + " classes or paths at " +
             std::to_string(missed->renderer_spp) + " spp";
    if (missed) return "misses at most " + percent(missed->max_share, 2) + " of the scene's light";
    if (finite) return "renders finite (" + std::to_string(finite->spp) + " spp, seed " + std::to_string(finite->seed) + ")";
    return covers_scene ? "covers the scene" : cls + " is " + verdict;
  }
};

struct Case {
  std::string pointer;
  std::string name;
  std::string renderer;
  std::string scene;
  std::optional<int> max_bounces;
  Notation notation = Notation::kFull;
  std::string classes;
  std::vector<Requirement> require;
};

struct Outcome {
  const Case* c = nullptr;
  const Requirement* r = nullptr;
  bool passed = false;
  std::string verdict;
  std::optional<Witness> counterexample;
  std::optional<BiasReport> missed;  // a missed requirement's measurement
  double time_s = 0.0;
};

// The cases of a check file's `text` (read from `file`, which errors name with JSON pointers).
Result<std::vector<Case>> parse_check(const std::string& text, const std::string& file);

// Decides every requirement of every case, in order. Relative paths in the cases resolve against
// the folder of `file`, then the current one; errors about a file a case names point at the
// case's key in `file`.
Result<std::vector<Outcome>> decide_check(const std::string& file, const std::vector<Case>& cases, const Limits& limits);

}  // namespace pathex
