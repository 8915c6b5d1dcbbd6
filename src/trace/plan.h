// The plan of a render (DESIGN §11): what a render of a profile over a scene runs, decided once,
// before it, from the scene, the profile, the bound and the requested classes (pathex trace
// --only, a class file's "render": true). `pathex trace` (and through it the MPI ranks),
// `converge`, `bias` and the C++ API all call plan_render(), so for the same inputs they run the
// same strategies, aim the same lights and record the same paths. A plan holds
//   - the strategies that run: the profile pruned to those that can sample a path of the scene's
//     universe and of the requested classes, their subpath lengths narrowed, and under requested
//     classes reduced to a cheaper cover when one saves enough (trace/prune.h);
//   - the emission narrowing: the point and spot lights whose every recorded path scatters
//     specularly at its first vertex; render() gives each a decorator that draws its first
//     direction only towards the shapes with a specular component (trace/emission_cones.h);
//   - the path filter: which sampled paths are recorded, and where a subpath stops because no
//     recorded path can be completed from it (trace/prune.h).
// The estimator reads the strategies, the filter and the lights' emission; it never sees a class.
#pragma once

#include <vector>

#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "reach/profile.h"
#include "scene/scene.h"
#include "trace/prune.h"

namespace pathex {

struct RenderPlan {
  Profile profile;                      // the strategies that run, narrowed; MIS is over these
  std::vector<PrunedStrategy> changes;  // each strategy not run or narrowed, in the profile's order, and why
  PathFilter filter;                    // what is recorded (default: every path)
  std::vector<int> aimed_lights;        // indices into the scene's "lights" whose emission is aimed
  // No strategy can sample a requested path (with nothing requested a plan never says so: a scene
  // whose lights no strategy reaches renders black with the profile whole).
  bool samples_nothing() const { return profile.strategies.empty(); }
};

// The plan that runs `profile` whole and records every path: what render(scene, profile, …) runs.
RenderPlan whole_plan(const Profile& profile);

// The plan of a render of `profile` over `scene` with at most `max_bounces` interior vertices,
// recording the paths of `requested` (empty: every path). The plan owns what it needs of them.
Result<RenderPlan> plan_render(const Scene& scene, const Profile& profile, int max_bounces,
                               const std::vector<const PathClass*>& requested, const Limits& limits);

}  // namespace pathex
