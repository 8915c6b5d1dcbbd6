#include "io/json_text.h"

#include <charconv>
#include <cmath>
#include <cstdint>

namespace pathex {
namespace {

bool plain(const std::string& s) {
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u > 0x7e || c == '"' || c == '\\') return false;
  }
  return true;
}

void put_string(const std::string& s, std::string& out) {
  if (plain(s)) {
    out += '"';
    out += s;
    out += '"';
  } else {
    out += nlohmann::ordered_json(s).dump();  // escapes, UTF-8 checked as dump(2) checks it
  }
}

template <typename Int>
void put_integer(Int v, std::string& out) {
  char buf[24];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

void put(const nlohmann::ordered_json& j, int indent, std::string& out) {
  using value_t = nlohmann::ordered_json::value_t;
  switch (j.type()) {
    case value_t::object:
    case value_t::array: {
      const bool object = j.is_object();
      if (j.empty()) {
        out += object ? "{}" : "[]";
        return;
      }
      out += object ? "{\n" : "[\n";
      bool first = true;
      for (auto it = j.cbegin(); it != j.cend(); ++it) {
        if (!first) out += ",\n";
        first = false;
        out.append(static_cast<std::size_t>(indent + 2), ' ');
        if (object) {
          put_string(it.key(), out);
          out += ": ";
        }
        put(it.value(), indent + 2, out);
      }
      out += '\n';
      out.append(static_cast<std::size_t>(indent), ' ');
      out += object ? '}' : ']';
      return;
    }
    case value_t::string:
      put_string(j.get_ref<const std::string&>(), out);
      return;
    case value_t::boolean:
      out += j.get<bool>() ? "true" : "false";
      return;
    case value_t::number_integer:
      put_integer(j.get<std::int64_t>(), out);
      return;
    case value_t::number_unsigned:
      put_integer(j.get<std::uint64_t>(), out);
      return;
    case value_t::number_float: {
      const double x = j.get<double>();
      if (!std::isfinite(x)) {
        out += "null";
        return;
      }
      char buf[64];
      char* end = nlohmann::detail::to_chars(buf, buf + sizeof buf, x);  // what dump() calls
      out.append(buf, static_cast<std::size_t>(end - buf));
      return;
    }
    case value_t::null:
      out += "null";
      return;
    default:  // binary and discarded values: nlohmann's own text, its lines shifted to this depth
      for (const char c : j.dump(2)) {
        out += c;
        if (c == '\n') out.append(static_cast<std::size_t>(indent), ' ');
      }
      return;
  }
}

}  // namespace

std::string json_text(const nlohmann::ordered_json& doc) {
  std::string out;
  put(doc, 0, out);
  out += '\n';
  return out;
}

}  // namespace pathex
