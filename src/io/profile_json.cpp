#include "io/profile_json.h"

#include <filesystem>

#include "io/input_file.h"
#include "io/json_reader.h"

namespace pathex {
namespace {

Error at(const std::string& filename, const std::string& pointer, std::string message) {
  return JsonReader(filename).fail(pointer, std::move(message));
}

Result<Range> range_field(const nlohmann::json& v, const std::string& filename, const std::string& pointer) {
  if (v.is_number_integer()) {
    const long long n = v.get<long long>();
    if (n < 0 || n > kMaxBouncesCeiling + 4)
      return at(filename, pointer, "expected a count in [0, " + std::to_string(kMaxBouncesCeiling + 4) + "], found " + v.dump());
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
  Result<nlohmann::json> parsed = parse_json(text, filename);
  if (!parsed) return parsed.error();
  const nlohmann::json& doc = *parsed;
  if (!doc.is_object()) return at(filename, "", "expected a JSON object describing a renderer profile");
  for (const auto& [key, value] : doc.items())
    if (key != "name" && key != "description" && key != "source" && key != "strategies" && key != "max_bounces" &&
        key != "$schema")
      return at(filename, "/" + pointer_token(key),
                "unknown key '" + key + "', expected one of name, description, source, strategies, max_bounces");
  Profile p;
  if (!doc.contains("name") || !doc.at("name").is_string() || doc.at("name").get<std::string>().empty())
    return at(filename, "/name", "expected a non-empty string name");
  p.name = doc.at("name").get<std::string>();
  if (doc.contains("description")) {
    if (!doc.at("description").is_string()) return at(filename, "/description", "expected a string");
    p.description = doc.at("description").get<std::string>();
  }
  if (doc.contains("source")) {
    if (!doc.at("source").is_string()) return at(filename, "/source", "expected a string");
    p.source = doc.at("source").get<std::string>();
  }
  if (doc.contains("max_bounces") && !doc.at("max_bounces").is_null()) {
    const auto& m = doc.at("max_bounces");
    if (!m.is_number_integer() || m.get<long long>() < 0 || m.get<long long>() > kMaxBouncesCeiling)
      return at(filename, "/max_bounces",
                "expected a non-negative integer up to " + std::to_string(kMaxBouncesCeiling) +
                    " (or null for unbounded), found " + m.dump());
    p.max_bounces = static_cast<int>(m.get<long long>());
  }
  if (!doc.contains("strategies") || !doc.at("strategies").is_array() || doc.at("strategies").empty())
    return at(filename, "/strategies", "expected a non-empty array of strategies");
  const auto& arr = doc.at("strategies");
  for (std::size_t i = 0; i < arr.size(); ++i) {
    const std::string ptr = "/strategies/" + std::to_string(i);
    const auto& js = arr[i];
    if (!js.is_object()) return at(filename, ptr, "expected an object with s, chain and t");
    for (const auto& [key, value] : js.items())
      if (key != "name" && key != "s" && key != "t" && key != "chain" && key != "connector")
        return at(filename, ptr + "/" + pointer_token(key), "unknown key '" + key + "', expected one of name, s, chain, t, connector");
    Strategy st;
    st.name = js.contains("name") && js.at("name").is_string() ? js.at("name").get<std::string>() : "strategy" + std::to_string(i);
    if (!js.contains("s")) return at(filename, ptr + "/s", "missing s (letters before the chain)");
    if (!js.contains("t")) return at(filename, ptr + "/t", "missing t (letters after the chain)");
    Result<Range> s = range_field(js.at("s"), filename, ptr + "/s");
    if (!s) return s.error();
    Result<Range> t = range_field(js.at("t"), filename, ptr + "/t");
    if (!t) return t.error();
    st.s = *s;
    st.t = *t;
    if (js.contains("chain")) {
      if (!js.at("chain").is_string()) return at(filename, ptr + "/chain", "expected a chain expression string such as \"DD\"");
      st.chain = js.at("chain").get<std::string>();
    }
    if (js.contains("connector") && !js.at("connector").is_null()) {
      if (!js.at("connector").is_string()) return at(filename, ptr + "/connector", "expected a connector name");
      const std::string name = js.at("connector").get<std::string>();
      auto k = connector_from_string(name);
      if (!k)
        return at(filename, ptr + "/connector",
                  "unknown connector '" + name +
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

Result<std::vector<Profile>> builtin_profiles(const Limits& limits) {
  std::vector<Profile> out;
  for (const BuiltinProfileText& b : builtin_profile_texts()) {
    Result<Profile> p = parse_profile(b.json, std::string("builtin:") + b.name, limits);
    if (!p) return p.error();  // possible under very small limits
    out.push_back(std::move(*p));
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
  Result<std::string> text = read_input_file(name_or_path, limits.max_file_bytes);
  if (!text) return text.error();
  return parse_profile(*text, name_or_path, limits);
}

}  // namespace pathex
