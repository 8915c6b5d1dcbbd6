// Rendering only what is asked (DESIGN §11, issue 14): strategy pruning by the checker, --only
// renders against the same class taken from a full render, dead-state termination against the
// classifier, and "not rendered" in pathex trace's outputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "automata/ops.h"
#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "trace/plan.h"
#include "trace/prune.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "trace/render.h"
#include "support/compare_estimates.h"
#include "support/stat_seed.h"

namespace pathex {
namespace {

const std::string kScenes = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/";

Scene scene_at(const std::string& name, int size) {
  Scene s = load_scene_file(kScenes + name).expect("a sample scene");
  s.camera.width = size;
  s.camera.height = size;
  return s;
}

ClassOptions options_for(const Scene& scene) {
  const SceneTypes types = scene_types(scene);
  ClassOptions o;
  o.ends.lights.assign(types.lights.begin(), types.lights.end());
  o.ends.sensors = {types.sensor};
  return o;
}

// The classes of `exprs`, compiled for the scene's ends, kept alive for the test.
std::vector<const PathClass*> classes_for(const Scene& scene, const std::vector<std::string>& exprs) {
  static std::vector<std::unique_ptr<PathClass>> keep;
  std::vector<const PathClass*> out;
  for (const std::string& e : exprs) {
    keep.push_back(std::make_unique<PathClass>(compile_class(e, options_for(scene)).expect("a test class")));
    keep.back()->name = e;
    out.push_back(keep.back().get());
  }
  return out;
}

ProfilePruning prune(const Scene& scene, const std::string& renderer, const std::vector<const PathClass*>& requested,
                     int max_bounces) {
  const Profile p = resolve_profile(renderer, Limits{}).expect("a built-in profile");
  std::optional<Dfa> r;
  if (!requested.empty()) {
    r = dfa_empty();
    for (const PathClass* c : requested) r = dfa_union(*r, c->dfa);
  }
  return prune_profile(p, max_bounces, scene_universe(scene_types(scene)), r, Limits{}).expect("pruning");
}

const PrunedStrategy* change_of(const ProfilePruning& p, const std::string& strategy) {
  for (const PrunedStrategy& c : p.changes)
    if (c.strategy == strategy) return &c;
  return nullptr;
}

TEST(Pruning, TheIssuesExamples) {
  // Only point lights: emitter hits are never tested.
  const Scene point = scene_at("point-plane.json", 8);
  const ProfilePruning pt_nee = prune(point, "pt-nee", {}, 8);
  const PrunedStrategy* hit = change_of(pt_nee, "emitter-hit");
  ASSERT_NE(hit, nullptr);
  EXPECT_EQ(hit->now, "");
  EXPECT_EQ(pt_nee.profile.strategies.size(), 1u);
  EXPECT_EQ(pt_nee.profile.strategies[0].name, "nee");
  // bdpt keeps every s but 0 (the eye subpath hitting a light).
  const ProfilePruning bdpt = prune(point, "bdpt", {}, 8);
  ASSERT_EQ(bdpt.profile.strategies.size(), 1u);
  EXPECT_EQ(bdpt.profile.strategies[0].s.lo, 1);
  // An orthographic sensor: no light tracing.
  const Scene ortho = scene_at("mirror-ortho.json", 8);
  const ProfilePruning lt = prune(ortho, "lt", {}, 8);
  const PrunedStrategy* splat = change_of(lt, "light-splat");
  ASSERT_NE(splat, nullptr);
  EXPECT_EQ(splat->now, "");
  EXPECT_EQ(prune(ortho, "bdpt", {}, 8).profile.strategies.at(0).t.lo, 2);
  // Caustics in a scene without a specular material: nothing runs.
  EXPECT_TRUE(prune(point, "bdpt", classes_for(point, {"$caustic"}), 8).samples_nothing());
  EXPECT_TRUE(prune(point, "pt-nee", classes_for(point, {"$caustic"}), 8).samples_nothing());
  // A class every strategy meets prunes nothing on a scene that has every end and material.
  const Scene cornell = scene_at("cornell.json", 8);
  EXPECT_TRUE(prune(cornell, "pt", {}, 8).changes.empty());
  // NEE cannot sample a caustic (its light-side join letters are DD right after the light).
  const ProfilePruning caustic = prune(cornell, "pt-nee", classes_for(cornell, {"$caustic"}), 8);
  ASSERT_NE(change_of(caustic, "nee"), nullptr);
  EXPECT_EQ(change_of(caustic, "nee")->now, "");
}

// "bdpt (2, DD, 1)" -> {"bdpt", 2, 1}
struct TechniqueName {
  std::string strategy;
  int s = 0, t = 0;
};
TechniqueName parse_technique(const std::string& name) {
  static const std::regex re(R"(^(.*) \((\d+), [^,]+, (\d+)\)$)");
  std::smatch m;
  EXPECT_TRUE(std::regex_match(name, m, re)) << name;
  return {m[1], std::stoi(m[2]), std::stoi(m[3])};
}

// A strategy the checker prunes (or a subpath length it narrows away) contributes nothing to a full
// render of the whole profile: over every sample scene and every built-in profile the tracer runs.
TEST(Pruning, APrunedStrategyNeverContributes) {
  constexpr int kBounces = 6;
  int scenes = 0, pruned_seen = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".json") continue;
    const Scene scene = scene_at(entry.path().filename().string(), 12);
    ++scenes;
    for (const Profile& profile : builtin_profiles(Limits{}).expect("the built-in profiles")) {
      if (!runnable_strategies(profile).ok()) continue;
      const ProfilePruning p = prune(scene, profile.name, {}, kBounces);
      if (p.changes.empty()) continue;
      ++pruned_seen;
      RenderOptions o;
      o.spp = 2;
      o.max_bounces = kBounces;
      o.images = false;
      o.threads = 1;
      const RenderOutput out = render(scene, profile, nullptr, o).expect("a render");
      const HistogramReport rep = make_report(out.histogram, RunInfo{}, nullptr, {}).expect("a report");
      for (const PathEstimate& path : rep.paths)
        for (const TechniqueEstimate& te : path.strategies) {
          const TechniqueName t = parse_technique(te.name);
          const Strategy* kept = nullptr;
          for (const Strategy& st : p.profile.strategies)
            if (st.name == t.strategy) kept = &st;
          const bool runs = kept != nullptr && kept->s.contains(t.s) && kept->t.contains(t.t);
          EXPECT_TRUE(runs || te.samples == 0) << entry.path().filename() << " " << profile.name << ": " << te.name
                                               << " contributed to " << path.path << " though the checker prunes it";
        }
    }
  }
  EXPECT_GE(scenes, 9);
  EXPECT_GE(pruned_seen, 10);  // the assertion above ran on many pruned profiles
}

// The paths of class `expr` in a render of `scene` by `renderer` — the full profile with every
// path recorded, or (only) the pruned profile recording only that class — as a report whose
// `paths` are the class's and whose `total` is the class's estimate.
HistogramReport render_class(const Scene& scene, const std::string& renderer, const std::string& expr, bool only,
                             std::uint64_t seed, std::uint64_t spp, int max_bounces) {
  const std::vector<const PathClass*> classes = classes_for(scene, {expr});
  const Classifier cl = Classifier::build(classes, Limits{}).expect("a classifier");
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.max_bounces = max_bounces;
  o.images = false;
  const Profile full = resolve_profile(renderer, Limits{}).expect("a profile");
  const RenderOutput out = (only ? render(scene, plan_render(scene, full, max_bounces, classes, Limits{}).expect("a plan"), &cl, o)
                                 : render(scene, full, &cl, o))
                               .expect("a render");
  HistogramReport rep = make_report(out.histogram, RunInfo{}, &cl, {{expr, expr}}).expect("a report");
  std::erase_if(rep.paths, [&](const PathEstimate& p) { return !classes[0]->dfa.accepts(p.path); });
  rep.total = rep.classes.at(0).estimate;
  return rep;
}

// An --only render of one class agrees with the class taken from a full render (independent
// seeds), path by path by the shared comparison rule (tests/support/compare_estimates.h: every
// path of the class above 0.5 % of it, 0.1 % together), so that a path the pruned profile lost
// shows by name.
//
// Per path, and at 21 x 21: issue 36's sweep failed 5 of 100 seeds when the classes were compared
// as one number each at 16 x 16, all a stderr far below the spread over seeds (cornell.json's
// $direct, bdpt: 0.08965 ± 0.00032 against 0.09298 ± 0.00012 at seed 17, where seeds 1-4 read
// ± 0.0017-0.0020; mirror-ortho.json's one path LSDDSDE, ± 0.000024-0.000133 over four seeds).
// At a width of 16 the 16 pixel groups (pixel p's group is p mod 16) are the image's columns, so
// the variance of an edge that runs down a few columns (the lamp's, the mirror's) falls in one or
// two groups and the stderr has one or two effective degrees of freedom, not 16. At 21 x 21 a
// group is x + 5y mod 16, which spreads every row and column over all groups; the lamp seen
// directly, a few pixels, is then a path of its own with its own few degrees of freedom. (At
// 256 x 256, cornell.json's total under pt-nee: the stderr's spread over 40 seeds implies 15
// degrees of freedom, 21 at 255 x 255: an edge is one column of many there.)
TEST(Only, AgreesWithTheClassOfAFullRender) {
  struct Case {
    std::string scene, renderer, expr;
  };
  const std::vector<Case> cases = {
      {"point-glass.json", "bdpt", "$caustic"},       {"point-glass.json", "pt-nee", "$direct"},
      {"cornell.json", "bdpt", "$direct"},            {"cornell.json", "pt-nee", "$caustic"},
      {"cornell.json", "bdpt", "L.{8,}E"},            {"point-mirror-caustic.json", "bdpt", "$caustic"},
      {"closed-sphere-point.json", "pt-nee", "L.{6}E"}, {"mirror-ortho.json", "bdpt", "$direct"},
      // The cover selected for --only (trace/prune.h) on every sample scene, several classes.
      {"point-glass.json", "bdpt", "L.{8,}E"},        {"point-glass.json", "bdpt", "$direct"},
      {"cornell.json", "bdpt", "$caustic"},           {"cornell.json", "bdpt", "L.*S.*E"},
      {"closed-sphere-point.json", "bdpt", "L.{7,}E"}, {"closed-sphere-emitting.json", "bdpt", "L.{7,}E"},
      {"closed-sphere-emitting.json", "bdpt", "$direct"}, {"point-plane.json", "bdpt", "$direct"},
      {"point-plane.json", "bdpt", "L.*E"},        {"point-mirror-caustic.json", "bdpt", "L.*E"},
      {"mirror-ortho.json", "bdpt", "L.*S.*E"},        {"laser.json", "bdpt", "L.{6,}E"},
      {"spotmeter-caustic.json", "bdpt", "L.*E"}, {"sun-window.json", "pt-nee+distant", "$direct"},
      {"sun-window.json", "bdpt", "L.{7,}E"},
  };
  std::vector<test::Comparison> comparisons;
  int sparse = 0;
  for (const Case& c : cases) {
    const Scene scene = scene_at(c.scene, 21);
    const std::string what = c.scene + " " + c.renderer + " " + c.expr;
    const HistogramReport full = render_class(scene, c.renderer, c.expr, false, test::stat_seed(11), 32, 10);
    const HistogramReport only = render_class(scene, c.renderer, c.expr, true, test::stat_seed(11) + 1, 32, 10);
    EXPECT_GT(full.total.luminance, 0.0) << what;
    EXPECT_GT(only.total.luminance, 0.0) << what;
    sparse += test::compare_paths(full, only, 0.005, what + ": full against only", &comparisons);
  }
  EXPECT_GE(comparisons.size(), cases.size()) << sparse << " sparse";
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

Dfa union_of(const std::vector<const PathClass*>& classes) {
  Dfa u = dfa_empty();
  for (const PathClass* c : classes) u = dfa_union(u, c->dfa);
  return u;
}

// The cover --only runs (trace/prune.h) samples every requested path the whole profile samples:
// checked with the automata (covers()) and, independently of them, against the definition of a
// strategy (strategy_samples()) on the requested paths up to 11 letters, for every sample scene,
// two profiles and four classes.
TEST(Cover, TheSelectedCoverSamplesEveryRequestedPath) {
  constexpr int kBounces = 5;
  int reduced = 0, paths = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".json") continue;
    const Scene scene = scene_at(entry.path().filename().string(), 8);
    const Dfa universe = scene_universe(scene_types(scene));
    for (const std::string renderer : {"bdpt", "pt-nee"})
      for (const std::string expr : {"$caustic", "$direct", "L.{7,}E", "L.*S.*E"}) {
        const std::vector<const PathClass*> classes = classes_for(scene, {expr});
        const ProfilePruning p = prune(scene, renderer, classes, kBounces);
        if (p.samples_nothing()) continue;
        const std::string what = entry.path().filename().string() + " " + renderer + " " + expr;
        const Profile full = resolve_profile(renderer, Limits{}).expect("a profile");
        const Dfa requested = union_of(classes);
        EXPECT_TRUE(covers(p.profile, full, kBounces, universe, requested, Limits{}).expect("a cover check")) << what;
        const Dfa sampled = reachable_language(full, kBounces, Limits{}).expect("the profile's language");
        for (const std::string& path : enumerate_members(dfa_intersect(dfa_intersect(universe, requested), sampled), 11, 400)) {
          bool any = false;
          for (const Strategy& st : p.profile.strategies) any = any || strategy_samples(st, path, kBounces);
          EXPECT_TRUE(any) << what << ": " << path << " is sampled by " << renderer << " but by none of the cover";
          ++paths;
        }
        for (const PrunedStrategy& c : p.changes) reduced += c.reason.find("cheapest cover") != std::string::npos ? 1 : 0;
      }
  }
  EXPECT_GE(reduced, 10);  // the check above ran on many reduced profiles
  EXPECT_GE(paths, 1000);
}

// A connector's paths keep the joins that sample them too: the cover is chosen among the joins for
// every requested path a join samples, with the connectors kept beside them, so MIS weighs the two
// as in a full render. (It once left a connector's paths to the connector alone: bdpt+manifold's
// --only render of lamp-glass's directly seen caustic, LDDSSDDSE, dropped light tracing, and the
// manifold alone was 50× less efficient than the full render, bench/README.md.) Checked against
// the definition of a strategy on the requested paths up to 13 letters.
TEST(Cover, AConnectorsPathsKeepTheJoinsThatSampleThem) {
  constexpr int kBounces = 7;
  int both = 0;
  for (const std::string name : {"lamp-glass.json", "point-glass.json"})
    for (const std::string renderer : {"bdpt+manifold", "pt-nee+manifold"})
      for (const std::string expr : {"LDDSSDDSE", "LSDSSDDSE", "$caustic", "L.*S.*E"}) {
        const Scene scene = scene_at(name, 8);
        const std::vector<const PathClass*> classes = classes_for(scene, {expr});
        const ProfilePruning p = prune(scene, renderer, classes, kBounces);
        if (p.samples_nothing()) continue;
        const std::string what = name + " " + renderer + " " + expr;
        const Profile full = resolve_profile(renderer, Limits{}).expect("a profile");
        const Dfa requested = union_of(classes);
        const Dfa universe = scene_universe(scene_types(scene));
        const Dfa sampled = reachable_language(full, kBounces, Limits{}).expect("the profile's language");
        for (const std::string& path : enumerate_members(dfa_intersect(dfa_intersect(universe, requested), sampled), 13, 400)) {
          const auto samples = [&](const Profile& profile, bool connector) {
            for (const Strategy& st : profile.strategies)
              if ((st.connector != ConnectorKind::kNone) == connector && strategy_samples(st, path, kBounces)) return true;
            return false;
          };
          const bool by_join = samples(full, false), by_connector = samples(full, true);
          EXPECT_EQ(samples(p.profile, false), by_join) << what << ": " << path;
          EXPECT_EQ(samples(p.profile, true), by_connector) << what << ": " << path;
          both += by_join && by_connector ? 1 : 0;
        }
      }
  EXPECT_GE(both, 4);  // paths that a join and a connector both sample were met
  // The case that showed it: light tracing (4, DD, 1) beside the manifold (1, DSSD, 2).
  const Scene lamp = scene_at("lamp-glass.json", 8);
  const ProfilePruning p = prune(lamp, "bdpt+manifold", classes_for(lamp, {"LDDSSDDSE"}), kBounces);
  std::vector<std::string> runs;
  for (const Strategy& st : p.profile.strategies) runs.push_back(st.describe());
  EXPECT_EQ(runs, (std::vector<std::string>{"(4, DD, 1)", "(1, DS+D, 2) via manifold"}));
}

// covers() rejects a subset that misses a requested path, and the path it misses is one the
// subset's strategies do not sample by their definition.
TEST(Cover, ASubsetThatMissesARequestedPathIsRejected) {
  constexpr int kBounces = 8;
  const Profile full = resolve_profile("bdpt", Limits{}).expect("bdpt");
  ASSERT_EQ(full.strategies.size(), 1u);
  const auto with = [&](Range s, Range t) {
    Profile p = full;
    p.strategies[0].s = s;
    p.strategies[0].t = t;
    return p;
  };
  const auto missed = [&](const Profile& kept, const Scene& scene, const std::string& expr) {
    const Dfa universe = scene_universe(scene_types(scene));
    const Dfa requested = union_of(classes_for(scene, {expr}));
    const bool ok = covers(kept, full, kBounces, universe, requested, Limits{}).expect("a cover check");
    const Dfa wanted = dfa_intersect(dfa_intersect(universe, requested), reachable_language(full, kBounces, Limits{}).expect("R"));
    const std::optional<std::string> w = shortest_member(dfa_difference(wanted, reachable_language(kept, kBounces, Limits{}).expect("K")));
    EXPECT_EQ(ok, !w.has_value()) << expr;
    if (w) {
      EXPECT_TRUE(strategy_samples(full.strategies[0], *w, kBounces)) << *w;
      for (const Strategy& st : kept.strategies) EXPECT_FALSE(strategy_samples(st, *w, kBounces)) << *w;
    }
    return w.value_or("");
  };
  const Range any{0, Range::kOpen};
  // Light tracing alone misses the caustics of point-glass seen through the glass or a mirror
  // (a specular vertex before the pinhole); with the joins t >= 3 it covers them.
  const Scene glass = scene_at("point-glass.json", 8);
  const Profile lt = with(any, Range{1, 1});
  EXPECT_NE(missed(lt, glass, "$caustic"), "");
  Profile lt_and_eye = lt;
  lt_and_eye.strategies.push_back(with(any, Range{3, Range::kOpen}).strategies[0]);
  EXPECT_EQ(missed(lt_and_eye, glass, "$caustic"), "");
  // Next-event estimation alone misses the long paths of the Cornell box whose light first meets
  // a specular surface (L D D S …).
  const Scene cornell = scene_at("cornell.json", 8);
  const std::string w = missed(with(Range{1, 1}, any), cornell, "L.{8,}E");
  EXPECT_EQ(w.substr(0, 4), "LDDS");
  // In a closed diffuse sphere lit by a point light it samples every path alone.
  EXPECT_EQ(missed(with(Range{1, 1}, any), scene_at("closed-sphere-point.json", 8), "L.{7,}E"), "");
}

// A subpath stops exactly when its prefix (light side, read forward) or suffix (eye side, read
// backward) is dead for the requested classes: then no full path through it is requested. Checked
// on random full paths against the classifier, both ways (an alive prefix of a requested path is
// never cut).
TEST(DeadState, AStoppedSubpathCouldNotHaveContributed) {
  const Scene cornell = scene_at("cornell.json", 8);
  // Which sides can die: a caustic (L..S+D.*..E) is decided near the light, any suffix completes
  // it; every string extends to a member of L.{8,}E; a direct path is short on both sides.
  struct Case {
    std::string expr;
    bool light_dies, eye_dies;
  };
  for (const Case& c : std::vector<Case>{{"$caustic", true, false}, {"L.{8,}E", false, false}, {"$direct", true, true},
                                         {"L..S.*E & L.*S..E", true, true}}) {
    const std::string& expr = c.expr;
    const std::vector<const PathClass*> classes = classes_for(cornell, {expr});
    const PathFilter only = PathFilter::make(classes, Limits{}).expect("requested paths");
    const Classifier& cl = only.classifier();
    std::mt19937_64 rng(5);
    int dead_light = 0, dead_eye = 0, requested = 0;
    for (int n = 0; n < 20000; ++n) {
      // L c0 … c(k+2) E with random letters (valid or not: the automata answer for any string).
      const int letters = 4 + static_cast<int>(rng() % 12);
      std::string path = "L";
      for (int i = 0; i < letters; ++i) path += (rng() % 3 == 0) ? 'S' : 'D';
      path += 'E';
      const bool in = !cl.members(cl.classify(path)).empty();
      EXPECT_EQ(in, only.records(accel::pack(path))) << path;
      requested += in ? 1 : 0;
      SubpathPrefix light(only, true, path[1], path[2]);
      bool dead = !light.alive();
      for (std::size_t i = 3; i + 1 < path.size() && !dead; ++i) {
        light.extend(path[i]);
        dead = !light.alive();
      }
      if (dead) {
        ++dead_light;
        EXPECT_FALSE(in) << expr << ": the light subpath of " << path << " was stopped";
      }
      SubpathPrefix eye(only, false, path[path.size() - 2], path[path.size() - 3]);
      dead = !eye.alive();
      for (std::size_t i = path.size() - 4; i >= 1 && !dead; --i) {
        eye.extend(path[i]);
        dead = !eye.alive();
      }
      if (dead) {
        ++dead_eye;
        EXPECT_FALSE(in) << expr << ": the eye subpath of " << path << " was stopped";
      }
    }
    EXPECT_GT(requested, 0) << expr;
    EXPECT_EQ(dead_light > 0, c.light_dies) << expr << ": " << dead_light << " light subpaths stopped";
    EXPECT_EQ(dead_eye > 0, c.eye_dies) << expr << ": " << dead_eye << " eye subpaths stopped";
  }
  // Without requested classes nothing is dead.
  SubpathPrefix all(PathFilter(), true, 'S', 'D');
  all.extend('S');
  EXPECT_TRUE(all.alive());
}

// A join is not made when no requested path has its length (PathFilter::has_length), and a light
// is aimed only when every requested path scatters specularly at its first vertex
// (first_vertex_specular): both against every string of up to 14 letters between L and E.
TEST(DeadState, LengthsAndSpecularFirstVerticesAreExact) {
  const Scene glass = scene_at("point-glass.json", 8);  // a point light (L S D) and a pinhole
  struct Case {
    std::string expr;
    std::vector<int> lengths;  // of the requested paths, up to 14 letters
    bool specular_first;       // after L S D (a point light's letters)
  };
  for (const Case& c : std::vector<Case>{{"L.{8,}E", {8, 9, 10, 11, 12, 13, 14}, false},
                                         {"L.{5}E | L.{7}E", {5, 7}, false},
                                         {"LSDS+D.*E", {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14}, true},
                                         {"$caustic", {6, 7, 8, 9, 10, 11, 12, 13, 14}, true},
                                         {"$direct", {5}, false}}) {
    const PathFilter only = PathFilter::make(classes_for(glass, {c.expr}), Limits{}).expect("requested paths");
    std::vector<int> lengths;
    bool all_specular = true;
    for (int n = 0; n <= 14; ++n) {
      bool any = false;
      for (std::uint32_t bits = 0; bits < (1u << n); ++bits) {
        std::string path = "L";
        for (int i = 0; i < n; ++i) path += ((bits >> i) & 1) ? 'S' : 'D';
        path += 'E';
        if (!only.records(accel::pack(path))) continue;
        any = true;
        if (path.compare(0, 3, "LSD") == 0 && path[3] != 'S') all_specular = false;
      }
      if (any) lengths.push_back(n);
      EXPECT_EQ(only.has_length(n), any) << c.expr << ": " << n << " letters";
    }
    EXPECT_EQ(lengths, c.lengths) << c.expr;
    EXPECT_EQ(only.first_vertex_specular('S', 'D'), all_specular && c.specular_first) << c.expr;
    EXPECT_EQ(only.first_vertex_specular('S', 'D'), c.specular_first) << c.expr;
  }
}

std::string run(const std::string& args, int* status) {
  std::string out;
  FILE* p = popen((std::string(PATHEX_BINARY) + " " + args + " 2>&1").c_str(), "r");
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  *status = WEXITSTATUS(pclose(p));
  return out;
}

TEST(Only, ClassesNotAskedForAreReportedNotRendered) {
  const std::string dir = ::testing::TempDir() + "/only-not-rendered";
  int status = 0;
  const std::string table = run("trace " + kScenes + "point-glass.json --spp 2 --resolution 16x16 --quiet --out " + dir +
                                    " --only '$caustic'",
                                &status);
  EXPECT_EQ(status, 0) << table;
  EXPECT_NE(table.find("\ndirect: not rendered\n"), std::string::npos) << table;
  EXPECT_NE(table.find("\ncaustic: 100.0 % of the image"), std::string::npos) << table;
  EXPECT_NE(table.find("rendered only caustic (L..S+D.*..E)"), std::string::npos) << table;
  std::ifstream in(dir + "/histogram.json");
  const nlohmann::json doc = nlohmann::json::parse(in);
  ASSERT_EQ(doc.at("only").size(), 1u);
  EXPECT_EQ(doc.at("only")[0].at("name"), "caustic");
  for (const nlohmann::json& c : doc.at("classes")) {
    const bool caustic = c.at("name") == "caustic";
    EXPECT_EQ(c.contains("luminance"), caustic) << c.dump();
    EXPECT_EQ(c.value("rendered", true), caustic) << c.dump();
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/direct.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/caustic.png"));
  // An expression that is no class of the render becomes one ("only-1"), estimated.
  const std::string json = run("trace " + kScenes + "point-glass.json --spp 2 --resolution 8x8 --quiet --json --out " + dir +
                                   " --only 'L.{8,}E'",
                               &status);
  EXPECT_EQ(status, 0) << json;
  const nlohmann::json doc2 = nlohmann::json::parse(json);
  EXPECT_EQ(doc2.at("classes").back().at("name"), "only-1");
  EXPECT_TRUE(doc2.at("classes").back().contains("luminance"));
  // "render": true in a class file is the same request.
  const std::string file = ::testing::TempDir() + "/only-classes.json";
  std::ofstream(file) << R"({"classes": [{"name": "glass", "expr": "$caustic", "render": true},)"
                      << R"( {"name": "short", "expr": "L.{4,5}E"}, {"name": "long", "expr": "L..S+D.*..E & L.{9,}E"}]})";
  const std::string listed = run("trace " + kScenes + "point-glass.json --spp 2 --resolution 8x8 --quiet --json --out " + dir +
                                     " --classes " + file,
                                 &status);
  EXPECT_EQ(status, 0) << listed;
  const nlohmann::json doc3 = nlohmann::json::parse(listed);
  ASSERT_EQ(doc3.at("classes").size(), 3u);
  EXPECT_TRUE(doc3.at("classes")[0].contains("luminance"));
  EXPECT_EQ(doc3.at("classes")[1].value("rendered", true), false);  // not within the caustics
  EXPECT_TRUE(doc3.at("classes")[2].contains("luminance"));          // within the caustics: estimated
  // Caustics of a scene without a specular material: nothing runs, and the output says why.
  const std::string none = run("trace " + kScenes + "point-plane.json --spp 2 --quiet --out " + dir + "-none --only '$caustic'", &status);
  EXPECT_EQ(status, 1) << none;
  EXPECT_NE(none.find("nothing to render: no strategy of bdpt samples a path of the requested classes in this scene "
                      "(lights point; sensor pinhole; materials D)"),
            std::string::npos)
      << none;
  EXPECT_NE(none.find("L..S+D.*..E has no path in this scene"), std::string::npos) << none;
  EXPECT_FALSE(std::filesystem::exists(dir + "-none/histogram.json"));
  // A bad expression is a located usage error.
  const std::string bad = run("trace " + kScenes + "point-glass.json --spp 1 --quiet --out " + dir + " --only 'L(('", &status);
  EXPECT_EQ(status, 2) << bad;
  EXPECT_NE(bad.find("--only 'L(('"), std::string::npos) << bad;
}

}  // namespace
}  // namespace pathex
