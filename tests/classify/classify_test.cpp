// Path classes and the multi-class classifier (src/classify/pathclass.h, classifier.h) against
// definitions written out in plain code: the built-ins as documented in pathclass.cpp with their
// exact member lists and counts, the notation examples of DESIGN §1 verbatim, Heckbert
// conversion decided per path from the light/sensor pairs and the classic expression's AST,
// eye-first expressions as reversals, class files with references and their error pointers, and
// the classifier against each class's own DFA on every valid path up to length 12, including
// which partial paths are still alive. Random class sets use fixed seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "automata/ops.h"
#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "core/budget.h"
#include "io/class_file.h"
#include "oracle/dfa_print.h"
#include "oracle/naive_matcher.h"
#include "oracle/random_regex.h"

namespace pathex {
namespace {

PathClass full(const std::string& text) {
  Result<PathClass> c = compile_class(text, ClassOptions{});
  EXPECT_TRUE(c.ok()) << "'" << text << "': " << (c.ok() ? "" : c.error().render());
  return c.ok() ? std::move(*c) : PathClass{};
}

PathClass heckbert(const std::string& text, std::vector<LightType> lights = {kAllLightTypes.begin(), kAllLightTypes.end()},
                   std::vector<SensorType> sensors = {kAllSensorTypes.begin(), kAllSensorTypes.end()}) {
  ClassOptions o;
  o.notation = Notation::kHeckbert;
  o.ends.lights = std::move(lights);
  o.ends.sensors = std::move(sensors);
  Result<PathClass> c = compile_class(text, o);
  EXPECT_TRUE(c.ok()) << "'" << text << "': " << (c.ok() ? "" : c.error().render());
  return c.ok() ? std::move(*c) : PathClass{};
}

// Every valid full path L[SD]{m}E with 4 ≤ m ≤ max_len − 2, in shortlex order (D < S).
std::vector<std::string> valid_paths(int max_len) {
  std::vector<std::string> out;
  for (int m = 4; m + 2 <= max_len; ++m)
    for (unsigned bits = 0; bits < (1u << m); ++bits) {
      std::string p = "L";
      for (int i = m - 1; i >= 0; --i) p += (bits >> i) & 1u ? 'S' : 'D';
      out.push_back(p + "E");
    }
  return out;
}

std::vector<std::string> members(const Dfa& d, int max_len) { return enumerate_members(d, max_len, 1u << 20); }

std::vector<std::string> filter(const std::vector<std::string>& paths, const std::function<bool(const std::string&)>& keep) {
  std::vector<std::string> out;
  for (const std::string& p : paths)
    if (keep(p)) out.push_back(p);
  return out;
}

// The scattering letters c0 … c(k+2) of a valid path, and the interior ones c2 … ck.
std::string letters(const std::string& p) { return p.substr(1, p.size() - 2); }
std::string interior(const std::string& p) { return p.substr(3, p.size() - 6); }

// --- built-ins, as documented in pathclass.cpp ---

TEST(Builtins, NamesDescriptionsAndOrder) {
  const auto& b = ClassTable::builtins().builtin_classes();
  std::vector<std::string> names, texts;
  for (const auto& c : b) {
    names.push_back(c->name);
    texts.push_back(c->text);
    EXPECT_FALSE(c->description.empty()) << c->name;
    EXPECT_EQ(c->notation, Notation::kFull);
    EXPECT_FALSE(c->eye_first);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"all", "local", "emission", "direct", "indirect", "caustic"}));
  EXPECT_EQ(texts, (std::vector<std::string>{"L[SD]{4,}E", "L.*DD.*E", "L....E", "L.....E", "L......+E", "L..S+D.*..E"}));
  EXPECT_EQ(ClassTable::builtins().find("local")->description,
            "paths that local path sampling can reach: some join DD exists (Veach 8.3.3)");
  EXPECT_EQ(ClassTable::builtins().find("nope"), nullptr);
}

TEST(Builtins, ExactMembersUpToLength10) {
  const std::vector<std::string> paths = valid_paths(10);
  const ClassTable& t = ClassTable::builtins();
  EXPECT_EQ(t.find("all")->dfa, dfa_universe());
  EXPECT_EQ(members(t.find("all")->dfa, 10), paths);
  EXPECT_EQ(members(t.find("local")->dfa, 10),
            filter(paths, [](const std::string& p) { return letters(p).find("DD") != std::string::npos; }));
  EXPECT_EQ(members(t.find("emission")->dfa, 10), filter(paths, [](const std::string& p) { return p.size() == 6; }));
  EXPECT_EQ(members(t.find("direct")->dfa, 10), filter(paths, [](const std::string& p) { return p.size() == 7; }));
  EXPECT_EQ(members(t.find("indirect")->dfa, 10), filter(paths, [](const std::string& p) { return p.size() >= 8; }));
  // Classic LS+D.*E: the interior vertices start with one or more S, then a D.
  EXPECT_EQ(members(t.find("caustic")->dfa, 10), filter(paths, [](const std::string& p) {
              const std::string in = interior(p);
              return !in.empty() && in[0] == 'S' && in.find('D') != std::string::npos;
            }));
  EXPECT_EQ(members(t.find("local")->dfa, 7),
            (std::vector<std::string>{"LDDDDE", "LDDDSE", "LDDSDE", "LDDSSE", "LDSDDE", "LSDDDE", "LSDDSE", "LSSDDE",
                                      "LDDDDDE", "LDDDDSE", "LDDDSDE", "LDDDSSE", "LDDSDDE", "LDDSDSE", "LDDSSDE",
                                      "LDDSSSE", "LDSDDDE", "LDSDDSE", "LDSSDDE", "LSDDDDE", "LSDDDSE", "LSDDSDE",
                                      "LSDDSSE", "LSDSDDE", "LSSDDDE", "LSSDDSE", "LSSSDDE"}));
  EXPECT_EQ(members(t.find("caustic")->dfa, 8), (std::vector<std::string>{"LDDSDDDE", "LDDSDDSE", "LDDSDSDE", "LDDSDSSE",
                                                                          "LDSSDDDE", "LDSSDDSE", "LDSSDSDE", "LDSSDSSE",
                                                                          "LSDSDDDE", "LSDSDDSE", "LSDSDSDE", "LSDSDSSE",
                                                                          "LSSSDDDE", "LSSSDDSE", "LSSSDSDE", "LSSSDSSE"}));
}

TEST(Builtins, CountsFollowClosedForms) {
  // With m = n − 2 scattering letters: $local has the 2^m strings minus the F(m + 2) without DD
  // (Fibonacci, F(1) = F(2) = 1); $caustic has 16 end pairs times the interiors of length
  // i = m − 4 that start with S and contain a D: 2^(i−1) − 1; $indirect has all 2^m for m ≥ 6.
  const ClassTable& t = ClassTable::builtins();
  constexpr int kMax = 65;  // 2^63 still fits 64 bits
  const std::vector<BigUint> local = count_by_length(t.find("local")->dfa, kMax);
  const std::vector<BigUint> caustic = count_by_length(t.find("caustic")->dfa, kMax);
  const std::vector<BigUint> indirect = count_by_length(t.find("indirect")->dfa, kMax);
  std::vector<std::uint64_t> fib = {0, 1, 1};
  while (fib.size() < 70) fib.push_back(fib[fib.size() - 1] + fib[fib.size() - 2]);
  for (int n = 0; n <= kMax; ++n) {
    const int m = n - 2;
    const std::uint64_t all = m >= 4 ? std::uint64_t{1} << m : 0;
    EXPECT_EQ(local[static_cast<std::size_t>(n)].to_string(), std::to_string(m >= 4 ? all - fib[static_cast<std::size_t>(m + 2)] : 0)) << n;
    const int i = m - 4;
    EXPECT_EQ(caustic[static_cast<std::size_t>(n)].to_string(), std::to_string(i >= 1 ? 16 * ((std::uint64_t{1} << (i - 1)) - 1) : 0)) << n;
    EXPECT_EQ(indirect[static_cast<std::size_t>(n)].to_string(), std::to_string(n >= 8 ? all : 0)) << n;
  }
  EXPECT_TRUE(is_finite(t.find("emission")->dfa));
  EXPECT_TRUE(is_finite(t.find("direct")->dfa));
  EXPECT_FALSE(is_finite(t.find("indirect")->dfa));
}

// --- DESIGN §1, verbatim ---

TEST(Notation, DesignExamples) {
  // `LDDDSE` an area light seen directly by a pinhole camera (k = 1).
  Result<FullPath> p = parse_full_path("LDDDSE", 100);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->k(), 1);
  EXPECT_EQ(light_type_from_letters("DD"), LightType::kArea);
  EXPECT_EQ(sensor_type_from_letters("DS"), SensorType::kPinhole);
  EXPECT_EQ(heckbert("LE", {LightType::kArea}, {SensorType::kPinhole}).dfa, full("LDDDSE").dfa);
  EXPECT_EQ(members(full("LDDDSE").dfa, 20), std::vector<std::string>{"LDDDSE"});
  // `LSDSDDSE` point light → mirror → diffuse floor → pinhole.
  p = parse_full_path("LSDSDDSE", 100);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->k(), 3);
  EXPECT_EQ(light_type_from_letters(letters(p->text).substr(0, 2)), LightType::kPoint);
  EXPECT_EQ(p->c(2), 'S');
  EXPECT_EQ(p->c(3), 'D');
  EXPECT_EQ(sensor_type_from_letters(letters(p->text).substr(4, 2)), SensorType::kPinhole);
  EXPECT_EQ(heckbert("LSDE", {LightType::kPoint}, {SensorType::kPinhole}).dfa, full("LSDSDDSE").dfa);
  // `LSDSDE` a point light seen directly by an orthographic camera.
  EXPECT_EQ(sensor_type_from_letters("SD"), SensorType::kOrthographic);
  EXPECT_EQ(heckbert("LE", {LightType::kPoint}, {SensorType::kOrthographic}).dfa, full("LSDSDE").dfa);
  // The hard caustic of samples/classes/basic.json: point light, mirror, diffuse, orthographic.
  EXPECT_TRUE(full("$caustic & ~$local").dfa.accepts("LSDSDSDE"));
  EXPECT_FALSE(full("$caustic & ~$local").dfa.accepts("LSDSDDSE"));
}

TEST(Notation, ClassicLwEIsFullLxywyxE) {
  const std::vector<std::string> middles = {"", "D", "S", "SD", "DS*D", "(S|D)*", "S+D.*", "~(.*SS.*)", "(S|D){2,3}"};
  for (const std::string& w : middles) {
    const std::string classic = "L" + (w.empty() ? "" : "(" + w + ")") + "E";
    std::vector<Dfa> parts;
    for (LightType lt : kAllLightTypes)
      for (SensorType st : kAllSensorTypes) {
        const std::string f = "L" + light_letters(lt) + (w.empty() ? "" : "(" + w + ")") + sensor_letters(st) + "E";
        const Dfa one = full(f).dfa;
        EXPECT_EQ(heckbert(classic, {lt}, {st}).dfa, one) << classic << " " << to_string(lt) << " " << to_string(st);
        parts.push_back(one);
      }
    Dfa all = dfa_empty();
    for (const Dfa& d : parts) all = dfa_union(all, d);
    EXPECT_EQ(heckbert(classic).dfa, all) << classic << " with every light and sensor";
  }
  // The classic universe L[SD]*E becomes the universe when every type is allowed.
  EXPECT_EQ(heckbert("L(S|D)*E").dfa, dfa_universe());
  EXPECT_EQ(ends_universe(EndTypes{}), dfa_universe());
}

// Heckbert membership decided per path: the pairs are allowed types and the classic string
// L c2 … ck E is in the classic expression's language (by the oracle).
TEST(Notation, HeckbertWithLightAndSensorSubsetsAgreesWithTheDefinition) {
  const std::vector<std::string> classics = {"LE", "LDE", "LS+DE", "L(S|D)*E", "L~(.*SS.*)E", "L.*DD.*E", "L(SD)*E",
                                             "~(LSE)", "LD*E|LS*E", "L[SD]{2,}E&L.*S.*E"};
  const std::vector<std::pair<std::vector<LightType>, std::vector<SensorType>>> ends = {
      {{LightType::kArea}, {SensorType::kPinhole}},
      {{LightType::kArea, LightType::kPoint}, {SensorType::kPinhole, SensorType::kLens}},
      {{LightType::kDistant, LightType::kLaser}, {SensorType::kOrthographic, SensorType::kSpotmeter}},
      {{kAllLightTypes.begin(), kAllLightTypes.end()}, {SensorType::kSpotmeter}},
  };
  const std::vector<std::string> paths = valid_paths(12);
  for (const std::string& text : classics)
    for (const auto& [lights, sensors] : ends) {
      const PathClass c = heckbert(text, lights, sensors);
      EXPECT_FALSE(c.eye_first);
      EndTypes e;
      e.lights = lights;
      e.sensors = sensors;
      EXPECT_TRUE(is_subset(c.dfa, ends_universe(e))) << text;
      for (const std::string& p : paths) {
        const std::string l = letters(p);
        const bool light_ok = std::any_of(lights.begin(), lights.end(), [&](LightType t) { return light_letters(t) == l.substr(0, 2); });
        const bool sensor_ok = std::any_of(sensors.begin(), sensors.end(), [&](SensorType t) { return sensor_letters(t) == l.substr(l.size() - 2); });
        const bool want = light_ok && sensor_ok && oracle::naive_match(c.ast, "L" + interior(p) + "E");
        ASSERT_EQ(c.dfa.accepts(p), want) << "'" << text << "' on " << p;
        ASSERT_EQ(ends_universe(e).accepts(p), light_ok && sensor_ok) << p;
      }
    }
}

// --- eye-first ---

TEST(EyeFirst, DenotesTheReversal) {
  const PathClass e = full("ED*SL");
  EXPECT_TRUE(e.eye_first);
  EXPECT_EQ(e.dfa, full("LSD*E").dfa);
  EXPECT_NE(e.dfa, full("LD*SE").dfa);
  EXPECT_EQ(members(e.dfa, 8), (std::vector<std::string>{"LSDDDE", "LSDDDDE", "LSDDDDDE"}));
  EXPECT_EQ(full("EDS*DL").dfa, full("LDS*DE").dfa);
  EXPECT_EQ(full("ESDDSDSL").dfa, full("LSDSDDSE").dfa) << "DESIGN's point light → mirror → diffuse → pinhole, eye-first";
  EXPECT_EQ(full("E.*DD.*L").dfa, full("$local").dfa);
  EXPECT_EQ(full("E(S|D)*DDL").dfa, full("LDD(S|D)*E").dfa);
  EXPECT_EQ(heckbert("ES*DL").dfa, heckbert("LDS*E").dfa);
  EXPECT_TRUE(heckbert("ES*DL").eye_first);
  // The light-first tree is the reversed one; the tree as written is kept.
  EXPECT_EQ(dump(e.ast), "cat{E star{D} S L}");
  EXPECT_EQ(dump(e.light_ast), "cat{L S star{D} E}");
  // Not eye-first: empty, or some member does not start with E.
  EXPECT_FALSE(full("E&L").eye_first);
  EXPECT_FALSE(full("E?L.*E").eye_first);
  EXPECT_FALSE(full("L.*E").eye_first);
  // Every valid path, by the oracle on the reversed string.
  for (const char* text : {"ED*SL", "E.*SS.*L", "E..S.*..L", "E(~(.*DD.*))L", "E(S|D){2,5}L"}) {
    const PathClass c = full(text);
    EXPECT_TRUE(c.eye_first) << text;
    for (const std::string& p : valid_paths(12))
      ASSERT_EQ(c.dfa.accepts(p), oracle::naive_match(c.ast, std::string(p.rbegin(), p.rend()))) << text << " on " << p;
  }
}

// --- class files ---

TEST(ClassFiles, EntriesReferToEarlierOnesAndBuiltins) {
  ClassTable table;
  Result<bool> r = load_class_file(R"({"classes": [
      {"name": "caustic2", "expr": "L..S+D.*..E", "description": "same as the built-in"},
      {"name": "glass", "expr": "$caustic2 & L.*SS.*E"},
      {"name": "eye", "expr": "E..S.*..L"},
      {"name": "either", "expr": "$glass | $eye"},
      {"name": "mirror-classic", "expr": "LSDE", "notation": "heckbert"},
      {"name": "not-local", "expr": "~$local"}
    ]})", "inline.json", ClassOptions{}, &table);
  ASSERT_TRUE(r.ok()) << r.error().render();
  ASSERT_EQ(table.user_classes().size(), 6u);
  EXPECT_EQ(table.find("caustic2")->dfa, ClassTable::builtins().find("caustic")->dfa);
  EXPECT_EQ(table.find("caustic2")->description, "same as the built-in");
  EXPECT_EQ(table.find("glass")->dfa, dfa_intersect(full("$caustic").dfa, full("L.*SS.*E").dfa));
  EXPECT_TRUE(table.find("eye")->eye_first);
  EXPECT_EQ(table.find("eye")->dfa, full("L..(.*S)..E").dfa);
  // $eye stands for the class's language, read light-first.
  EXPECT_EQ(table.find("either")->dfa, dfa_union(table.find("glass")->dfa, table.find("eye")->dfa));
  EXPECT_EQ(table.find("mirror-classic")->dfa, heckbert("LSDE").dfa);
  EXPECT_EQ(table.find("mirror-classic")->notation, Notation::kHeckbert);
  EXPECT_EQ(table.find("not-local")->dfa, dfa_difference(dfa_universe(), full("$local").dfa));
  // Built-ins stay visible through a user table.
  EXPECT_EQ(table.find("local"), ClassTable::builtins().find("local"));
}

TEST(ClassFiles, EntriesAreFullNotationWhateverTheCommandLineSays) {
  ClassOptions o;
  o.notation = Notation::kHeckbert;
  o.ends.lights = {LightType::kPoint};
  ClassTable table;
  ASSERT_TRUE(load_class_file(R"({"classes": [{"name": "a", "expr": "LSDSDE"},
                                              {"name": "b", "expr": "LE", "notation": "heckbert"}]})",
                              "f.json", o, &table)
                  .ok());
  EXPECT_EQ(table.find("a")->dfa, full("LSDSDE").dfa);
  EXPECT_EQ(table.find("b")->dfa, heckbert("LE", {LightType::kPoint}).dfa) << "end types still come from the options";
}

struct FileError {
  const char* json;
  ErrorCode code;
  const char* where;
  const char* message;
  int column;
};

TEST(ClassFiles, ErrorsNameTheJsonPointer) {
  const FileError cases[] = {
      {R"({"classes": [{"name": "a", "expr": "$nope"}]})", ErrorCode::kUnknownName, "f.json:/classes/0/expr",
       "unknown class name '$nope', expected a built-in name or one defined earlier in the class file", 1},
      {R"({"classes": [{"name": "a", "expr": "$b"}, {"name": "b", "expr": "LDDDSE"}]})", ErrorCode::kUnknownName,
       "f.json:/classes/0/expr",
       "unknown class name '$b', expected a built-in name or one defined earlier in the class file", 1},
      {R"({"classes": [{"name": "a", "expr": "LDE"}, {"name": "a", "expr": "LSE"}]})", ErrorCode::kBadValue,
       "f.json:/classes/1/name", "class name 'a' is already defined", 0},
      {R"({"classes": [{"name": "local", "expr": "LDE"}]})", ErrorCode::kBadValue, "f.json:/classes/0/name",
       "class name 'local' is already defined", 0},
      {R"({"classes": [{"name": "1x", "expr": "LDE"}]})", ErrorCode::kBadFile, "f.json:/classes/0/name",
       "invalid class name '1x', expected a letter or '_' then letters, digits, '_' or '-'", 0},
      {R"({"classes": [{"name": "a", "expr": "LDE", "notation": "bogus"}]})", ErrorCode::kBadFile,
       "f.json:/classes/0/notation", "expected \"full\", \"heckbert\" or \"lpe\"", 0},
      {R"({"classes": [{"name": "a", "expr": "LDE", "colour": "red"}]})", ErrorCode::kBadFile,
       "f.json:/classes/0/colour", "unknown key 'colour', expected one of name, expr, notation, description, render", 0},
      {R"({"classes": [{"name": "a", "expr": "LDE", "render": "yes"}]})", ErrorCode::kBadFile,
       "f.json:/classes/0/render", "expected true or false", 0},
      {R"({"classes": [{"name": "a"}]})", ErrorCode::kBadFile, "f.json:/classes/0/expr", "expected a string expression", 0},
      {R"({"classes": [{"expr": "LDE"}]})", ErrorCode::kBadFile, "f.json:/classes/0/name", "expected a string class name", 0},
      {R"({"classes": {}})", ErrorCode::kBadFile, "f.json:/classes", "expected an array of class entries", 0},
      {R"({"class": []})", ErrorCode::kBadFile, "f.json:/class", "unknown key 'class', expected \"classes\"", 0},
      {R"({})", ErrorCode::kBadFile, "f.json:/", "missing \"classes\" array", 0},
      {R"([])", ErrorCode::kBadFile, "f.json:/", "expected a JSON object with a \"classes\" array", 0},
      {R"({"classes": [{"name": "a", "expr": "L(DD"}]})", ErrorCode::kSyntax, "f.json:/classes/0/expr",
       "missing ')' to close this '('", 2},
      {R"({"classes": [{"name": "a", "expr": "LDE", "notation": "heckbert"}, {"name": "b", "expr": "$local|$a"}]})",
       ErrorCode::kUnknownName, "f.json:/classes/1/expr",
       "'$a' is written in Heckbert notation and cannot be used in a full-notation expression", 8},
      // The caret finds "$a" itself, not the "$a" that begins "$ab".
      {R"({"classes": [{"name": "a", "expr": "LDE", "notation": "heckbert"}, {"name": "ab", "expr": "LDDDDE"},
                       {"name": "b", "expr": "$ab|$a"}]})",
       ErrorCode::kUnknownName, "f.json:/classes/2/expr",
       "'$a' is written in Heckbert notation and cannot be used in a full-notation expression", 5},
      {R"({"classes": [{"name": "f", "expr": "LDDDDE"}, {"name": "h", "expr": "LS$f", "notation": "heckbert"}]})",
       ErrorCode::kUnknownName, "f.json:/classes/1/expr",
       "'$f' is written in full notation and cannot be used in a Heckbert-notation expression", 3},
  };
  for (const FileError& c : cases) {
    ClassTable table;
    Result<bool> r = load_class_file(c.json, "f.json", ClassOptions{}, &table);
    ASSERT_FALSE(r.ok()) << c.json;
    EXPECT_EQ(r.error().code, c.code) << c.json;
    EXPECT_EQ(r.error().where, c.where) << c.json;
    EXPECT_EQ(r.error().message, c.message) << c.json;
    EXPECT_EQ(r.error().column, c.column) << c.json;
  }
  // Not JSON at all: the parser's own words follow.
  ClassTable table;
  Result<bool> r = load_class_file("{\"classes\": [", "f.json", ClassOptions{}, &table);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where, "f.json:/classes/0");  // the value being read when the text ran out
  EXPECT_EQ(r.error().message.rfind("not valid JSON: ", 0), 0u) << r.error().message;
  // The rendered form puts the caret under the offending reference.
  ClassTable t2;
  r = load_class_file(R"({"classes": [{"name": "a", "expr": "LD $nope E"}]})", "f.json", ClassOptions{}, &t2);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().render(),
            "f.json:/classes/0/expr: column 4: unknown class name '$nope', expected a built-in name or one defined "
            "earlier in the class file\n  LD $nope E\n     ^");
}

// --- limits ---

TEST(Limits, ExponentialClassStopsAtTheStateCapWithinTheBudget) {
  std::optional<WorkBudget> budget(std::in_place, Limits{}.max_work);
  Result<PathClass> c = compile_class("(S|D)*S(S|D){40}", ClassOptions{});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().code, ErrorCode::kLimit);
  EXPECT_EQ(c.error().message, "the DFA exceeds the limit of 100000 states (raise it with --max-states)");
  EXPECT_EQ(c.error().render(),
            "column 1: the DFA exceeds the limit of 100000 states (raise it with --max-states)\n  (S|D)*S(S|D){40}\n  ^");
  // The state cap stopped the subset construction early: about max_states states were built,
  // well within the work budget (a counter, not a clock: tests/automata/budget_test.cpp).
  EXPECT_GT(budget->spent(), Limits{}.max_states);
  EXPECT_LT(budget->spent(), Limits{}.max_work);
  budget.reset();  // each operation below has its own budget
  // Inside a class file the error names the entry.
  ClassTable table;
  Result<bool> r = load_class_file(R"({"classes": [{"name": "x", "expr": "L(S|D)*S(S|D){40}E"}]})", "f.json",
                                   ClassOptions{}, &table);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
  EXPECT_EQ(r.error().where, "f.json:/classes/0/expr");
  // The eye-first reversal is bounded too: E(S|D){14}S(S|D)*L is small forward, 2^15 reversed.
  ClassOptions small;
  small.limits.max_states = 5000;
  Result<PathClass> e = compile_class("E(S|D){14}S(S|D)*L", small);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().code, ErrorCode::kLimit);
  EXPECT_EQ(e.error().message, "the DFA exceeds the limit of 5000 states (raise it with --max-states)");
  EXPECT_TRUE(compile_class("E(S|D){14}S(S|D)*L", ClassOptions{}).ok());
}

// --- the multi-class classifier ---

// A class text for random class sets: built-ins, fixed shapes, and random middles light-first
// and eye-first.
std::string random_class(std::uint64_t seed) {
  static const char* kFixed[] = {"$local", "$caustic", "$direct", "$indirect", "$emission", "$all", "~$local",
                                 "L.*SS.*E", "L..(.*SDS.*)..E", "E..S.*..L", "L..D+..E"};
  const std::uint64_t pick = seed % 4;
  oracle::RandomRegex gen(seed);
  if (pick == 0) return kFixed[(seed / 4) % std::size(kFixed)];
  if (pick == 1) return "E(" + gen.expression(3) + ")L";
  return "L(" + gen.expression(3) + ")E";
}

// Which classes accept `path`, each by its own DFA.
std::vector<int> expected_set(const std::vector<PathClass>& classes, std::string_view path) {
  std::vector<int> out;
  for (std::size_t i = 0; i < classes.size(); ++i)
    if (classes[i].dfa.accepts(path)) out.push_back(static_cast<int>(i));
  return out;
}

TEST(Classifier, ClassifiesEveryPathLikeItsClassesAndKnowsWhatIsAlive) {
  const std::vector<std::string> paths = valid_paths(12);
  std::vector<std::string> probes = paths;
  for (std::size_t i = 0; i < oracle::strings_up_to(5); ++i) probes.push_back(oracle::shortlex_string(i));
  for (const char* odd : {"LDDxDE", "ldddse", "LDD DSE", "LDDDSE\n", "\xce\xa8LDDDSE"}) probes.push_back(odd);
  std::size_t nonempty_sets = 0, dead_prefixes = 0, alive_prefixes = 0, long_only = 0;
  for (std::uint64_t set = 0; set < 40; ++set) {
    std::vector<PathClass> classes;
    const std::uint64_t n = 1 + set % 6;
    for (std::uint64_t k = 0; k < n; ++k) classes.push_back(full(random_class(9000 + set * 10 + k)));
    std::vector<const PathClass*> ptrs;
    std::string names;
    for (const PathClass& c : classes) {
      ptrs.push_back(&c);
      names += " '" + c.text + "'";
    }
    Result<Classifier> built = Classifier::build(ptrs, Limits{});
    ASSERT_TRUE(built.ok()) << names << ": " << built.error().render();
    const Classifier& cl = *built;
    ASSERT_EQ(cl.num_classes(), static_cast<int>(n));
    for (std::size_t i = 0; i < classes.size(); ++i) EXPECT_EQ(cl.name(static_cast<int>(i)), classes[i].text);
    for (const std::string& p : probes) {
      const std::vector<int> want = expected_set(classes, p);
      nonempty_sets += !want.empty();
      ASSERT_EQ(cl.members(cl.classify(p)), want) << names << " on '" << p << "'";
      ASSERT_EQ(cl.members(cl.classify_backward(p)), want) << names << " on '" << p << "' read backward";
    }
    std::vector<Dfa> reversed_dfas;
    std::vector<std::vector<std::uint8_t>> forward_live, reversed_live;
    for (const PathClass& c : classes) {
      reversed_dfas.push_back(dfa_reverse(c.dfa, Limits{}).expect("a test input"));
      forward_live.push_back(c.dfa.live());
      reversed_live.push_back(reversed_dfas.back().live());
    }
    // alive: forward after a prefix, backward after a suffix. Brute force: some class accepts
    // prefix + x or prefix + x E, or x + suffix or L x + suffix, for x in [SD]^{0..7} (every
    // member is L[SD]*E). When that finds nothing, a longer completion may still exist; then
    // some class's own DFA must have a live state there.
    std::vector<std::string> heads;  // x and L x, for the backward search
    std::function<void(const std::string&)> grow = [&](const std::string& x) {
      heads.push_back(x);
      heads.push_back("L" + x);
      if (x.size() < 7)
        for (const char* ch : {"D", "S"}) grow(x + ch);
    };
    grow("");
    std::vector<std::vector<int>> head_state(classes.size());
    for (std::size_t c = 0; c < classes.size(); ++c)
      for (const std::string& h : heads) {
        int t = classes[c].dfa.start;
        for (char ch : h) t = classes[c].dfa.step(t, *letter_from_char(ch));
        head_state[c].push_back(t);
      }
    for (std::size_t i = 0; i < oracle::strings_up_to(6); ++i) {
      const std::string q = oracle::shortlex_string(i);
      bool found_fwd = false, found_bwd = false;
      // Forward: from the states after q, every tail x up to 7 letters, then optionally E.
      std::function<void(const std::vector<int>&, int)> tails = [&](const std::vector<int>& st, int depth) {
        for (std::size_t c = 0; c < classes.size() && !found_fwd; ++c) {
          const Dfa& d = classes[c].dfa;
          found_fwd = d.accept[static_cast<std::size_t>(st[c])] || d.accept[static_cast<std::size_t>(d.step(st[c], kE))];
        }
        if (found_fwd || depth == 7) return;
        for (Letter l : {kD, kS}) {
          std::vector<int> next(st.size());
          for (std::size_t c = 0; c < classes.size(); ++c) next[c] = classes[c].dfa.step(st[c], l);
          tails(next, depth + 1);
        }
      };
      std::vector<int> after_q(classes.size());
      for (std::size_t c = 0; c < classes.size(); ++c) {
        int t = classes[c].dfa.start;
        for (char ch : q) t = classes[c].dfa.step(t, *letter_from_char(ch));
        after_q[c] = t;
      }
      tails(after_q, 0);
      // Backward: every head, then q.
      for (std::size_t h = 0; h < heads.size() && !found_bwd; ++h)
        for (std::size_t c = 0; c < classes.size() && !found_bwd; ++c) {
          int t = head_state[c][h];
          for (char ch : q) t = classes[c].dfa.step(t, *letter_from_char(ch));
          found_bwd = classes[c].dfa.accept[static_cast<std::size_t>(t)] != 0;
        }
      for (int backward = 0; backward < 2; ++backward) {
        const Classifier::Direction& dir = backward ? cl.backward() : cl.forward();
        Classifier::State s = dir.start;
        if (backward) {
          for (std::size_t k = q.size(); k-- > 0;) s = Classifier::step(dir, s, q[k]);
        } else {
          for (char ch : q) s = Classifier::step(dir, s, ch);
        }
        bool live_somewhere = false;
        for (std::size_t c = 0; c < classes.size(); ++c) {
          const Dfa& d = backward ? reversed_dfas[c] : classes[c].dfa;
          int t = d.start;
          for (std::size_t k = 0; k < q.size(); ++k)
            t = d.step(t, *letter_from_char(q[backward ? q.size() - 1 - k : k]));
          live_somewhere = live_somewhere || (backward ? reversed_live : forward_live)[c][static_cast<std::size_t>(t)];
        }
        const bool alive = cl.alive(dir, s);
        const bool found = backward ? found_bwd : found_fwd;
        const std::string what = names + (backward ? " suffix '" : " prefix '") + q + "'";
        if (found) {
          EXPECT_TRUE(alive) << what;
        } else {
          long_only += alive;
        }
        EXPECT_EQ(alive, live_somewhere) << what;
        (alive ? alive_prefixes : dead_prefixes)++;
      }
    }
    // A character outside the alphabet leads to the sink: no class, nothing alive.
    Classifier::State s = cl.forward().start;
    for (char ch : std::string("LDx")) s = Classifier::step(cl.forward(), s, ch);
    EXPECT_FALSE(cl.alive(cl.forward(), s));
    EXPECT_TRUE(cl.members(cl.set_of(cl.forward(), s)).empty());
  }
  EXPECT_GT(nonempty_sets, 5000u) << "the class sets must match real paths";
  EXPECT_GT(alive_prefixes, 1000u);
  EXPECT_GT(dead_prefixes, 1000u);
  EXPECT_LT(long_only, alive_prefixes / 10) << "most alive states have a short completion the search finds";
}

TEST(Classifier, TheTwentySampleClassesAgreeWithTheirDfas) {
  ClassTable table;
  Result<bool> r = read_class_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/twenty.json", ClassOptions{}, &table);
  ASSERT_TRUE(r.ok()) << r.error().render();
  std::vector<const PathClass*> ptrs;
  for (const auto& c : table.user_classes()) ptrs.push_back(c.get());
  ASSERT_GE(ptrs.size(), 20u);
  Result<Classifier> cl = Classifier::build(ptrs, Limits{});
  ASSERT_TRUE(cl.ok()) << cl.error().render();
  for (const std::string& p : valid_paths(12)) {
    std::vector<int> want;
    for (std::size_t i = 0; i < ptrs.size(); ++i)
      if (ptrs[i]->dfa.accepts(p)) want.push_back(static_cast<int>(i));
    ASSERT_EQ(cl->members(cl->classify(p)), want) << p;
    ASSERT_EQ(cl->members(cl->classify_backward(p)), want) << p;
  }
}

TEST(Classifier, ProductPastTheLimitFailsNamingTheOption) {
  std::vector<PathClass> classes;
  for (const char* t : {"L.*DD.*E", "L.*SS.*E", "L.*SDS.*E", "L.*DSD.*E", "$caustic"}) classes.push_back(full(t));
  std::vector<const PathClass*> ptrs;
  for (const PathClass& c : classes) ptrs.push_back(&c);
  Result<Classifier> ok = Classifier::build(ptrs, Limits{});
  ASSERT_TRUE(ok.ok());
  Limits small;
  small.max_states = 40;
  for (const PathClass& c : classes) ASSERT_LE(c.dfa.num_states, 40) << "each class alone fits";
  Result<Classifier> r = Classifier::build(ptrs, small);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
  EXPECT_EQ(r.error().message, "the classifier automaton exceeds the limit of 40 states (raise it with --max-states)");
}

}  // namespace
}  // namespace pathex
