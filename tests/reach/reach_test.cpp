// The checker against hand-derived facts: the seed's statements (Veach ch. 8) verbatim, a table
// over all 16 light × sensor types for direct visibility and one diffuse bounce, and profile
// validation errors. Brute-force agreement with the strategy definitions is in
// brute_force_test.cpp.
#include <gtest/gtest.h>

#include "automata/ops.h"
#include "io/profile_json.h"
#include "reach/query.h"

namespace pathex {
namespace {

const Limits kLimits;

CompiledProfile compiled(const std::string& name, std::optional<int> bound = std::nullopt) {
  static std::map<std::string, Profile> profiles;  // CompiledProfile points into this
  if (!profiles.count(name)) {
    Result<Profile> p = resolve_profile(name, kLimits);
    EXPECT_TRUE(p.ok()) << name << ": " << (p.ok() ? "" : p.error().render());
    profiles.emplace(name, std::move(*p));
  }
  Result<CompiledProfile> c = compile_profile(profiles.at(name), bound, kLimits);
  EXPECT_TRUE(c.ok());
  return std::move(*c);
}

Verdict verdict(const std::string& expr, const std::string& renderer) {
  Result<PathClass> pc = compile_class(expr, ClassOptions{});
  EXPECT_TRUE(pc.ok()) << expr;
  Result<QueryResult> q = query(*pc, compiled(renderer), QueryOptions{});
  EXPECT_TRUE(q.ok());
  return q->verdict;
}

const char* const kPlainJoin[] = {"pt", "pt-nee", "lt", "bdpt", "pbrt-v4-path", "pbrt-v4-bdpt",
                                  "pbrt-v4-lightpath", "mitsuba3-path", "mitsuba3-ptracer"};

// --- the seed's facts, verbatim ---

TEST(SeedFacts, BdptReachesExactlyTheLocalPaths) {
  // "local path sampling reaches exactly the paths that contain DD" (Veach 8.3.3).
  const Dfa local = compile_class("L.*DD.*E", ClassOptions{}).expect("a test input").dfa;
  EXPECT_TRUE(is_equivalent(compiled("bdpt").reachable, local));
  EXPECT_EQ(verdict("$local", "bdpt"), Verdict::kReachable);
  EXPECT_EQ(verdict("~$local", "bdpt"), Verdict::kUnreachable);
}

TEST(SeedFacts, PointLightSeenByOrthographicCamera) {
  // LSDSDE: a point light seen directly by an orthographic camera. No plain join can sample it.
  for (const char* r : kPlainJoin) EXPECT_EQ(verdict("LSDSDE", r), Verdict::kUnreachable) << r;
  EXPECT_EQ(verdict("LSDSDE", "bdpt+ortho"), Verdict::kReachable);
  Result<QueryResult> q = query(compile_class("LSDSDE", ClassOptions{}).expect("a test input"), compiled("bdpt"), QueryOptions{});
  ASSERT_TRUE(q.ok());
  ASSERT_EQ(q->unreachable.size(), 1u);
  const Witness& w = q->unreachable[0];
  EXPECT_EQ(w.path, "LSDSDE");
  ASSERT_EQ(w.chains.size(), 2u);
  EXPECT_EQ(w.chains[0].chain.letters, "SD");
  EXPECT_TRUE(w.chains[0].connectors.empty());
  EXPECT_EQ(w.chains[1].chain.letters, "DSD");
  ASSERT_EQ(w.chains[1].connectors.size(), 1u);
  EXPECT_EQ(w.chains[1].connectors[0], ConnectorKind::kOrthoProjection);
  EXPECT_EQ(w.reason, "no DD join: the point light fixes x0 and the orthographic sensor fixes the last direction");
}

TEST(SeedFacts, PointMirrorDiffuseOrthographic) {
  // LSDSDSDE: point light, mirror, diffuse, orthographic camera: unreachable by plain joins; the
  // mirror connector joins c1..c3, ortho-projection c3..c5.
  for (const char* r : kPlainJoin) EXPECT_EQ(verdict("LSDSDSDE", r), Verdict::kUnreachable) << r;
  EXPECT_EQ(verdict("LSDSDSDE", "bdpt+mirror"), Verdict::kReachable);
  // The mirror connector stands only where its S is an interior vertex: not at c0..c2 or at
  // ck..c(k+2), where the S letters are the light's or the sensor's.
  EXPECT_EQ(verdict("LSDSDE", "bdpt+mirror"), Verdict::kUnreachable);
  const Profile mirror = resolve_profile("bdpt+mirror", kLimits).expect("a test input");
  const Strategy& connector = mirror.strategies[1];
  EXPECT_FALSE(strategy_samples(connector, "LSDSDE", std::nullopt));   // c1..c3: the sensor's S
  EXPECT_FALSE(strategy_samples(connector, "LDSDDE", std::nullopt));   // c0..c2: the light's S
  EXPECT_TRUE(strategy_samples(connector, "LSDSDSE", std::nullopt));  // c1..c3, S at x1
  EXPECT_EQ(verdict("LSDSDSDE", "bdpt+ortho"), Verdict::kReachable);
  const std::vector<ChainEvidence> ev = chain_evidence("LSDSDSDE");
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[1].chain.letters, "DSD");
  EXPECT_EQ(ev[1].chain.from, 1);
  EXPECT_EQ(ev[1].connectors, std::vector<ConnectorKind>({ConnectorKind::kMirror, ConnectorKind::kManifold}));
  EXPECT_EQ(ev[2].connectors, std::vector<ConnectorKind>({ConnectorKind::kOrthoProjection}));
}

TEST(SeedFacts, SunThroughAWindowNeedsAConnectorForEyeTracing) {
  // LDSDDSE: sun (LDS) -> diffuse floor -> pinhole. Eye tracing (pt, pt-nee) cannot join c0..c2 =
  // DSD; the distant-projection connector can. Light tracing joins at the camera (DD at c2..c3).
  EXPECT_EQ(verdict("LDSDDSE", "pt"), Verdict::kUnreachable);
  EXPECT_EQ(verdict("LDSDDSE", "pt-nee"), Verdict::kUnreachable);
  EXPECT_EQ(verdict("LDSDDSE", "pt-nee+distant"), Verdict::kReachable);
  EXPECT_EQ(verdict("LDSDDSE", "pbrt-v4-path"), Verdict::kReachable);
  EXPECT_EQ(verdict("LDSDDSE", "mitsuba3-path"), Verdict::kReachable);
  EXPECT_EQ(verdict("LDSDDSE", "lt"), Verdict::kReachable);
  // Every sunlit path seen through a pinhole, for an eye tracer without the connector:
  EXPECT_EQ(verdict("LDS.*DSE & ~(L.*DD.*E)", "pt-nee+distant"), Verdict::kPartial);
}

TEST(SeedFacts, ChainsOfLDSDDSSDSE) {
  const std::vector<ChainEvidence> ev = chain_evidence("LDSDDSSDSE");
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_EQ(ev[0].chain.letters, "DSD");
  EXPECT_EQ(ev[0].connectors, std::vector<ConnectorKind>({ConnectorKind::kDistantProjection}));
  EXPECT_EQ(ev[1].chain.letters, "DD");
  EXPECT_EQ(ev[2].chain.letters, "DSSD");
  EXPECT_EQ(ev[2].connectors, std::vector<ConnectorKind>({ConnectorKind::kManifold}));
  EXPECT_EQ(ev[3].chain.letters, "DS");
}

// --- 16 light × sensor types, k = 1 and k = 2 ---
//
// Rows: lights area (DD), distant (DS), point (SD), laser (SS). Columns: sensors lens (DD),
// pinhole (DS), orthographic (SD), spot meter (SS). 'R' reachable, 'U' unreachable.
//
// k = 1: the path is L c0 c1 c2 c3 E, light pair c0 c1, sensor pair c2 c3; no interior vertex.
//   pt      (0, DD, 2..): the chain must be c0 c1 = DD -> area light only, any sensor.
//   pt-nee  adds (1, DD, 2..): the chain c1 c2 leaves one letter after it, t = 1 < 2 -> no help.
//   lt      (1.., DD, 1): chain c1 c2 -> c1 = D (area, point) and c2 = D (lens, pinhole);
//           (2.., DD, 0): chain c2 c3 = DD -> lens, any light.
//   bdpt    DD anywhere: c0c1 (area) or c1c2 (area/point with lens/pinhole) or c2c3 (lens).
// k = 2: L c0 c1 D c3 c4 E, one diffuse interior vertex c2 = D.
//   pt      c0 c1 = DD -> area only.
//   pt-nee  adds chain c1 c2 = ?D with t = 2 -> c1 = D: area or point, any sensor.
//   lt      (1.., DD, 1): chain c2 c3 -> c3 = D: lens or pinhole, any light; (2.., DD, 0): lens.
//   bdpt    light in {area, point} (c1 c2 = DD) or sensor in {lens, pinhole} (c2 c3 = DD).
struct Table {
  const char* renderer;
  const char* rows[4];
};
const Table kDirect[] = {
    {"pt", {"RRRR", "UUUU", "UUUU", "UUUU"}},
    {"pt-nee", {"RRRR", "UUUU", "UUUU", "UUUU"}},
    {"lt", {"RRUU", "RUUU", "RRUU", "RUUU"}},
    {"bdpt", {"RRRR", "RUUU", "RRUU", "RUUU"}},
};
const Table kOneBounce[] = {
    {"pt", {"RRRR", "UUUU", "UUUU", "UUUU"}},
    {"pt-nee", {"RRRR", "UUUU", "RRRR", "UUUU"}},
    {"lt", {"RRUU", "RRUU", "RRUU", "RRUU"}},
    {"bdpt", {"RRRR", "RRUU", "RRRR", "RRUU"}},
};

void check_table(const Table* tables, std::size_t n, const std::string& interior) {
  for (std::size_t ti = 0; ti < n; ++ti) {
    const Table& t = tables[ti];
    for (std::size_t li = 0; li < 4; ++li) {
      for (std::size_t si = 0; si < 4; ++si) {
        const std::string path =
            "L" + light_letters(kAllLightTypes[li]) + interior + sensor_letters(kAllSensorTypes[si]) + "E";
        const Verdict want = t.rows[li][si] == 'R' ? Verdict::kReachable : Verdict::kUnreachable;
        EXPECT_EQ(verdict(path, t.renderer), want)
            << t.renderer << " " << to_string(kAllLightTypes[li]) << " x " << to_string(kAllSensorTypes[si]) << " " << path;
      }
    }
  }
}

TEST(TypeTable, DirectVisibilityK1) { check_table(kDirect, 4, ""); }
TEST(TypeTable, OneDiffuseBounceK2) { check_table(kOneBounce, 4, "D"); }

TEST(TypeTable, HeckbertClassesOverSceneTypes) {
  // Classic LDE with a point light and a pinhole is LSDDDSE: pt cannot, pt-nee can.
  ClassOptions o;
  o.notation = Notation::kHeckbert;
  o.ends.lights = {LightType::kPoint};
  o.ends.sensors = {SensorType::kPinhole};
  Result<PathClass> pc = compile_class("LDE", o);
  ASSERT_TRUE(pc.ok());
  EXPECT_EQ(enumerate_members(pc->dfa, 20, 10), std::vector<std::string>({"LSDDDSE"}));
  EXPECT_EQ(query(*pc, compiled("pt"), QueryOptions{}).expect("a test input").verdict, Verdict::kUnreachable);
  EXPECT_EQ(query(*pc, compiled("pt-nee"), QueryOptions{}).expect("a test input").verdict, Verdict::kReachable);
}

// --- bounds, evidence, counts ---

TEST(Query, MaxBouncesMakesLongPathsUnreachable) {
  // pbrt-v4-path has maxdepth 5: LDD D{5} DSE reachable, D{6} not.
  EXPECT_EQ(verdict("LDDD{5}DSE", "pbrt-v4-path"), Verdict::kReachable);
  EXPECT_EQ(verdict("LDDD{6}DSE", "pbrt-v4-path"), Verdict::kUnreachable);
  Result<QueryResult> q = query(compile_class("LDDD+DSE", ClassOptions{}).expect("a test input"), compiled("pbrt-v4-path"), QueryOptions{});
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->verdict, Verdict::kPartial);
  EXPECT_TRUE(q->finite_reachable);
  EXPECT_FALSE(q->finite_unreachable);
  ASSERT_FALSE(q->unreachable.empty());
  EXPECT_EQ(q->unreachable[0].path, "LDDDDDDDDDSE");
  EXPECT_EQ(q->unreachable[0].reason, "6 bounces exceed max_bounces 5");
}

TEST(Query, ReachableWitnessesNameTheirStrategies) {
  Result<QueryResult> q = query(compile_class("LDDDDSE", ClassOptions{}).expect("a test input"), compiled("pt-nee"), QueryOptions{});
  ASSERT_TRUE(q.ok());
  ASSERT_EQ(q->reachable.size(), 1u);
  EXPECT_EQ(q->reachable[0].strategies, std::vector<std::string>({"emitter-hit", "nee"}));
}

TEST(Query, CountsByLengthAreExact) {
  // $caustic through pt-nee: L..S+D.*..E. Length 7 has none (S+D needs two interior letters).
  // Length 8 (k = 3): L ab S D cd E -> 4 light pairs * 4 sensor pairs = 16 members. pt-nee
  // reaches those with ab = DD by an emitter hit (4, any sensor); NEE needs c1 c2 = DD but c2 = S.
  QueryOptions o;
  o.max_len = 8;
  Result<QueryResult> q = query(compile_class("$caustic", ClassOptions{}).expect("a test input"), compiled("pt-nee"), o);
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->counts_class[7].to_string(), "0");
  EXPECT_EQ(q->counts_class[8].to_string(), "16");
  EXPECT_EQ(q->counts_reachable[8].to_string(), "4");
  EXPECT_EQ(q->counts_unreachable[8].to_string(), "12");
  EXPECT_EQ(q->verdict, Verdict::kPartial);
}

TEST(Query, EmptyClassInARestrictedUniverse) {
  QueryOptions o;
  o.universe = compile_class("LSD.*DSE", ClassOptions{}).expect("a test input").dfa;  // point lights and a pinhole
  Result<QueryResult> q = query(compile_class("LDD.*E", ClassOptions{}).expect("a test input"), compiled("bdpt"), o);
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->verdict, Verdict::kEmpty);
}

// --- profiles ---

TEST(Profiles, EveryBuiltinParses) {
  Result<std::vector<Profile>> all = builtin_profiles(kLimits);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->size(), builtin_profile_texts().size());
  for (const BuiltinProfileText& b : builtin_profile_texts()) {
    Result<Profile> p = parse_profile(b.json, b.name, kLimits);
    EXPECT_TRUE(p.ok()) << b.name << ": " << (p.ok() ? "" : p.error().render());
    if (p.ok()) {
      EXPECT_EQ(p->name, b.name);
    }
  }
}

TEST(Profiles, RealIntegratorFacts) {
  // Orthographic sensors get nothing from pbrt-v4 lightpath or Mitsuba 3 ptracer.
  EXPECT_EQ(verdict("L.*SDE", "pbrt-v4-lightpath"), Verdict::kUnreachable);
  EXPECT_EQ(verdict("L.*SDE", "mitsuba3-ptracer"), Verdict::kUnreachable);
  // Path tracers skip light sampling at specular vertices: LSD S DSE (point -> mirror -> pinhole
  // with the mirror seen directly) is unreachable, LSD D DSE reachable.
  EXPECT_EQ(verdict("LSDSDSE", "pbrt-v4-path"), Verdict::kUnreachable);
  EXPECT_EQ(verdict("LSDDDSE", "pbrt-v4-path"), Verdict::kReachable);
  // pbrt-v4 bdpt skips (s, t) = (1, 1): a point light seen by a pinhole, LSDDSE.
  EXPECT_EQ(verdict("LSDDSE", "pbrt-v4-bdpt"), Verdict::kUnreachable);
  EXPECT_EQ(verdict("LSDDSE", "bdpt"), Verdict::kReachable);
}

TEST(Profiles, BadProfilesNameTheJsonPointer) {
  struct Case { const char* json; const char* where; const char* message; };
  const Case cases[] = {
      {R"({"name": "x", "strategies": [{"s": 0, "chain": "DD", "t": 2, "extra": 1}]})", "p.json:/strategies/0/extra",
       "unknown key 'extra', expected one of name, s, chain, t, connector"},
      {R"({"name": "x", "strategies": [{"s": "3..1", "chain": "DD", "t": 2}]})", "p.json:/strategies/0/s",
       "'3..1': the range is inverted (3 > 1)"},
      {R"({"name": "x", "strategies": [{"s": 0, "chain": "DSS", "t": 2, "connector": "manifold"}]})", "p.json:/strategies/0/chain",
       "chain 'DSS' is not within DS*D (a chain runs from one D separator to the next; it contains DSS)"},
      {R"({"name": "x", "strategies": [{"s": 0, "chain": "DSD", "t": 2}]})", "p.json:/strategies/0/chain",
       "chain 'DSD' has specular letters, so it needs a connector (mirror, distant-projection, ortho-projection or manifold); a plain join is DD"},
      {R"({"name": "x", "strategies": [{"s": 1, "chain": "DSD", "t": 2, "connector": "distant-projection"}]})",
       "p.json:/strategies/0/s", "the distant-projection connector joins at c0..c2, so s must be 0"},
      {R"({"name": "x", "strategies": [{"s": "0..", "chain": "DSD", "t": "1..", "connector": "mirror"}]})",
       "p.json:/strategies/0/s", "the mirror connector constructs interior vertices only, so s and t must be at least 1 (found s 0.., t 1..)"},
      {R"({"name": "x", "strategies": [{"s": 1, "chain": "DS+D", "t": "0..", "connector": "manifold"}]})",
       "p.json:/strategies/0/t", "the manifold connector constructs interior vertices only, so s and t must be at least 1 (found s 1, t 0..)"},
      {R"({"name": "x", "strategies": [{"s": 0, "chain": "DD", "t": 2, "connector": "warp"}]})", "p.json:/strategies/0/connector",
       "unknown connector 'warp', expected mirror, distant-projection, ortho-projection or manifold"},
      {R"({"name": "x", "strategies": []})", "p.json:/strategies", "expected a non-empty array of strategies"},
      {R"({"name": "x", "max_bounces": -1, "strategies": [{"s": 0, "t": 2}]})", "p.json:/max_bounces",
       "expected a non-negative integer up to 10000 (or null for unbounded), found -1"},
      {R"({"strategies": [{"s": 0, "t": 2}]})", "p.json:/name", "expected a non-empty string name"},
      {R"({"name": "x", "strategies": [{"s": 0, "chain": "D(D", "t": 2}]})", "p.json:/strategies/0/chain",
       "missing ')' to close this '('"},
  };
  for (const Case& c : cases) {
    Result<Profile> p = parse_profile(c.json, "p.json", kLimits);
    ASSERT_FALSE(p.ok()) << c.json;
    EXPECT_EQ(p.error().where, c.where) << c.json;
    EXPECT_EQ(p.error().message, c.message) << c.json;
  }
}

TEST(Profiles, RangeParsing) {
  EXPECT_EQ(parse_range("2").expect("a test input").to_string(), "2");
  EXPECT_EQ(parse_range("0..1").expect("a test input").to_string(), "0..1");
  EXPECT_EQ(parse_range("2..").expect("a test input").to_string(), "2..");
  EXPECT_FALSE(parse_range("..2").ok());
  EXPECT_FALSE(parse_range("-1").ok());
  EXPECT_FALSE(parse_range("a").ok());
}

}  // namespace
}  // namespace pathex
