#include "io/json_reader.h"

#include <cmath>
#include <sstream>
#include <vector>

namespace pathex {
namespace {

// "[json.exception.parse_error.101] parse error at …" -> "parse error at …"
std::string without_tag(const std::string& what) {
  const std::size_t tag = what.find("] ");
  if (what.rfind("[json.exception", 0) == 0 && tag != std::string::npos) return what.substr(tag + 2);
  return what;
}

// Builds the document from SAX events and keeps, for each open container, where the parser is in
// it: the key whose value comes next, or the index of the next element.
template <class Json>
class Builder {
 public:
  explicit Builder(std::string_view text) : text_(text) {}

  Json root;
  std::string error;  // set when parsing stops
  std::string error_pointer;

  bool null() { return value(Json(nullptr)); }
  bool boolean(bool b) { return value(Json(b)); }
  bool number_integer(typename Json::number_integer_t v) { return value(Json(v)); }
  bool number_unsigned(typename Json::number_unsigned_t v) { return value(Json(v)); }
  bool number_float(typename Json::number_float_t v, const typename Json::string_t&) { return value(Json(v)); }
  bool string(typename Json::string_t& s) { return value(Json(std::move(s))); }
  bool binary(typename Json::binary_t& b) { return value(Json(std::move(b))); }
  bool start_object(std::size_t) { return open(Json::object()); }
  bool start_array(std::size_t) { return open(Json::array()); }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool key(typename Json::string_t& k) {
    open_.back().key = k;
    open_.back().key_pending = true;
    return true;
  }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& ex) {
    error_pointer = pointer();
    std::string what = without_tag(ex.what());
    // nlohmann says where a syntax error is; for a number out of range it does not.
    if (what.find(" at line ") == std::string::npos) what += " at " + line_column(position);
    if (ex.id == 406) what += " (beyond the range of a double)";
    error = what;
    return false;
  }

 private:
  struct Open {
    Json* container;
    std::string key;
    bool key_pending = false;
  };

  std::string line_column(std::size_t position) const {
    std::size_t line = 1, column = 0;
    for (std::size_t i = 0; i < position && i < text_.size(); ++i) {
      if (text_[i] == '\n') { ++line; column = 0; }
      else ++column;
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
  }

  std::string pointer() const {
    std::string p;
    for (std::size_t k = 0; k < open_.size(); ++k) {
      const Open& o = open_[k];
      if (o.container->is_array()) {
        // An element still open is the array's last; otherwise the next one is being read.
        const std::size_t n = o.container->size();
        p += "/" + std::to_string(k + 1 < open_.size() ? n - 1 : n);
      } else if (o.key_pending) {
        p += "/" + pointer_token(o.key);
      } else {
        break;  // between an object's members: the object itself
      }
    }
    return p;
  }

  // Places a value where the parser is; returns it.
  Json* place(Json&& v) {
    if (open_.empty()) {
      root = std::move(v);
      return &root;
    }
    Open& o = open_.back();
    if (o.container->is_array()) {
      o.container->push_back(std::move(v));
      return &o.container->back();
    }
    return &((*o.container)[o.key] = std::move(v));
  }
  // An object's key stays pending until its value is complete: a scalar at once, a container
  // when it closes (so an error inside it still names the key).
  void done() {
    if (!open_.empty()) open_.back().key_pending = false;
  }
  bool value(Json&& v) {
    place(std::move(v));
    done();
    return true;
  }
  bool open(Json&& empty) {
    if (open_.size() >= kMaxJsonDepth) {
      error_pointer = pointer();
      error = "nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels";
      return false;
    }
    open_.push_back({place(std::move(empty)), "", false});
    return true;
  }
  bool close() {
    open_.pop_back();
    done();
    return true;
  }

  std::string_view text_;
  std::vector<Open> open_;
};

template <class Json>
Result<Json> parse_as(std::string_view text, const std::string& file) {
  Builder<Json> b(text);
  bool ok = false;
  try {
    ok = Json::sax_parse(text.begin(), text.end(), &b, nlohmann::json::input_format_t::json, /*strict=*/true);
  } catch (const nlohmann::json::exception& ex) {  // the SAX interface reports errors; this is a safety net
    b.error = without_tag(ex.what());
  }
  if (!ok || !b.error.empty()) {
    Error e = make_error(ErrorCode::kBadFile, "not valid JSON: " + (b.error.empty() ? std::string("unreadable") : b.error));
    e.where = file + ":" + (b.error_pointer.empty() ? "/" : b.error_pointer);
    return e;
  }
  return std::move(b.root);
}

}  // namespace

Result<nlohmann::json> parse_json(std::string_view text, const std::string& file) {
  return parse_as<nlohmann::json>(text, file);
}
Result<nlohmann::ordered_json> parse_ordered_json(std::string_view text, const std::string& file) {
  return parse_as<nlohmann::ordered_json>(text, file);
}

std::string pointer_token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

Error JsonReader::fail(const std::string& pointer, std::string message) const {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = file_ + ":" + (pointer.empty() ? "/" : pointer);
  return e;
}

Result<bool> JsonReader::keys(const json& j, const std::string& ptr, std::initializer_list<const char*> allowed) const {
  if (!j.is_object()) return fail(ptr, "expected an object, found " + kind(j));
  for (const auto& [key, value] : j.items()) {
    bool ok = key == "$schema" || key == "description";
    for (const char* a : allowed) ok = ok || key == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      return fail(ptr + "/" + pointer_token(key), "unknown key '" + key + "', expected one of " + list);
    }
  }
  return true;
}

std::string JsonReader::kind(const json& j) {
  if (j.is_null()) return "null";
  if (j.is_boolean()) return "a boolean";
  if (j.is_number()) return "a number";
  if (j.is_string()) return "a string";
  if (j.is_array()) return "an array";
  return "an object";
}

std::string JsonReader::fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

Result<double> JsonReader::number(const json& j, const std::string& key, const std::string& ptr, double lo, double hi,
                                  std::optional<double> fallback) const {
  const std::string p = ptr + "/" + pointer_token(key);
  if (!j.is_object() || !j.contains(key)) {
    if (fallback) return *fallback;
    return fail(p, "missing " + key + ", expected a number");
  }
  const json& v = j.at(key);
  if (!v.is_number()) return fail(p, "expected a number, found " + kind(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) return fail(p, "expected a finite number");
  if (x < lo || x > hi) return fail(p, "expected a number in [" + fmt(lo) + ", " + fmt(hi) + "], found " + fmt(x));
  return x;
}

Result<long long> JsonReader::integer(const json& j, const std::string& key, const std::string& ptr, long long lo,
                                      long long hi, std::optional<long long> fallback) const {
  const std::string p = ptr + "/" + pointer_token(key);
  if (!j.is_object() || !j.contains(key)) {
    if (fallback) return *fallback;
    return fail(p, "missing " + key + ", expected an integer");
  }
  const json& v = j.at(key);
  // An unsigned beyond long long is out of range, not a wrapped negative number.
  if (v.is_number_unsigned() && v.get<unsigned long long>() > static_cast<unsigned long long>(hi))
    return fail(p, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " + v.dump());
  if (!v.is_number_integer()) return fail(p, "expected an integer, found " + v.dump());
  const long long x = v.get<long long>();
  if (x < lo || x > hi)
    return fail(p, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " + std::to_string(x));
  return x;
}

Result<std::uint64_t> JsonReader::unsigned_integer(const json& j, const std::string& key, const std::string& ptr,
                                                   std::uint64_t hi) const {
  const std::string p = ptr + "/" + pointer_token(key);
  if (!j.is_object() || !j.contains(key)) return fail(p, "missing " + key + ", expected an integer");
  const json& v = j.at(key);
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<long long>() >= 0))
    return fail(p, "expected an integer in [0, " + std::to_string(hi) + "], found " + v.dump());
  const std::uint64_t x = v.get<std::uint64_t>();
  if (x > hi) return fail(p, "expected an integer in [0, " + std::to_string(hi) + "], found " + std::to_string(x));
  return x;
}

Result<bool> JsonReader::boolean(const json& j, const std::string& key, const std::string& ptr) const {
  const std::string p = ptr + "/" + pointer_token(key);
  if (!j.is_object() || !j.contains(key)) return fail(p, "missing " + key + ", expected true or false");
  if (!j.at(key).is_boolean()) return fail(p, "expected true or false, found " + kind(j.at(key)));
  return j.at(key).get<bool>();
}

Result<std::string> JsonReader::string(const json& j, const std::string& key, const std::string& ptr) const {
  const std::string p = ptr + "/" + pointer_token(key);
  if (!j.is_object() || !j.contains(key)) return fail(p, "missing " + key + ", expected a string");
  if (!j.at(key).is_string()) return fail(p, "expected a string, found " + kind(j.at(key)));
  return j.at(key).get<std::string>();
}

}  // namespace pathex
