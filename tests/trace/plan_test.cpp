// The plan of a render (trace/plan.h) is made once, by plan_render(), for every caller: `pathex
// trace` (whose run.json lists the plan's changes and aimed lights, and whose histogram's paths are
// the ones its filter records), `converge` and `bias` (which call it with the same arguments) and
// the C++ API (api::Plan). For the same scene, renderer and requested classes they run the same
// strategies and record the same paths.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "pathex/pathex.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "support/cli_run.h"
#include "trace/accel/path_ids.h"
#include "trace/plan.h"

namespace pathex {
namespace {

const std::string kScenes = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/";

struct Case {
  std::string scene, renderer;
  std::vector<std::string> only;
  std::vector<int> aimed;  // the lights the plan aims
};

// The requested classes as pathex trace compiles --only without a class file: a built-in by its
// $name, any other expression for the scene's ends.
std::vector<const PathClass*> requested_classes(const Scene& scene, const std::vector<std::string>& only) {
  static std::vector<std::unique_ptr<PathClass>> keep;
  const SceneTypes types = scene_types(scene);
  ClassOptions o;
  o.ends.lights.assign(types.lights.begin(), types.lights.end());
  o.ends.sensors = {types.sensor};
  std::vector<const PathClass*> out;
  for (const std::string& e : only) {
    const PathClass* same = nullptr;
    for (const auto& c : ClassTable::builtins().builtin_classes())
      if (e[0] == '$' && c->name == e.substr(1)) same = c.get();
    if (same == nullptr) {
      keep.push_back(std::make_unique<PathClass>(compile_class(e, o).expect("a test class")));
      same = keep.back().get();
    }
    out.push_back(same);
  }
  return out;
}

// Every full path L c0 … c(k+2) E with `letters` letters between L and E.
std::vector<std::string> all_paths(int letters) {
  std::vector<std::string> out;
  for (std::uint32_t bits = 0; bits < (1u << letters); ++bits) {
    std::string p = "L";
    for (int i = 0; i < letters; ++i) p += (bits >> i) & 1 ? 'S' : 'D';
    out.push_back(p + "E");
  }
  return out;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> c = {
      {"point-glass.json", "bdpt", {"$caustic"}, {0}},  // narrowed, the point light aimed
      {"point-glass.json", "lt", {"$caustic"}, {0}},    // aimed under light tracing too
      {"point-glass.json", "pt-nee", {"$caustic"}, {}},  // a point light's caustics: nothing to render
      {"cornell.json", "bdpt", {"$direct"}, {}},        // a cover of the joins
      {"cornell.json", "pt-nee", {"L.{8,}E", "$caustic"}, {}},
      {"point-glass.json", "pt-nee", {}, {}},           // nothing requested: the universe's pruning alone
      {"mirror-ortho.json", "bdpt+ortho", {"$direct"}, {}},
  };
  return c;
}

// The library's plan of case `c` over `scene`, as pathex trace makes it (its profile's bound, else 16).
RenderPlan library_plan(const Scene& scene, const Case& c) {
  const Profile profile = resolve_profile(c.renderer, Limits{}).expect("a profile");
  return plan_render(scene, profile, profile.max_bounces.value_or(16), requested_classes(scene, c.only), Limits{}).expect("a plan");
}

// The library's plan and the API's: the same strategies (name and what runs), the same aimed
// lights, and the same filter on every path of the scene up to 12 letters.
TEST(Plan, TheApiGetsTheLibrarysPlan) {
  for (const Case& c : cases()) {
    const std::string what = c.scene + " " + c.renderer;
    const Scene scene = load_scene_file(kScenes + c.scene).expect("a sample scene");
    const RenderPlan plan = library_plan(scene, c);
    const api::Plan ap(api::Renderer(c.renderer), kScenes + c.scene, c.only);
    ASSERT_TRUE(ap.ok()) << what << ": " << ap.error();
    std::vector<std::string> strategies;
    for (const Strategy& st : plan.profile.strategies) strategies.push_back(st.name + " " + st.describe());
    EXPECT_EQ(ap.strategies(), strategies) << what;
    EXPECT_EQ(plan.aimed_lights, c.aimed) << what;
    EXPECT_EQ(ap.aimed_lights(), plan.aimed_lights) << what;
    EXPECT_FALSE(plan.changes.empty()) << what;  // every case leaves out or narrows some strategy
    const Dfa universe = scene_universe(scene_types(scene));
    int recorded = 0, checked = 0;
    for (int n = 4; n <= 12; ++n)
      for (const std::string& p : all_paths(n)) {
        if (!universe.accepts(p)) continue;
        ++checked;
        const bool r = plan.filter.records(accel::pack(p));
        recorded += r ? 1 : 0;
        EXPECT_EQ(ap.records(p), r) << what << ": " << p;
      }
    EXPECT_GT(checked, 100) << what;
    EXPECT_GT(recorded, 0) << what;
    EXPECT_EQ(recorded == checked, c.only.empty()) << what;
  }
}

// pathex trace renders the library's plan: run.json's "pruned" lists exactly the plan's changes
// and aimed lights, and every path in histogram.json is one the plan's filter records.
TEST(Plan, TraceRendersTheLibrarysPlan) {
  for (const Case& c : cases()) {
    const std::string what = c.scene + " " + c.renderer;
    const Scene scene = load_scene_file(kScenes + c.scene).expect("a sample scene");
    const RenderPlan plan = library_plan(scene, c);
    const std::string out = (test::scratch_dir() / ("plan-" + c.renderer + "-" + std::to_string(&c - cases().data()))).string();
    std::string args = "trace samples/scenes/" + c.scene + " --renderer " + c.renderer + " --spp 2 --resolution 12x12 --quiet --out " +
                       test::shell_quote(out);
    for (const std::string& e : c.only) args += " --only " + test::shell_quote(e);
    const test::CliRun r = test::run_pathex(args);
    if (plan.samples_nothing()) {
      EXPECT_EQ(r.code, 1) << what;
      EXPECT_NE(r.out.find("nothing to render: no strategy of " + c.renderer), std::string::npos) << what << ": " << r.out;
      continue;
    }
    ASSERT_EQ(r.code, 0) << what << ": " << r.err;
    const nlohmann::json run = nlohmann::json::parse(test::read_file(out + "/run.json"));
    std::vector<std::string> pruned, planned;
    for (const nlohmann::json& p : run.value("pruned", nlohmann::json::array()))
      pruned.push_back(p.at("strategy").get<std::string>() + " " + p.at("profile").get<std::string>() + " -> " +
                       (p.at("runs").is_null() ? std::string("(not run)") : p.at("runs").get<std::string>()));
    for (const PrunedStrategy& p : plan.changes) planned.push_back(p.strategy + " " + p.was + " -> " + (p.now.empty() ? "(not run)" : p.now));
    std::size_t aimed = 0;
    for (std::size_t i = 0; i < pruned.size(); ++i)
      if (pruned[i].rfind("light /lights/", 0) == 0) {
        ASSERT_LT(aimed, plan.aimed_lights.size()) << what << ": " << pruned[i];
        EXPECT_EQ(pruned[i].rfind("light /lights/" + std::to_string(plan.aimed_lights[aimed]) + " ", 0), 0u) << what;
        ++aimed;
        pruned.erase(pruned.begin() + static_cast<std::ptrdiff_t>(i--));
      }
    EXPECT_EQ(aimed, plan.aimed_lights.size()) << what;
    EXPECT_EQ(pruned, planned) << what;
    const nlohmann::json hist = nlohmann::json::parse(test::read_file(out + "/histogram.json"));
    int paths = 0;
    for (const nlohmann::json& p : hist.at("paths")) {
      const std::string path = p.at("path").get<std::string>();
      if (path.front() != 'L') continue;  // the "other" row
      ++paths;
      EXPECT_TRUE(plan.filter.records(accel::pack(path))) << what << ": " << path;
    }
    EXPECT_GT(paths, 0) << what;
  }
}

}  // namespace
}  // namespace pathex
