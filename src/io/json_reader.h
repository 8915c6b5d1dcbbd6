// The one JSON reader. Every JSON input of pathex (scenes, class files, renderer profiles, check
// files, histograms) is parsed by parse_json() and read through JsonReader, so that no input can
// reach nlohmann's exceptions:
//   - parse_json() runs nlohmann's SAX parser with a handler that builds the document and keeps
//     the JSON pointer of the value being read, so a syntax error, a number beyond a double
//     (`1e400`, nlohmann's out_of_range.406) or nesting deeper than kMaxJsonDepth becomes one
//     Error at "file:/pointer" with the line and column;
//   - JsonReader's accessors check the kind and range of a value before converting it and name
//     its pointer when it is wrong, so the walk over a document never throws either.
// Messages say what was found and what was expected; unknown keys are errors, so a typo never
// silently does nothing.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace pathex {

// Deeper documents are refused (nlohmann's own reading is iterative, but the walks over a
// document are not): no pathex format nests more than six levels.
inline constexpr std::size_t kMaxJsonDepth = 64;

// Parses `text`; errors name `file` and the pointer of the value being read.
Result<nlohmann::json> parse_json(std::string_view text, const std::string& file);
Result<nlohmann::ordered_json> parse_ordered_json(std::string_view text, const std::string& file);

// One reference token of a JSON pointer (RFC 6901): '~' is written "~0" and '/' is "~1".
std::string pointer_token(std::string_view key);

class JsonReader {
 public:
  using json = nlohmann::json;
  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }
  // A kBadFile error at "file:pointer" ("file:/" for the root).
  Error fail(const std::string& pointer, std::string message) const;

  // The keys of `j` must be among `allowed` (plus "$schema" and "description").
  Result<bool> keys(const json& j, const std::string& ptr, std::initializer_list<const char*> allowed) const;

  // "null", "a boolean", "a number", "a string", "an array", "an object".
  static std::string kind(const json& j);
  // A number for messages, as the shortest text that reads back the same.
  static std::string fmt(double x);

  // j[key] as a finite number in [lo, hi]; `fallback` when the key is absent (else an error).
  Result<double> number(const json& j, const std::string& key, const std::string& ptr, double lo, double hi,
                        std::optional<double> fallback = std::nullopt) const;
  // j[key] as an integer in [lo, hi]; `fallback` when the key is absent (else an error).
  Result<long long> integer(const json& j, const std::string& key, const std::string& ptr, long long lo, long long hi,
                            std::optional<long long> fallback = std::nullopt) const;
  // j[key] as an integer in [0, hi], up to 2^64 - 1 (seeds, counts); required.
  Result<std::uint64_t> unsigned_integer(const json& j, const std::string& key, const std::string& ptr,
                                         std::uint64_t hi) const;
  // j[key] as a string (required).
  Result<std::string> string(const json& j, const std::string& key, const std::string& ptr) const;
  // j[key] as true or false (required).
  Result<bool> boolean(const json& j, const std::string& key, const std::string& ptr) const;

 private:
  std::string file_;
};

}  // namespace pathex
