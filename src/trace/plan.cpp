// plan_render() (trace/plan.h): the strategy pruning, the path filter and the emission narrowing
// of one render, in the order each needs the one before: the filter decides which lights are
// aimed, and only a profile that traces light subpaths past their first vertex aims any.
#include "trace/plan.h"

#include <algorithm>
#include <variant>

#include "automata/ops.h"
#include "scene/universe.h"

namespace pathex {
namespace {

// Whether a strategy of `profile` traces a light subpath beyond its first vertex (some s >= 2)
// within the bound: only then does a light's first direction come from its emission sampling.
bool walks_from_lights(const Profile& profile, int max_bounces) {
  if (max_bounces < 1) return false;
  return std::any_of(profile.strategies.begin(), profile.strategies.end(),
                     [](const Strategy& st) { return st.s.hi == Range::kOpen || st.s.hi >= 2; });
}

}  // namespace

RenderPlan whole_plan(const Profile& profile) {
  RenderPlan plan;
  plan.profile = profile;
  return plan;
}

Result<RenderPlan> plan_render(const Scene& scene, const Profile& profile, int max_bounces,
                               const std::vector<const PathClass*>& requested, const Limits& limits) {
  const SceneTypes types = scene_types(scene);
  // --- the strategies: those that can sample a requested path of this scene ---
  std::optional<Dfa> language;
  if (!requested.empty()) {
    Dfa r = dfa_empty();
    for (const PathClass* c : requested) r = dfa_union(r, c->dfa);
    language = std::move(r);
  }
  Result<ProfilePruning> pruning = prune_profile(profile, max_bounces, scene_universe(types), language, limits);
  if (!pruning) return pruning.error();
  RenderPlan plan;
  if (pruning->samples_nothing() && requested.empty()) {
    // Nothing of the scene can be sampled at all: the profile runs whole (a black image).
    plan.profile = profile;
  } else {
    plan.profile = std::move(pruning->profile);
    plan.changes = std::move(pruning->changes);
  }
  if (requested.empty()) return plan;
  // --- the path filter ---
  Result<PathFilter> filter = PathFilter::make(requested, limits);
  if (!filter) return filter.error();
  plan.filter = std::move(*filter);
  // --- the emission narrowing: a point or spot light whose recorded paths all scatter specularly
  // first. With a pinhole or a lens, whose first letter c(k+1) is D, the test also rules out the
  // light seen directly; other sensors are not aimed at. ---
  if (sensor_letters(types.sensor)[0] != 'D' || !walks_from_lights(plan.profile, max_bounces)) return plan;
  const std::string point = light_letters(LightType::kPoint);  // spot lights share it
  for (std::size_t i = 0; i < scene.lights.size(); ++i)
    if ((std::holds_alternative<PointLight>(scene.lights[i]) || std::holds_alternative<SpotLight>(scene.lights[i])) &&
        plan.filter.first_vertex_specular(point[0], point[1]))
      plan.aimed_lights.push_back(static_cast<int>(i));
  return plan;
}

}  // namespace pathex
