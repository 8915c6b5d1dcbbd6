#include "bias/unreachable_lights.h"

#include <map>
#include <sstream>
#include <utility>
#include <variant>

#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "trace/render.h"

namespace pathex {

namespace {

// "the point light at (0, 1.9, 0)": lights have no names, so they are told apart by where they are.
std::string describe_light(const Light& light) {
  auto at = [](const glm::vec3& v) {
    std::ostringstream o;
    o << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return o.str();
  };
  return std::visit(
      [&](const auto& l) -> std::string {
        using T = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<T, PointLight>) return "the point light at " + at(l.position);
        else if constexpr (std::is_same_v<T, SpotLight>) return "the spot light at " + at(l.position);
        else if constexpr (std::is_same_v<T, DistantLight>) return "the distant light along " + at(l.direction);
        else return "the laser at " + at(l.position);
      },
      light);
}

}  // namespace

std::vector<UnreachableLight> unreachable_lights(const Scene& scene, const Profile& profile, const CompiledProfile& compiled,
                                              const Dfa& universe, int bound, const Limits& limits) {
  std::vector<UnreachableLight> found;
  QueryOptions qo;
  qo.universe = universe;
  qo.max_bounces = bound;
  qo.witnesses = 0;
  qo.max_len = 0;
  ClassOptions copts;
  copts.limits = limits;
  std::vector<std::pair<LightType, std::string>> lights;  // type, description
  for (const Shape& sh : scene.shapes)
    if (sh.emissive()) lights.emplace_back(LightType::kArea, "the emissive shape " + sh.pointer);
  for (const Light& l : scene.lights) {
    const LightType t = std::holds_alternative<DistantLight>(l) ? LightType::kDistant
                        : std::holds_alternative<LaserLight>(l) ? LightType::kLaser
                                                                : LightType::kPoint;
    lights.emplace_back(t, describe_light(l));
  }
  std::map<LightType, std::string> alternatives;  // per unreachable type: the renderers that reach it
  for (const auto& [type, description] : lights) {
    if (!alternatives.count(type)) {
      // Every path that starts at a light of this type: L, the light's two letters, anything, E.
      Result<PathClass> from_light = compile_class("L" + light_letters(type) + ".*E", copts);
      if (!from_light) continue;
      Result<QueryResult> q = query(*from_light, compiled, qo);
      if (!q || q->verdict != Verdict::kUnreachable) {
        alternatives[type] = "";
        continue;
      }
      // The built-in profiles are embedded texts; if the limits in force refuse one, the warning
      // names no alternative rather than failing the render it only advises on.
      Result<std::vector<Profile>> builtins = builtin_profiles(limits);
      if (!builtins) continue;
      std::string others;
      for (const Profile& other : *builtins) {
        if (other.name == profile.name || !runnable_strategies(other)) continue;
        Result<CompiledProfile> oc = compile_profile(other, bound, limits);
        if (!oc) continue;
        Result<QueryResult> oq = query(*from_light, *oc, qo);
        if (oq && oq->verdict != Verdict::kUnreachable && oq->verdict != Verdict::kEmpty)
          others += (others.empty() ? "" : ", ") + other.name;
      }
      alternatives[type] = others.empty() ? "none of the built-in renderers" : others;
    }
    if (alternatives[type].empty()) continue;
    found.push_back({description, type, alternatives[type]});
  }
  return found;
}

}  // namespace pathex
