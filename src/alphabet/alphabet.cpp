#include "alphabet/alphabet.h"

#include <cstdio>

namespace pathex {

std::optional<Letter> letter_from_char(char c) {
  switch (c) {
    case 'D': return kD;
    case 'E': return kE;
    case 'L': return kL;
    case 'S': return kS;
    default: return std::nullopt;
  }
}

std::string light_letters(LightType t) {
  switch (t) {
    case LightType::kArea: return "DD";
    case LightType::kDistant: return "DS";
    case LightType::kPoint: return "SD";
    case LightType::kLaser: return "SS";
  }
  return "";
}

std::string sensor_letters(SensorType t) {
  switch (t) {
    case SensorType::kLens: return "DD";
    case SensorType::kPinhole: return "DS";
    case SensorType::kOrthographic: return "SD";
    case SensorType::kSpotmeter: return "SS";
  }
  return "";
}

std::string to_string(LightType t) {
  switch (t) {
    case LightType::kArea: return "area";
    case LightType::kDistant: return "distant";
    case LightType::kPoint: return "point";
    case LightType::kLaser: return "laser";
  }
  return "";
}

std::string to_string(SensorType t) {
  switch (t) {
    case SensorType::kLens: return "lens";
    case SensorType::kPinhole: return "pinhole";
    case SensorType::kOrthographic: return "orthographic";
    case SensorType::kSpotmeter: return "spotmeter";
  }
  return "";
}

std::optional<LightType> light_type_from_string(std::string_view s) {
  for (LightType t : kAllLightTypes)
    if (to_string(t) == s) return t;
  return std::nullopt;
}

std::optional<SensorType> sensor_type_from_string(std::string_view s) {
  for (SensorType t : kAllSensorTypes)
    if (to_string(t) == s) return t;
  return std::nullopt;
}

std::optional<LightType> light_type_from_letters(std::string_view two) {
  for (LightType t : kAllLightTypes)
    if (light_letters(t) == two) return t;
  return std::nullopt;
}

std::optional<SensorType> sensor_type_from_letters(std::string_view two) {
  for (SensorType t : kAllSensorTypes)
    if (sensor_letters(t) == two) return t;
  return std::nullopt;
}

std::string describe_char_at(std::string_view text, std::size_t pos) {
  const auto c = static_cast<unsigned char>(text[pos]);
  // The length of a well-formed UTF-8 sequence starting here (RFC 3629), or 0.
  std::size_t n = c < 0x80 ? 1 : (c >= 0xC2 && c <= 0xDF) ? 2 : (c >= 0xE0 && c <= 0xEF) ? 3 : (c >= 0xF0 && c <= 0xF4) ? 4 : 0;
  for (std::size_t i = 1; i < n; ++i)
    if (pos + i >= text.size() || (static_cast<unsigned char>(text[pos + i]) & 0xC0) != 0x80) n = 0;
  if (n == 0 || c < 0x20 || c == 0x7F) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "byte 0x%02X", static_cast<unsigned>(c));
    return buf;
  }
  return "'" + std::string(text.substr(pos, n)) + "'";
}

Result<FullPath> parse_full_path(std::string_view s, std::size_t max_length) {
  Error e;
  e.code = ErrorCode::kBadPath;
  e.source = std::string(s);
  if (s.size() > max_length) {
    e.code = ErrorCode::kLimit;
    e.message = "path of " + std::to_string(s.size()) + " letters exceeds the limit of " +
                std::to_string(max_length) + " (raise it with --max-length)";
    e.source.clear();
    return e;
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!letter_from_char(s[i])) {
      e.column = static_cast<int>(i) + 1;
      const std::string found = describe_char_at(s, i);
      e.message = "unexpected " + (found[0] == '\'' ? "character " + found : found) + ", expected one of L E S D";
      return e;
    }
  }
  if (s.empty() || s[0] != 'L') {
    e.column = 1;
    e.message = "a full path starts with L";
    return e;
  }
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i] == 'L') {
      e.column = static_cast<int>(i) + 1;
      e.message = "L may appear only at the start";
      return e;
    }
    if (s[i] == 'E' && i + 1 != s.size()) {
      e.column = static_cast<int>(i) + 1;
      e.message = "E may appear only at the end";
      return e;
    }
  }
  if (s.back() != 'E') {
    e.column = static_cast<int>(s.size()) + 1;
    e.message = "a full path ends with E";
    return e;
  }
  if (s.size() < 6) {
    e.column = static_cast<int>(s.size());
    e.message = "a full path has at least four scattering letters (L c0 c1 c2 c3 E, k >= 1)";
    return e;
  }
  return FullPath{std::string(s)};
}

std::vector<Chain> chains(const FullPath& p) {
  std::vector<Chain> out;
  const int last = p.k() + 2;  // index of c(k+2)
  int prev = 0;
  for (int i = 1; i <= last; ++i) {
    if (i == last || p.c(i) == 'D') {
      out.push_back(Chain{p.text.substr(static_cast<std::size_t>(prev) + 1,
                                        static_cast<std::size_t>(i - prev) + 1),
                          prev, i});
      prev = i;
    }
  }
  return out;
}

}  // namespace pathex
