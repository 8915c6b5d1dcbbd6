#include "io/reach_json.h"

namespace pathex {

nlohmann::json count_json(const BigUint& b) {
  std::uint64_t v = 0;
  if (b.to_u64(&v)) return v;
  return b.to_string();
}

nlohmann::json to_json(const ChainEvidence& c) {
  nlohmann::json conn = nlohmann::json::array();
  for (ConnectorKind k : c.connectors) conn.push_back(to_string(k));
  return {{"letters", c.chain.letters}, {"from", c.chain.from}, {"to", c.chain.to}, {"connectors", conn}};
}

nlohmann::json to_json(const Strategy& s) {
  nlohmann::json j = {{"name", s.name}, {"s", s.s.to_string()}, {"chain", s.chain}, {"t", s.t.to_string()}};
  j["connector"] = s.connector == ConnectorKind::kNone ? nlohmann::json(nullptr) : nlohmann::json(to_string(s.connector));
  return j;
}

nlohmann::json to_json(const Witness& w) {
  nlohmann::json o = {{"path", w.path}};
  nlohmann::json chains = nlohmann::json::array();
  for (const ChainEvidence& c : w.chains) chains.push_back(to_json(c));
  o["chains"] = chains;
  if (w.reason.empty()) o["strategies"] = w.strategies;  // reachable: who samples it
  else o["reason"] = w.reason;                           // unreachable: why nobody does
  return o;
}

nlohmann::json to_json(const QueryResult& q) {
  nlohmann::json j;
  j["expression"] = q.expression;
  j["renderer"] = q.renderer;
  j["verdict"] = to_string(q.verdict);
  j["max_bounces"] = q.max_bounces ? nlohmann::json(*q.max_bounces) : nlohmann::json(nullptr);
  auto witnesses = [](const std::vector<Witness>& ws) {
    nlohmann::json arr = nlohmann::json::array();
    for (const Witness& w : ws) arr.push_back(to_json(w));
    return arr;
  };
  j["reachable_witnesses"] = witnesses(q.reachable);
  j["unreachable_witnesses"] = witnesses(q.unreachable);
  // Ascending lengths that have members; counts past 2^64 are decimal strings.
  nlohmann::json counts = nlohmann::json::array();
  for (std::size_t n = 0; n < q.counts_class.size(); ++n) {
    if (q.counts_class[n].is_zero()) continue;
    counts.push_back({{"length", n},
                      {"class", count_json(q.counts_class[n])},
                      {"reachable", count_json(q.counts_reachable[n])},
                      {"unreachable", count_json(q.counts_unreachable[n])}});
  }
  j["counts_by_length"] = counts;
  j["counts_max_len"] = q.max_len;
  j["finite"] = {{"class", q.finite_class}, {"reachable", q.finite_reachable}, {"unreachable", q.finite_unreachable}};
  return j;
}

std::string query_json_text(const std::vector<std::vector<QueryResult>>& rows, const std::string& scene) {
  nlohmann::json arr = nlohmann::json::array();
  for (const std::vector<QueryResult>& row : rows)
    for (const QueryResult& q : row) {
      nlohmann::json j = to_json(q);
      if (!scene.empty()) j["scene"] = scene;
      arr.push_back(std::move(j));
    }
  return arr.dump(2) + "\n";
}

std::string renderers_json_text(const std::vector<ProfileReach>& profiles) {
  nlohmann::json arr = nlohmann::json::array();
  for (const ProfileReach& r : profiles) {
    const Profile& p = *r.profile;
    nlohmann::json j = {{"name", p.name}, {"description", p.description}, {"source", p.source}};
    j["max_bounces"] = p.max_bounces ? nlohmann::json(*p.max_bounces) : nlohmann::json(nullptr);
    nlohmann::json st = nlohmann::json::array();
    for (const Strategy& s : p.strategies) st.push_back(to_json(s));
    j["strategies"] = st;
    j["reachable"] = {{"dfa_states", r.dfa_states}, {"relation", r.relation},
                      {"equals_local", r.equals_local}, {"shortest_unreachable", r.shortest_unreachable}};
    arr.push_back(std::move(j));
  }
  return arr.dump(2) + "\n";
}

}  // namespace pathex
