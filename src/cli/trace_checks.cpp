#include "cli/trace_checks.h"

#include <iostream>

#include "bias/unreachable_lights.h"

namespace pathex::cli {

void warn_unreachable_lights(const Scene& scene, const Profile& profile, const CompiledProfile& compiled,
                             const Dfa& universe, int bound, const Limits& limits) {
  for (const UnreachableLight& l : unreachable_lights(scene, profile, compiled, universe, bound, limits))
    std::cerr << "pathex: warning: " << profile.name << " cannot sample any path from " << l.description << " (L"
              << light_letters(l.type) << "…E), so its light is missing from the image; renderers that reach it: "
              << l.reached_by << " (--renderer NAME)\n";
}

}  // namespace pathex::cli
