// Issue 14, "effects the scene cannot have are not simulated" (trace/scene_features.h): each
// sample scene's features are what its materials say, and the walk, skipping what a scene's
// features rule out, traces exactly (bit for bit) the subpaths it traces with every feature on,
// so that skipping the Dirac and refraction bookkeeping changes nothing but the time.
#include "trace/scene_features.h"

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/integrator.h"
#include "trace/render.h"

namespace pathex::tracer {

// The integrator's subpaths, traced by its public stages (as tests/trace/mis_test.cpp drives them).
struct IntegratorTestAccess {
  static int eye(const Integrator& in, Integrator::Thread& th, Sampler& rng, int px, int py) { return in.eye_subpath(th, rng, px, py); }
  // The light's first direction drawn in advance, after its pick and point (render.cpp's kLightRayDim).
  static int light(const Integrator& in, Integrator::Thread& th, Sampler& rng) {
    return in.light_subpath(th, rng, rng.at2d(rng.dimension() + 3));
  }
};

namespace {

// A scene of samples/scenes/, or of bench/scenes/ when `name` starts with "bench/".
Scene sample_scene(const std::string& name) {
  const std::string dir = name.starts_with("bench/") ? "/" : "/samples/scenes/";
  Result<Scene> scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + dir + name);
  EXPECT_TRUE(scene.ok()) << scene.error().render();
  return std::move(*scene);
}

TEST(SceneFeatures, FromTheMaterials) {
  const std::map<std::string, SceneFeatures> expected = {
      {"cornell.json", {/*specular=*/true, /*transmission=*/true}},
      {"bench/scenes/cornell-diffuse.json", {false, false}},
      {"point-plane.json", {false, false}},
      {"point-mirror-caustic.json", {true, false}},
      {"mirror-ortho.json", {true, false}},
      {"point-glass.json", {true, true}},
  };
  for (const auto& [name, features] : expected) {
    const Scene scene = sample_scene(name);
    const RenderScene rs = make_render_scene(scene).expect("a scene the tracer renders");
    EXPECT_EQ(rs.features, features) << name;
  }
  // A mixture counts its components of nonzero weight only.
  const Material mix = Mixture{{{0.5f, Diffuse{}}, {0.0f, Dielectric{}}, {0.25f, Mirror{}}}};
  const Material diffuse = Diffuse{};
  EXPECT_EQ(scene_features({&diffuse}), (SceneFeatures{false, false}));
  EXPECT_EQ(scene_features({&diffuse, &mix}), (SceneFeatures{true, false}));
  const Material glass = Dielectric{};
  EXPECT_EQ(scene_features({&glass}), (SceneFeatures{true, true}));
}

bool same_bits(const Vertex& a, const Vertex& b) {
  const auto eq = [](const vec3& x, const vec3& y) { return std::memcmp(&x, &y, sizeof(vec3)) == 0; };
  const auto feq = [](float x, float y) { return std::memcmp(&x, &y, sizeof(float)) == 0; };
  return a.kind == b.kind && a.letter == b.letter && a.pos_letter == b.pos_letter && a.finite == b.finite && eq(a.p, b.p) &&
         eq(a.n, b.n) && eq(a.beta, b.beta) && eq(a.wo, b.wo) && feq(a.pdf_fwd, b.pdf_fwd) && feq(a.pdf_rev, b.pdf_rev) &&
         a.shape == b.shape && a.light == b.light;
}

// The walk with the scene's features against the walk with every feature on, on the same
// random numbers: the same vertices, bit for bit, for both subpaths of 2000 samples per scene.
TEST(SceneFeatures, SkippingTracesTheSameSubpaths) {
  const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("the built-in bdpt");
  const StrategySet strategies = runnable_strategies(bdpt).expect("a profile the tracer runs");
  for (const char* name : {"bench/scenes/cornell-diffuse.json", "point-plane.json", "point-mirror-caustic.json"}) {
    const Scene scene = sample_scene(name);
    const RenderScene rs = make_render_scene(scene).expect("a scene the tracer renders");
    RenderScene general = make_render_scene(scene).expect("a scene the tracer renders");
    ASSERT_NE(rs.features, SceneFeatures{}) << name << ": a scene without some feature";
    general.features = SceneFeatures{};
    RenderOptions o;
    o.max_bounces = 8;
    o.rr_depth = 2;  // roulette on, so that η² would matter
    HistogramLayout layout;
    ClassImages images(1, 1, nullptr, {});
    const Integrator special(rs, strategies, o), reference(general, strategies, o);
    const auto thread = [&] {
      Integrator::Thread th{Histogram(layout, nullptr), {ClassImages::PixelSum(images)}, {}, {}, 0, {}, {}, {}};
      th.images = &images;
      th.connectors.resize(strategies.strategies.size());
      return th;
    };
    Integrator::Thread a = thread(), b = thread();
    int vertices = 0, specular = 0;
    for (int i = 0; i < 2000; ++i) {
      const int px = i % rs.camera.width, py = (i / rs.camera.width) % rs.camera.height;
      Sampler ra(7, static_cast<std::uint64_t>(i), 0, SamplerKind::kSobol), rb = ra;
      const int nta = IntegratorTestAccess::eye(special, a, ra, px, py), ntb = IntegratorTestAccess::eye(reference, b, rb, px, py);
      const int nsa = IntegratorTestAccess::light(special, a, ra), nsb = IntegratorTestAccess::light(reference, b, rb);
      ASSERT_EQ(nta, ntb) << name << " sample " << i;
      ASSERT_EQ(nsa, nsb) << name << " sample " << i;
      for (int j = 0; j < nta; ++j) ASSERT_TRUE(same_bits(a.eye[static_cast<std::size_t>(j)], b.eye[static_cast<std::size_t>(j)])) << name << " eye vertex " << j;
      for (int j = 0; j < nsa; ++j) ASSERT_TRUE(same_bits(a.light[static_cast<std::size_t>(j)], b.light[static_cast<std::size_t>(j)])) << name << " light vertex " << j;
      vertices += nta + nsa;
      for (int j = 0; j < nta; ++j) specular += a.eye[static_cast<std::size_t>(j)].letter == 'S';
    }
    EXPECT_GT(vertices, 2000 * 3) << name << ": subpaths long enough to compare";
    EXPECT_EQ(specular > 0, rs.features.specular) << name << ": Dirac vertices compared where the scene has them";
  }
}

}  // namespace
}  // namespace pathex::tracer
