// The parser against its corpus (grammar/corpus/*.json, the RE2 habit of {input, dump} tables):
// every valid entry parses to the exact tree dump and its normal form reparses to the same tree;
// every invalid entry fails with the exact code, column and message. Then what the corpus cannot
// express: other limits, user-defined names, node columns, caret rendering, hostile nesting.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/stack.h"
#include "regex/ast.h"
#include "regex/lpe.h"
#include "regex/parser.h"

namespace pathex {
namespace {

// The error of a result that must have failed (a Result's error is read only after a check).
Error error_of(const Result<Regex>& r) {
  EXPECT_FALSE(r.ok());
  return r.ok() ? Error{} : r.error();
}

nlohmann::json load_corpus(const std::string& name) {
  const std::string path = std::string(PATHEX_SOURCE_DIR) + "/grammar/corpus/" + name;
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot open " << path;
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

const NameLookup& builtin_names() {
  static const NameLookup lookup = [](std::string_view name) -> const Regex* {
    const PathClass* c = ClassTable::builtins().find(name);
    return c ? &c->ast : nullptr;
  };
  return lookup;
}

Result<Regex> parse_default(std::string_view text) { return parse(text, Limits{}, builtin_names()); }

std::string code_name(ErrorCode c) {
  switch (c) {
    case ErrorCode::kSyntax: return "syntax";
    case ErrorCode::kUnknownName: return "unknown-name";
    case ErrorCode::kLimit: return "limit";
    default: return "other";
  }
}

// --- the corpus ---

TEST(ParserCorpus, ValidEntriesParseToTheirDump) {
  const nlohmann::json corpus = load_corpus("valid.json");
  ASSERT_GE(corpus.size(), 60u);
  for (const auto& entry : corpus) {
    const std::string expr = entry.at("expr");
    Result<Regex> r = parse_default(expr);
    ASSERT_TRUE(r.ok()) << "'" << expr << "': " << r.error().render();
    EXPECT_EQ(dump(*r), entry.at("dump").get<std::string>()) << "'" << expr << "'";
    EXPECT_EQ(r->source, expr);
  }
}

TEST(ParserCorpus, NormalFormReparsesToTheSameTree) {
  for (const auto& entry : load_corpus("valid.json")) {
    const std::string expr = entry.at("expr");
    Result<Regex> r = parse_default(expr);
    ASSERT_TRUE(r.ok()) << expr;
    const std::string normal = to_string(*r);
    Result<Regex> again = parse_default(normal);
    ASSERT_TRUE(again.ok()) << "normal form '" << normal << "' of '" << expr << "': " << again.error().render();
    EXPECT_EQ(dump(*again), entry.at("dump").get<std::string>()) << "'" << expr << "' -> '" << normal << "'";
    EXPECT_EQ(to_string(*again), normal) << "the normal form is a fixed point";
    EXPECT_EQ(normal.find_first_of(" \t\n"), std::string::npos) << normal;
  }
}

TEST(ParserCorpus, InvalidEntriesFailWithCodeColumnAndMessage) {
  const nlohmann::json corpus = load_corpus("invalid.json");
  ASSERT_GE(corpus.size(), 40u);
  std::set<std::string> codes;
  for (const auto& entry : corpus) {
    const std::string expr = entry.at("expr");
    Result<Regex> r = parse_default(expr);
    ASSERT_FALSE(r.ok()) << "'" << expr << "' parsed to " << dump(*r);
    const Error& e = r.error();
    EXPECT_EQ(code_name(e.code), entry.at("code").get<std::string>()) << "'" << expr << "'";
    EXPECT_EQ(e.column, entry.at("column").get<int>()) << "'" << expr << "': " << e.message;
    EXPECT_EQ(e.message, entry.at("message").get<std::string>()) << "'" << expr << "'";
    EXPECT_EQ(e.source, expr);
    EXPECT_TRUE(e.where.empty());
    // The caret is under a character of the text or just past its end.
    EXPECT_GE(e.column, 1);
    EXPECT_LE(e.column, static_cast<int>(expr.size()) + 1) << expr;
    codes.insert(entry.at("code").get<std::string>());
  }
  EXPECT_EQ(codes, (std::set<std::string>{"syntax", "unknown-name", "limit"}));
}

// The corpus is only as good as its coverage: every operator and token must appear.
TEST(ParserCorpus, ValidCorpusCoversEveryConstruct) {
  std::string all;
  for (const auto& entry : load_corpus("valid.json")) all += entry.at("expr").get<std::string>() + "\n";
  for (const char* token : {"|", "&", "~", "*", "+", "?", "{", ",}", ".", "[", "[^", "(", "$", " ", "\t", "E.*", "ED"}) {
    EXPECT_NE(all.find(token), std::string::npos) << "no valid entry uses '" << token << "'";
  }
  for (const char* name : {"$all", "$local", "$emission", "$direct", "$indirect", "$caustic"})
    EXPECT_NE(all.find(name), std::string::npos) << name;
}

// --- limits other than the defaults ---

TEST(ParserLimits, DepthCountsGroupsComplementsAndOperators) {
  Limits l;
  l.max_depth = 3;
  EXPECT_TRUE(parse("~~S", l).ok());    // two '~' levels, tree height 3
  EXPECT_TRUE(parse("((S))", l).ok());  // two '(' levels, tree height 1
  EXPECT_TRUE(parse("S**", l).ok());    // tree height 3
  struct Case {
    const char* expr;
    int column;
  };
  // The last case is too tall only as a whole: the caret goes under the first character of the alternation.
  for (const Case c : {Case{"~~~S", 3}, Case{"(((S)))", 3}, Case{"(~(S))", 3}, Case{"S***", 4}, Case{"(S*)*|D", 1}}) {
    Result<Regex> r = parse(c.expr, l);
    ASSERT_FALSE(r.ok()) << c.expr;
    EXPECT_EQ(r.error().code, ErrorCode::kLimit) << c.expr;
    EXPECT_EQ(r.error().column, c.column) << c.expr;
    EXPECT_EQ(r.error().message, "nesting depth exceeds the limit of 3 levels (raise it with --max-depth)");
  }
}

TEST(ParserLimits, RepeatCountsUpToTheLimit) {
  Limits l;
  l.max_repeat = 5;
  EXPECT_EQ(dump(parse("S{5}", l).expect("a test input")), "rep{5,5 S}");
  EXPECT_EQ(dump(parse("S{0,5}", l).expect("a test input")), "rep{0,5 S}");
  EXPECT_EQ(dump(parse("S{5,}", l).expect("a test input")), "rep{5, S}");
  for (const auto& [expr, column] : std::vector<std::pair<std::string, int>>{{"S{6}", 3}, {"S{2,6}", 5}, {"S{ 10 ,}", 4}}) {
    Result<Regex> r = parse(expr, l);
    ASSERT_FALSE(r.ok()) << expr;
    EXPECT_EQ(r.error().code, ErrorCode::kLimit);
    EXPECT_EQ(r.error().column, column) << expr;
    EXPECT_EQ(r.error().message, "repetition count exceeds the limit of 5 repetitions (raise it with --max-repeat)");
  }
}

// Nesting that would overflow the stack of a naive recursive descent fails at the 100th level.
TEST(ParserLimits, HostileNestingFailsWithALocatedErrorNotACrash) {
  for (const std::string& expr :
       {std::string(200000, '(') + "S" + std::string(200000, ')'), std::string(200000, '~') + "S",
        std::string(100000, '(') + "~" + std::string(100000, '~')}) {
    Result<Regex> r = parse(expr, Limits{});
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kLimit);
    EXPECT_EQ(r.error().column, 100);
  }
  // Long but flat inputs are fine: concatenation and alternation are loops, not recursion.
  const std::string flat(200000, 'S');
  Result<Regex> r = parse(flat, Limits{});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->at(r->root).kids.size(), flat.size());
  std::string alts = "S";
  for (int i = 0; i < 50000; ++i) alts += "|D";
  ASSERT_TRUE(parse(alts, Limits{}).ok());
}

// The ceiling of --max-depth is safe: every recursive routine over the tree (parse, print, dump,
// reverse, the Thompson construction with nested & and ~, the LPE parser) runs the tallest trees
// the ceiling lets through, and the inputs it stops, on a quarter of the command line's stack
// (core/stack.h). In a build whose frames grow so that the ceiling no longer has that margin
// (the sanitized build's are ten times a release build's), this test dies of a stack overflow.
TEST(ParserLimits, TheDepthCeilingRunsOnAQuarterOfTheCommandLineStack) {
  Limits l;
  l.max_depth = kMaxDepthCeiling;
  const int n = kMaxDepthCeiling;
  const std::vector<std::string> tallest = {
      "L" + std::string(n - 3, '(') + "S" + std::string(n - 3, ')') + "DDDE",  // groups: tree height n
      "L(" + std::string(n - 4, '~') + "S)DDDE",                               // complements
      "L(" + std::string(n - 4, '(') + "S" + std::string(n - 4, ')') + std::string(n - 4, '*') + ")DE",
      [n] {  // intersections, each nested in the next: ((S&S)&S)&…
        std::string e = "S";
        for (int i = 0; i < n / 2 - 2; ++i) e = "(" + e + "&S)";
        return "L" + e + "DE";
      }()};
  const std::vector<std::string> too_tall = {std::string(10000, '(') + "S", "S" + std::string(100000, '*'),
                                             std::string(100000, '~') + "S"};
  bool ran = false;
  ASSERT_TRUE(run_on_stack(kCommandLineStackBytes / 4, [&] {
    for (const std::string& expr : tallest) {
      const Result<Regex> r = parse(expr, l);
      ASSERT_TRUE(r.ok()) << expr.substr(0, 40) << ": " << r.error().render();
      EXPECT_EQ(parse(to_string(*r), l).expect("the printed tree").nodes.size(), r->nodes.size()) << expr.substr(0, 40);
      EXPECT_FALSE(dump(*r).empty());
      EXPECT_EQ(dump(reversed(reversed(*r))), dump(*r));
      ClassOptions options;
      options.limits = l;
      const Result<PathClass> c = compile_class(expr, options);
      ASSERT_TRUE(c.ok()) << expr.substr(0, 40) << ": " << c.error().render();
    }
    for (const std::string& expr : too_tall) {
      const Result<Regex> r = parse(expr, l);
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.error().code, ErrorCode::kLimit);
    }
    // LPEs nest the same way, in their own parser.
    const std::string lpe = "C" + std::string(n - 3, '(') + "D" + std::string(n - 3, ')') + "L";
    EXPECT_TRUE(parse_lpe(lpe, {LightType::kArea}, {SensorType::kPinhole}, l).ok());
    EXPECT_FALSE(parse_lpe("C" + std::string(10000, '(') + "D", {LightType::kArea}, {SensorType::kPinhole}, l).ok());
    ran = true;
  }));
  EXPECT_TRUE(ran);
}

// --- names ---

TEST(ParserNames, UserNamesAreGraftedAndReadGreedily) {
  ClassTable table;
  ASSERT_TRUE(table.add("glass", "L.*SS.*E", ClassOptions{}).ok());
  ASSERT_TRUE(table.add("glass-2", "$glass & $indirect", ClassOptions{}).ok());
  NameLookup lookup = [&](std::string_view n) -> const Regex* {
    const PathClass* c = table.find(n);
    return c ? &c->ast : nullptr;
  };
  Result<Regex> r = parse("$glass-2|$local", Limits{}, lookup);
  ASSERT_TRUE(r.ok()) << r.error().render();
  EXPECT_EQ(dump(*r),
            "alt{and{cat{L star{[DS]} S S star{[DS]} E} cat{L [DS] [DS] [DS] [DS] [DS] plus{[DS]} E}} "
            "cat{L star{[DS]} D D star{[DS]} E}}");
  // `$localD` is one name, not `$local` then D.
  Result<Regex> greedy = parse("$localD", Limits{}, lookup);
  ASSERT_FALSE(greedy.ok());
  EXPECT_EQ(greedy.error().code, ErrorCode::kUnknownName);
  EXPECT_EQ(greedy.error().message,
            "unknown class name '$localD', expected a built-in name or one defined earlier in the class file");
  EXPECT_EQ(dump(parse("$local D", Limits{}, lookup).expect("a test input")), "cat{cat{L star{[DS]} D D star{[DS]} E} D}");
  // Without a lookup every name is unknown.
  EXPECT_EQ(error_of(parse("$all", Limits{})).code, ErrorCode::kUnknownName);
}

// --- columns on nodes (the NFA builder reports limit errors at them) ---

TEST(ParserColumns, NodesRecordTheColumnOfTheirToken) {
  Result<Regex> r = parse("  S|  D&[SD]*  ~$all", Limits{}, builtin_names());
  ASSERT_TRUE(r.ok());
  const Regex& g = *r;
  const Node& alt = g.at(g.root);
  ASSERT_EQ(alt.kind, NodeKind::kAlt);
  EXPECT_EQ(alt.column, 3);                       // first token, not the leading spaces
  EXPECT_EQ(g.at(alt.kids[0]).column, 3);         // S
  const Node& conj = g.at(alt.kids[1]);
  ASSERT_EQ(conj.kind, NodeKind::kAnd);
  EXPECT_EQ(conj.column, 7);                      // D, after the spaces
  const Node& cat = g.at(conj.kids[1]);
  ASSERT_EQ(cat.kind, NodeKind::kConcat);
  EXPECT_EQ(cat.column, 9);                       // [
  EXPECT_EQ(g.at(cat.kids[0]).column, 13);        // the '*'
  EXPECT_EQ(g.at(g.at(cat.kids[0]).kids[0]).column, 9);  // the set
  EXPECT_EQ(g.at(cat.kids[1]).column, 16);        // '~'
  EXPECT_EQ(g.at(g.at(cat.kids[1]).kids[0]).column, 17);  // the grafted $all
}

// --- rendering with the caret (exact strings) ---

TEST(ParserRender, CaretSitsUnderTheOffendingCharacter) {
  EXPECT_EQ(error_of(parse_default("L(DD")).render(),
            "column 2: missing ')' to close this '('\n"
            "  L(DD\n"
            "   ^");
  EXPECT_EQ(error_of(parse_default("LDD)E")).render(),
            "column 4: unmatched ')'\n"
            "  LDD)E\n"
            "     ^");
  // Past the end: the caret sits just after the last character.
  EXPECT_EQ(error_of(parse_default("S|")).render(),
            "column 3: expected a letter, '.', '[', '(', '~' or '$name' after '|', found the end\n"
            "  S|\n"
            "    ^");
  // Tabs before the caret are copied so the caret lines up in a terminal.
  EXPECT_EQ(error_of(parse_default("L\t(DD")).render(),
            "column 3: missing ')' to close this '('\n"
            "  L\t(DD\n"
            "   \t^");
  // The empty expression has no source line to point into.
  EXPECT_EQ(error_of(parse_default("")).render(),
            "column 1: empty expression, expected a letter, '.', '[', '(', '~' or '$name'");
  // A caller that knows the file adds `where`.
  Error e = error_of(parse_default("$caustic | $nope"));
  e.where = "classes.json:/classes/3/expr";
  EXPECT_EQ(e.render(),
            "classes.json:/classes/3/expr: column 12: unknown class name '$nope', expected a built-in name or one "
            "defined earlier in the class file\n"
            "  $caustic | $nope\n"
            "             ^");
}

}  // namespace
}  // namespace pathex
