// Ray offsets come from each hit point's own rounding-error bound (trace/embree_scene.h), not from
// the scene's size: adding a far-off ground plane or sphere to the Cornell box must leave its image
// unchanged. Each variant is rendered with the same seed as the plain box; the image means must
// agree within 3 standard errors of their difference (each render's batch-means error, combined
// as if independent, which only widens the tolerance for renders that share their random numbers).
// Before the change the plane 1e4 below moved the mean from 0.388 to 0.358, 1e6 below to 0.00003,
// and 1e19 below made the image black.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "support/stat_seed.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex {
namespace {

// The embedded Cornell box with `extra` (a JSON shape) appended to its shapes.
std::string cornell_with(const std::string& extra) {
  std::string text = default_scene_json();
  const std::size_t end = text.rfind(']');
  return text.substr(0, end) + (extra.empty() ? "" : ",\n    " + extra) + text.substr(end);
}

struct Mean {
  double luminance = 0, std_error = 0;
  std::uint64_t nonfinite = 0;
};

Mean render_mean(const std::string& scene_json) {
  Result<Scene> scene = load_scene_json(scene_json, ".", "test");
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().render());
  if (!scene) return {};
  scene->camera.width = scene->camera.height = 32;
  Result<Profile> profile = resolve_profile("bdpt", Limits{});
  RenderOptions o;
  o.spp = 16;
  o.seed = test::stat_seed(11);
  EXPECT_TRUE(profile.ok());  // a helper returning a value: the read below aborts if it is not
  Result<RenderOutput> out = render(*scene, *profile, nullptr, o);
  EXPECT_TRUE(out.ok());
  if (!out) return {};
  RunInfo info;
  info.spp = o.spp;
  Result<HistogramReport> rep = make_report(out->histogram, info, nullptr, {});
  EXPECT_TRUE(rep.ok());
  return {rep->total.luminance, rep->total.std_error, out->histogram.nonfinite()};
}

TEST(FarGeometry, LeavesTheCornellBoxUnchanged) {
  const Mean box = render_mean(cornell_with(""));
  ASSERT_GT(box.luminance, 0.3);
  ASSERT_GT(box.std_error, 0.0);
  const std::string white = R"(, "material": "white"})";
  const struct {
    const char* what;
    std::string shape;
  } variants[] = {
      {"a ground plane 1e4 below", R"({"type": "quad", "corner": [-1e4, -1e4, 1e4], "edge1": [2e4, 0, 0], "edge2": [0, 0, -2e4])" + white},
      {"a ground plane 1e6 below", R"({"type": "quad", "corner": [-1e6, -1e6, 1e6], "edge1": [2e6, 0, 0], "edge2": [0, 0, -2e6])" + white},
      {"a ground plane 1e19 below", R"({"type": "quad", "corner": [-1e19, -1e19, 1e19], "edge1": [2e19, 0, 0], "edge2": [0, 0, -2e19])" + white},
      {"a sphere at 1e6", R"({"type": "sphere", "center": [0, 0, 1e6], "radius": 1)" + white},
      {"a sphere of radius 1e5 at 1e6", R"({"type": "sphere", "center": [1e6, 0, 0], "radius": 1e5)" + white},
      {"a disk 1e6 below", R"({"type": "disk", "center": [0, -1e6, 0], "normal": [0, 1, 0], "radius": 1e6)" + white},
  };
  for (const auto& v : variants) {
    const Mean m = render_mean(cornell_with(v.shape));
    // Six comparisons at a family-wise false-failure rate of 0.1 % (Šidák, t with 16 dof).
    const double tolerance = test::family_sigmas(6) * std::sqrt(box.std_error * box.std_error + m.std_error * m.std_error);
    EXPECT_LE(std::fabs(m.luminance - box.luminance), tolerance)
        << v.what << ": mean " << m.luminance << " ± " << m.std_error << ", the box alone " << box.luminance << " ± "
        << box.std_error;
    EXPECT_EQ(m.nonfinite, 0u) << v.what;
  }
}

}  // namespace
}  // namespace pathex
