// DESIGN §7: for any string, the strategies with nonzero density are exactly those whose
// language contains it, and their MIS weights sum to 1. For random full paths in every sample
// scene and every profile the tracer runs, each strategy's weight is computed from its own side
// (the vertices re-split at its join, densities recomputed as it would sample them) and summed.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex {
namespace {

TEST(Mis, WeightsOfEveryStrategySumToOne) {
  const std::string dir = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes";
  std::size_t checked = 0;
  std::map<int, int> by_length;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    Result<Scene> scene = load_scene_file(entry.path().string());
    ASSERT_TRUE(scene.ok()) << scene.error().render();
    for (const char* renderer : {"bdpt", "pt-nee", "lt", "pbrt-v4-lightpath", "mitsuba3-ptracer", "pt-nee+distant",
                                 "pbrt-v4-path", "pbrt-v4-bdpt", "mitsuba3-path", "bdpt+ortho"}) {
      Result<Profile> profile = resolve_profile(renderer, Limits{});
      ASSERT_TRUE(profile.ok());
      Result<std::vector<MisCheck>> checks = check_mis_weights(*scene, *profile, 11, 300);
      ASSERT_TRUE(checks.ok()) << checks.error().render();
      for (const MisCheck& c : *checks) {
        ++checked;
        ++by_length[static_cast<int>(c.path.size())];
        EXPECT_NEAR(c.weight_sum, 1.0, 1e-4) << entry.path().filename() << " " << renderer << " " << c.path << " (s="
                                              << c.s << ", t=" << c.t << ")";
        EXPECT_EQ(c.recorded, c.path) << "the packed label differs (s=" << c.s << ", t=" << c.t << ")";
        // The per-sample sums (profiles running every plain join) are a special case of the
        // general recurrence and must give its weight.
        EXPECT_NEAR(c.weight, c.weight_general, 1e-5 * std::max(1.0, c.weight_general))
            << entry.path().filename() << " " << renderer << " " << c.path << " (s=" << c.s << ", t=" << c.t << ")";
      }
    }
  }
  EXPECT_GT(checked, 2000u);
  EXPECT_GE(by_length.size(), 5u);  // paths of many lengths
}

}  // namespace
}  // namespace pathex
