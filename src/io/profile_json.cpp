#include "io/profile_json.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "io/class_file.h"

namespace pathex {
namespace {

Error at(const std::string& filename, const std::string& pointer, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = filename + ":" + (pointer.empty() ? "/" : pointer);
  return e;
}

Result<Range> range_field(const nlohmann::json& v, const std::string& filename, const std::string& pointer) {
  if (v.is_number_integer()) {
    const long long n = v.get<long long>();
    if (n < 0 || n > 100000) return at(filename, pointer, "expected a non-negative count, found " + v.dump());
    return Range{static_cast<int>(n), static_cast<int>(n)};
  }
  if (v.is_string()) {
    Result<Range> r = parse_range(v.get<std::string>());
    if (!r) return at(filename, pointer, r.error().message);
    return r;
  }
  return at(filename, pointer, "expected a count like 2 or a range string like \"0..1\" or \"2..\", found " + v.dump());
}

}  // namespace

Result<Profile> parse_profile(const std::string& text, const std::string& filename, const Limits& limits) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& ex) {
    return at(filename, "", std::string("not valid JSON: ") + ex.what());
  }
  if (!doc.is_object()) return at(filename, "", "expected a JSON object describing a renderer profile");
  for (const auto& [key, value] : doc.items())
    if (key != "name" && key != "description" && key != "source" && key != "strategies" && key != "max_bounces" &&
        key != "$schema")
      return at(filename, "/" + key,
                "unknown key '" + key + "', expected one of name, description, source, strategies, max_bounces");
  Profile p;
  if (!doc.contains("name") || !doc["name"].is_string() || doc["name"].get<std::string>().empty())
    return at(filename, "/name", "expected a non-empty string name");
  p.name = doc["name"];
  if (doc.contains("description")) {
    if (!doc["description"].is_string()) return at(filename, "/description", "expected a string");
    p.description = doc["description"];
  }
  if (doc.contains("source")) {
    if (!doc["source"].is_string()) return at(filename, "/source", "expected a string");
    p.source = doc["source"];
  }
  if (doc.contains("max_bounces") && !doc["max_bounces"].is_null()) {
    const auto& m = doc["max_bounces"];
    if (!m.is_number_integer() || m.get<long long>() < 0 || m.get<long long>() > 100000)
      return at(filename, "/max_bounces", "expected a non-negative integer (or null for unbounded), found " + m.dump());
    p.max_bounces = m.get<int>();
  }
  if (!doc.contains("strategies") || !doc["strategies"].is_array() || doc["strategies"].empty())
    return at(filename, "/strategies", "expected a non-empty array of strategies");
  const auto& arr = doc["strategies"];
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const std::string ptr = "/strategies/" + std::to_string(i);
    const auto& js = arr[i];
    if (!js.is_object()) return at(filename, ptr, "expected an object with s, chain and t");
    for (const auto& [key, value] : js.items())
      if (key != "name" && key != "s" && key != "t" && key != "chain" && key != "connector")
        return at(filename, ptr + "/" + key, "unknown key '" + key + "', expected one of name, s, chain, t, connector");
    Strategy st;
    st.name = js.contains("name") && js["name"].is_string() ? js["name"].get<std::string>() : "strategy" + std::to_string(i);
    if (!js.contains("s")) return at(filename, ptr + "/s", "missing s (letters before the chain)");
    if (!js.contains("t")) return at(filename, ptr + "/t", "missing t (letters after the chain)");
    Result<Range> s = range_field(js["s"], filename, ptr + "/s");
    if (!s) return s.error();
    Result<Range> t = range_field(js["t"], filename, ptr + "/t");
    if (!t) return t.error();
    st.s = *s;
    st.t = *t;
    if (js.contains("chain")) {
      if (!js["chain"].is_string()) return at(filename, ptr + "/chain", "expected a chain expression string such as \"DD\"");
      st.chain = js["chain"];
    }
    if (js.contains("connector") && !js["connector"].is_null()) {
      if (!js["connector"].is_string()) return at(filename, ptr + "/connector", "expected a connector name");
      auto k = connector_from_string(js["connector"]);
      if (!k)
        return at(filename, ptr + "/connector",
                  "unknown connector '" + js["connector"].get<std::string>() +
                      "', expected mirror, distant-projection, ortho-projection or manifold");
      st.connector = *k;
    }
    Result<bool> ok = check_strategy(&st, limits, ptr);
    if (!ok) {
      Error e = ok.error();
      e.where = filename + ":" + e.where;
      return e;
    }
    p.strategies.push_back(std::move(st));
  }
  return p;
}

std::vector<Profile> builtin_profiles(const Limits& limits) {
  std::vector<Profile> out;
  for (const BuiltinProfileText& b : builtin_profile_texts()) {
    Result<Profile> p = parse_profile(b.json, std::string("builtin:") + b.name, limits);
    if (p) out.push_back(std::move(*p));  // tests check every built-in parses
  }
  return out;
}

Result<Profile> resolve_profile(const std::string& name_or_path, const Limits& limits) {
  for (const BuiltinProfileText& b : builtin_profile_texts())
    if (name_or_path == b.name) return parse_profile(b.json, std::string("builtin:") + b.name, limits);
  std::error_code ec;
  if (!std::filesystem::exists(name_or_path, ec)) {
    std::string names;
    for (const BuiltinProfileText& b : builtin_profile_texts()) names += std::string(names.empty() ? "" : ", ") + b.name;
    return make_error(ErrorCode::kBadValue,
                      "unknown renderer '" + name_or_path + "': not a built-in profile (" + names + ") nor a profile file");
  }
  std::string text;
  Result<bool> r = read_text_file(name_or_path, &text);
  if (!r) return r.error();
  return parse_profile(text, name_or_path, limits);
}

}  // namespace pathex
