// Renderer profiles as JSON (schema: grammar/profile.schema.json), and the built-in profiles,
// which are the files of samples/renderers embedded in the binary at build time.
#pragma once

#include <string>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "reach/profile.h"

namespace pathex {

struct BuiltinProfileText {
  const char* name;
  const char* json;
};
const std::vector<BuiltinProfileText>& builtin_profile_texts();

// Parses and validates a profile. Errors carry `where` = "filename:/json/pointer".
Result<Profile> parse_profile(const std::string& text, const std::string& filename, const Limits& limits);
// A built-in name (pt, pt-nee, lt, bdpt, …) or a path to a profile file.
Result<Profile> resolve_profile(const std::string& name_or_path, const Limits& limits);
// Every built-in profile, parsed under `limits`.
Result<std::vector<Profile>> builtin_profiles(const Limits& limits);

}  // namespace pathex
