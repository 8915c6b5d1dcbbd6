#include "io/class_json.h"

#include <nlohmann/json.hpp>

#include "alphabet/alphabet.h"
#include "io/reach_json.h"

namespace pathex {
namespace {

nlohmann::json chains_json(const std::string& path) {
  nlohmann::json arr = nlohmann::json::array();
  Result<FullPath> p = parse_full_path(path, path.size());
  if (!p) return arr;
  for (const Chain& c : chains(*p)) arr.push_back({{"letters", c.letters}, {"from", c.from}, {"to", c.to}});
  return arr;
}

// One line of text: a path read from stdin need not be UTF-8 (a stray byte is reported as bad, not
// a crash), so bytes that are not are written as U+FFFD.
std::string line_text(const nlohmann::json& j) {
  return j.dump(-1, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::string explain_json_text(const ClassFacts& f) {
  nlohmann::json j;
  j["expression"] = f.expression;
  j["normal_form"] = f.normal_form;
  j["notation"] = f.notation;
  j["eye_first"] = f.eye_first;
  j["dfa_states"] = f.dfa_states;
  j["live_states"] = f.live_states;
  j["empty"] = f.empty;
  j["finite"] = f.finite;
  nlohmann::json counts = nlohmann::json::array();
  for (std::size_t n = 0; n < f.counts.size(); ++n)
    if (!f.counts[n].is_zero()) counts.push_back({{"length", n}, {"count", count_json(f.counts[n])}});
  j["counts_by_length"] = counts;
  j["max_len"] = f.max_len;
  nlohmann::json members = nlohmann::json::array();
  for (const std::string& m : f.shortest_members) members.push_back({{"path", m}, {"chains", chains_json(m)}});
  j["shortest_members"] = members;
  return j.dump(2) + "\n";
}

std::string lpe_json_text(const std::string& expression, const std::string& notation, const LpeEmission& e) {
  nlohmann::json j;
  j["expression"] = expression;
  j["notation"] = notation;
  if (e.empty) {
    j["lpe"] = nullptr;
  } else {
    j["lpe"] = e.lpe;
    j["exact"] = e.exact;
    j["losses"] = e.losses;
    j["example"] = e.example ? nlohmann::json(*e.example) : nlohmann::json(nullptr);
  }
  return j.dump(2) + "\n";
}

std::string classify_json_line(std::size_t line, const std::string& path, const std::vector<std::string>& classes) {
  return line_text({{"line", line}, {"path", path}, {"classes", classes}});
}

std::string classify_error_json_line(std::size_t line, const std::string& path, const std::string& error) {
  return line_text({{"line", line}, {"path", path}, {"error", error}});
}

}  // namespace pathex
