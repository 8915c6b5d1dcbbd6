// Light path expressions against their corpus (grammar/corpus/lpe.json): every valid LPE denotes
// exactly the class of its full-path expression (minimal-DFA equality), every invalid one fails
// with the exact column and message. Then the way back: explain --emit lpe's LPE, read back with
// --notation lpe, is the same class (exact) or contains it (approximate), for the corpus, the
// built-ins and random classes; and the full-path form shown for an LPE is its class.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "automata/dfa.h"
#include "automata/ops.h"
#include "automata/to_regex.h"
#include "language/lpe_emit.h"
#include "language/notation_hint.h"
#include "classify/pathclass.h"
#include "regex/lpe.h"
#include "regex/parser.h"

namespace pathex {
namespace {

const nlohmann::json& corpus() {
  static const nlohmann::json c = [] {
    std::ifstream in(std::string(PATHEX_SOURCE_DIR) + "/grammar/corpus/lpe.json");
    std::stringstream ss;
    ss << in.rdbuf();
    return nlohmann::json::parse(ss.str());
  }();
  return c;
}

ClassOptions lpe_options() {
  ClassOptions o;
  o.notation = Notation::kLpe;
  return o;
}

Dfa full(const std::string& expr) {
  Result<PathClass> c = compile_class(expr, ClassOptions{});
  EXPECT_TRUE(c.ok()) << expr << ": " << (c ? "" : c.error().render());
  return c ? c->dfa : dfa_empty();
}

Dfa lpe(const std::string& expr, const ClassOptions& o = lpe_options()) {
  Result<PathClass> c = compile_class(expr, o);
  EXPECT_TRUE(c.ok()) << expr << ": " << (c ? "" : c.error().render());
  return c ? c->dfa : dfa_empty();
}

// --- the corpus ---

TEST(LpeCorpus, EachValidLpeIsTheClassOfItsFullPathExpression) {
  const nlohmann::json& c = corpus();
  ASSERT_GE(c["valid"].size(), 50u);
  for (const auto& e : c["valid"]) {
    const std::string l = e["lpe"], f = e["full"];
    EXPECT_EQ(lpe(l), full(f)) << l << " should be " << f << " (" << e["source"].get<std::string>() << ")";
  }
}

TEST(LpeCorpus, EachInvalidLpeFailsWithItsColumnAndMessage) {
  const nlohmann::json& c = corpus();
  ASSERT_GE(c["invalid"].size(), 30u);
  for (const auto& e : c["invalid"]) {
    const std::string l = e["lpe"];
    Result<PathClass> r = compile_class(l, lpe_options());
    ASSERT_FALSE(r.ok()) << l;
    EXPECT_EQ(r.error().column, e["column"].get<int>()) << l << ": " << r.error().message;
    EXPECT_EQ(r.error().message, e["message"].get<std::string>()) << l;
    EXPECT_EQ(r.error().code, e["code"] == "limit" ? ErrorCode::kLimit : ErrorCode::kSyntax) << l;
    EXPECT_EQ(r.error().source, l);
  }
}

// The corpus covers the production AOV kinds the issue names and every piece of syntax.
TEST(LpeCorpus, CoversTheUsualAovsAndTheSyntax) {
  std::string all;
  for (const auto& e : corpus()["valid"]) all += e["lpe"].get<std::string>() + "\n";
  for (const char* s : {"C<RD>L\n", "C<RD>[DSO].*", "C<RS>L\n", "C<RD>S+L", "CO\n", "C[LO]", "C.*\n", "|", "[^", "<.", "{2}",
                        "{2,}", "{1,2}", "?", "+", "*", "(", " ", "G"})
    EXPECT_NE(all.find(s), std::string::npos) << s;
}

// --- ends: C and L are the sensor and light types in force ---

TEST(LpeEnds, CameraAndLightTakeTheTypesInForce) {
  ClassOptions o = lpe_options();
  o.ends.lights = {LightType::kPoint};
  o.ends.sensors = {SensorType::kPinhole};
  EXPECT_EQ(lpe("C<RD>L", o), full("LSDDDSE"));
  EXPECT_TRUE(is_empty(lpe("C<RD>O", o)));  // O is an area light; there is none
  o.ends.lights = {LightType::kArea, LightType::kDistant};
  o.ends.sensors = {SensorType::kLens, SensorType::kOrthographic};
  EXPECT_EQ(lpe("CS+L", o), full("LD[DS]S+[DS]DE"));
  EXPECT_EQ(lpe("CSO", o), full("LDDS[DS]DE"));
}

TEST(LpeEnds, ClassFilesMayNameLpeClassesFromFullExpressions) {
  ClassTable table;
  ASSERT_TRUE(table.add("dd", "C<RD>L", lpe_options()).ok());
  Result<PathClass> c = compile_class("$dd|LDDSDDE", ClassOptions{}, &table);
  ASSERT_TRUE(c.ok()) << c.error().render();
  EXPECT_EQ(c->dfa, full("L..D..E|LDDSDDE"));
  Result<PathClass> bad = compile_class("C$dd", lpe_options(), &table);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().column, 2);
}

TEST(LpeLimits, NestingIsBounded) {
  ClassOptions o = lpe_options();
  o.limits.max_depth = 6;  // the translation of C and L adds three levels of its own
  EXPECT_TRUE(compile_class("C((D))L", o).ok());
  Result<PathClass> r = compile_class("C((((((D))))))L", o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
  EXPECT_EQ(r.error().column, 7);
  // A hostile depth fails with a message, not a stack overflow.
  EXPECT_FALSE(compile_class(std::string(100000, '(') + "D", lpe_options()).ok());
}

// --- the way back ---

// emit_lpe's promise: read back, the LPE is the class (exact) or a superset (approximate) and
// never drops a path.
void expect_round_trip(const Dfa& cls, const std::string& what) {
  Result<LpeEmission> e = emit_lpe(cls, Limits{});
  ASSERT_TRUE(e.ok()) << what << ": " << e.error().render();
  if (is_empty(cls)) {
    EXPECT_TRUE(e->empty) << what;
    return;
  }
  const Dfa back = lpe(e->lpe);
  EXPECT_EQ(e->exact, back == cls) << what << " -> " << e->lpe;
  EXPECT_TRUE(is_subset(cls, back)) << what << " -> " << e->lpe;
  if (!e->exact) {
    ASSERT_TRUE(e->example.has_value()) << what;
    EXPECT_TRUE(back.accepts(*e->example) && !cls.accepts(*e->example)) << *e->example;
    EXPECT_FALSE(e->losses.empty()) << what;
  }
}

TEST(LpeEmit, CorpusClassesRoundTripExactly) {
  for (const auto& e : corpus()["valid"]) {
    const Dfa cls = full(e["full"]);
    expect_round_trip(cls, e["full"]);
    // A corpus class from an LPE without O has every light and sensor type: nothing is lost.
    Result<LpeEmission> em = emit_lpe(cls, Limits{});
    if (em && !em->empty && e["lpe"].get<std::string>().find('O') == std::string::npos) {
      EXPECT_TRUE(em->exact) << e["full"].get<std::string>() << " -> " << em->lpe;
    }
  }
}

TEST(LpeEmit, BuiltinsAndKnownAnswers) {
  for (const auto& c : ClassTable::builtins().builtin_classes()) expect_round_trip(c->dfa, "$" + c->name);
  Result<LpeEmission> caustic = emit_lpe(full("$caustic"), Limits{});
  ASSERT_TRUE(caustic.ok());
  EXPECT_EQ(caustic->lpe, "C[DGS]*[DG]S+[LO]");  // (S*[DG])+ is written [DGS]*[DG]
  EXPECT_TRUE(caustic->exact);
  Result<LpeEmission> direct = emit_lpe(full("$direct"), Limits{});
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(direct->lpe, "C[DGS][LO]");
  EXPECT_TRUE(direct->exact);
  Result<LpeEmission> emission = emit_lpe(full("$emission"), Limits{});
  ASSERT_TRUE(emission.ok());
  EXPECT_EQ(emission->lpe, "C[LO]");

  // A point light seen by an orthographic camera: the LPE is CL and loses both types.
  Result<LpeEmission> ortho = emit_lpe(full("LSDSDE"), Limits{});
  ASSERT_TRUE(ortho.ok());
  EXPECT_EQ(ortho->lpe, "CL");
  EXPECT_FALSE(ortho->exact);
  EXPECT_EQ(ortho->losses, (std::vector<std::string>{
                               "light types: the class has only point lights; an LPE's L is every light",
                               "sensor types: the class has only orthographic sensors; an LPE's C is every sensor"}));
  EXPECT_EQ(ortho->example, "LDDDDE");

  // $local allows every light and sensor type but ties DD to the ends: an LPE cannot say so.
  Result<LpeEmission> local = emit_lpe(full("$local"), Limits{});
  ASSERT_TRUE(local.ok());
  EXPECT_EQ(local->lpe, "C[DGS]*[LO]");
  EXPECT_EQ(local->losses, (std::vector<std::string>{
                               "the class ties its interior letters to particular light or sensor types; an LPE cannot"}));
  EXPECT_TRUE(emit_lpe(full("LSDE"), Limits{}).expect("a test input").empty);
}

// Random classes: unions of a few random full paths and random end-product classes.
TEST(LpeEmit, RandomClassesRoundTrip) {
  std::mt19937 rng(15);
  const char* interiors[] = {"", "D", "S", "DS", "S+", "D*", "(DS)*", "S*D", "[SD]{2}", "D+S?D", "(S|DD)+", ".*SD.*"};
  for (int i = 0; i < 200; ++i) {
    std::string expr;
    const int terms = 1 + static_cast<int>(rng() % 3);
    for (int t = 0; t < terms; ++t) {
      const std::string ends[] = {"..", "DD", "SD", "DS", "SS", "[DS]D"};
      expr += (t ? "|" : "") + std::string("L") + ends[rng() % 6] + interiors[rng() % 12] + ends[rng() % 6] + "E";
    }
    expect_round_trip(full(expr), expr);
  }
}

// The full-path form explain shows for an LPE is exactly its class, and reads well.
TEST(LpeFullPathForm, IsTheClassAndFactorsTheEnds) {
  for (const auto& e : corpus()["valid"]) {
    const Dfa cls = full(e["full"]);
    Result<std::string> f = full_path_expression(cls, Limits{});
    ASSERT_TRUE(f.ok());
    if (is_empty(cls)) {
      EXPECT_EQ(*f, "");
      continue;
    }
    EXPECT_EQ(full(*f), cls) << e["full"].get<std::string>() << " printed as " << *f;
  }
  EXPECT_EQ(full_path_expression(lpe("C<RD>L"), Limits{}).expect("a test input"), "L..D..E");
  EXPECT_EQ(full_path_expression(lpe("C<RD>S+L"), Limits{}).expect("a test input"), "L..S+D..E");
  EXPECT_EQ(full_path_expression(lpe("C.*DS+L"), Limits{}).expect("a test input"), "L..S+D.*..E");
  EXPECT_EQ(full_path_expression(lpe("CO"), Limits{}).expect("a test input"), "LDD..E");
  EXPECT_EQ(full_path_expression(lpe("C<RD>.*"), Limits{}).expect("a test input"), "L...*D..E");
}

// State elimination alone, on random DFAs of random expressions, printed in full notation.
TEST(ToRegex, EliminationGivesTheSameLanguage) {
  std::mt19937 rng(7);
  const char* atoms[] = {"S", "D", ".", "L", "E", "(SD)", "[DE]"};
  const char* ops[] = {"", "", "*", "+", "?", "{2}"};
  for (int i = 0; i < 300; ++i) {
    std::string expr;
    const int n = 1 + static_cast<int>(rng() % 6);
    for (int k = 0; k < n; ++k) {
      if (k && rng() % 4 == 0) expr += "|";
      expr += std::string(atoms[rng() % 7]) + ops[rng() % 6];
    }
    Result<Regex> r = parse(expr, Limits{});
    ASSERT_TRUE(r.ok()) << expr;
    const Dfa d = compile(*r, Limits{}).expect("a test input");
    Result<Expr> x = dfa_to_expr(d, 2000, 100000);
    ASSERT_TRUE(x.ok());
    const std::string text = to_full_notation(*x);
    if (nullable(*x)) continue;  // ε cannot be written on its own in pathex syntax
    Result<Regex> back = parse(text, Limits{});
    ASSERT_TRUE(back.ok()) << expr << " -> " << text;
    EXPECT_EQ(compile(*back, Limits{}).expect("a test input"), d) << expr << " -> " << text;
  }
}

// --- the Heckbert hint ---

TEST(HeckbertHint, HeckbertStringsInFullNotationGetOne) {
  const std::string tail =
      ", which writes two letters for each light and sensor; for Heckbert's classic L…E add --notation heckbert";
  auto hint = [](const std::string& text) {
    Result<PathClass> c = compile_class(text, ClassOptions{});
    EXPECT_TRUE(c.ok()) << text;
    return heckbert_hint(text, *c, ClassOptions{}, nullptr);
  };
  EXPECT_EQ(hint("LSDE"), "'LSDE' matches no path in full notation" + tail);
  EXPECT_EQ(hint("LDSDE"), "'LDSDE' matches no path in full notation" + tail);
  EXPECT_EQ(hint("LS+DE"), "'LS+DE' matches only paths from a laser (LSS…) in full notation" + tail);
  EXPECT_EQ(hint("LDD(S|D)*SSE"), "'LDD(S|D)*SSE' matches only paths into a spot meter (…SSE) in full notation" + tail);
  // Full-notation classes that mean what they say get none.
  for (const char* quiet : {"LSDSDE", "L.*DD.*E", "$caustic", "LSS.*E", "LDDDDE", "L[SD]{4,}E"})
    EXPECT_EQ(hint(quiet), std::nullopt) << quiet;
  // Nor an empty class that is empty in Heckbert notation too.
  EXPECT_EQ(hint("LE&LDE"), std::nullopt);
}

}  // namespace
}  // namespace pathex
