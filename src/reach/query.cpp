#include "reach/query.h"

#include "automata/ops.h"
#include "core/budget.h"

namespace pathex {
namespace {

std::string light_name(const std::string& pair) {
  auto t = light_type_from_letters(pair);
  return t ? to_string(*t) : "?";
}
std::string sensor_name(const std::string& pair) {
  auto t = sensor_type_from_letters(pair);
  if (!t) return "?";
  return *t == SensorType::kSpotmeter ? "spot meter" : to_string(*t);
}

// What each S letter fixes, in words.
std::vector<std::string> fixed_facts(const FullPath& p) {
  std::vector<std::string> facts;
  const int k = p.k();
  const std::string lp = std::string{p.c(0), p.c(1)};
  const std::string sp = std::string{p.c(k + 1), p.c(k + 2)};
  const bool x0 = p.c(0) == 'S', dir0 = p.c(1) == 'S';
  if (x0 && dir0) facts.push_back("the " + light_name(lp) + " fixes x0 and the first direction");
  else if (x0) facts.push_back("the " + light_name(lp) + " light fixes x0");
  else if (dir0) facts.push_back("the " + light_name(lp) + " light fixes the first direction");
  std::vector<int> spec;
  for (int i = 2; i <= k; ++i)
    if (p.c(i) == 'S') spec.push_back(i - 1);
  if (!spec.empty()) {
    std::string s = spec.size() == 1 ? "x" + std::to_string(spec[0]) + " is specular"
                                     : std::to_string(spec.size()) + " specular vertices (";
    if (spec.size() > 1) {
      for (std::size_t j = 0; j < spec.size(); ++j) s += (j ? " " : "") + ("x" + std::to_string(spec[j]));
      s += ")";
    }
    facts.push_back(s);
  }
  const bool dirk = p.c(k + 1) == 'S', xk = p.c(k + 2) == 'S';
  if (dirk && xk) facts.push_back("the " + sensor_name(sp) + " fixes the last direction and x" + std::to_string(k));
  else if (dirk) facts.push_back("the " + sensor_name(sp) + " sensor fixes the last direction");
  else if (xk) facts.push_back("the " + sensor_name(sp) + " camera fixes x" + std::to_string(k));
  return facts;
}

std::string join_and(const std::vector<std::string>& parts) {
  std::string s;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i) s += i + 1 == parts.size() ? " and " : ", ";
    s += parts[i];
  }
  return s;
}

Result<QueryResult> query_unbudgeted(const PathClass& c, const CompiledProfile& r, const QueryOptions& o);

std::vector<std::string> strategies_for(const std::string& path, const CompiledProfile& r) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < r.profile->strategies.size(); ++i)
    if (r.strategy_languages[i].accepts(path)) out.push_back(r.profile->strategies[i].name);
  return out;
}

}  // namespace

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::kEmpty: return "empty";
    case Verdict::kReachable: return "reachable";
    case Verdict::kPartial: return "partial";
    case Verdict::kUnreachable: return "unreachable";
  }
  return "";
}

Result<CompiledProfile> compile_profile(const Profile& p, std::optional<int> max_bounces, const Limits& limits) {
  return within_budget(limits, [&]() -> Result<CompiledProfile> {
    CompiledProfile c;
    c.profile = &p;
    c.max_bounces = max_bounces ? max_bounces : p.max_bounces;
    c.reachable = dfa_empty();
    for (const Strategy& st : p.strategies) {
      Result<Dfa> l = strategy_language(st, c.max_bounces, limits);
      if (!l) return l.error();
      c.reachable = dfa_union(c.reachable, *l);
      c.strategy_languages.push_back(std::move(*l));
    }
    return c;
  });
}

std::vector<ChainEvidence> chain_evidence(const std::string& path) {
  std::vector<ChainEvidence> out;
  Result<FullPath> p = parse_full_path(path, path.size());
  if (!p) return out;
  for (const Chain& c : chains(*p)) {
    ChainEvidence e{c, {}};
    for (ConnectorKind k : kCatalogue)
      if (connector_handles(k, c.letters, c.from, c.to, p->k())) e.connectors.push_back(k);
    out.push_back(std::move(e));
  }
  return out;
}

std::string unreachable_reason(const std::string& path, const CompiledProfile& r) {
  Result<FullPath> p = parse_full_path(path, path.size());
  if (!p) return "not a valid full path";
  if (r.max_bounces && p->k() - 1 > *r.max_bounces)
    return std::to_string(p->k() - 1) + " bounces exceed max_bounces " + std::to_string(*r.max_bounces);
  std::vector<std::string> dd;
  for (const Chain& c : chains(*p))
    if (c.letters == "DD") dd.push_back("c" + std::to_string(c.from) + "..c" + std::to_string(c.to));
  if (dd.empty()) {
    std::vector<std::string> facts = fixed_facts(*p);
    return "no DD join" + (facts.empty() ? std::string() : ": " + join_and(facts));
  }
  std::string strategies;
  for (const Strategy& st : r.profile->strategies) strategies += (strategies.empty() ? "" : ", ") + st.describe();
  return "its DD joins (" + join_and(dd) + ") are not where " + r.profile->name + " joins: " + strategies;
}

Result<QueryResult> query(const PathClass& c, const CompiledProfile& r, const QueryOptions& o) {
  return within_budget(o.limits, [&]() -> Result<QueryResult> { return query_unbudgeted(c, r, o); });
}

namespace {

Result<QueryResult> query_unbudgeted(const PathClass& c, const CompiledProfile& r, const QueryOptions& o) {
  QueryResult q;
  q.expression = c.name.empty() ? c.text : "$" + c.name;
  q.renderer = r.profile->name;
  q.max_bounces = r.max_bounces;
  Dfa p = c.dfa;
  if (o.universe) p = dfa_intersect(p, *o.universe);
  if (o.max_bounces) p = dfa_intersect(p, bounded_universe(o.max_bounces));
  const Dfa yes = dfa_intersect(p, r.reachable);
  const Dfa no = dfa_difference(p, r.reachable);
  const bool p_empty = is_empty(p), yes_empty = is_empty(yes), no_empty = is_empty(no);
  q.verdict = p_empty ? Verdict::kEmpty : no_empty ? Verdict::kReachable : yes_empty ? Verdict::kUnreachable : Verdict::kPartial;

  q.max_len = o.max_len >= 0 ? o.max_len : o.max_bounces ? *o.max_bounces + 6 : 14;
  q.counts_class = count_by_length(p, q.max_len);
  q.counts_reachable = count_by_length(yes, q.max_len);
  q.counts_unreachable = count_by_length(no, q.max_len);
  q.finite_class = is_finite(p);
  q.finite_reachable = is_finite(yes);
  q.finite_unreachable = is_finite(no);

  const std::size_t n = static_cast<std::size_t>(std::max(o.witnesses, 0));
  // Witnesses: shortest members; enumerate within the first lengths that have members.
  auto witnesses = [&](const Dfa& d) {
    std::optional<std::string> first = shortest_member(d);
    if (!first) return std::vector<std::string>{};
    return enumerate_members(d, static_cast<int>(first->size()) + 8, n);
  };
  for (const std::string& w : witnesses(yes)) {
    Witness wi{w, chain_evidence(w), strategies_for(w, r), ""};
    q.reachable.push_back(std::move(wi));
  }
  for (const std::string& w : witnesses(no)) {
    Witness wi{w, chain_evidence(w), {}, unreachable_reason(w, r)};
    q.unreachable.push_back(std::move(wi));
  }
  return q;
}

}  // namespace

}  // namespace pathex
