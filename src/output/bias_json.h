// bias.json (keys in README "pathex bias"): what `pathex bias` writes, what the check file's
// `missed` requirement reports and `trace --missed` shares.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "bias/bias.h"

namespace pathex {

nlohmann::ordered_json to_json(const BiasReport& r);
// bias.json's text: to_json(r), indented by 2, with a final newline.
std::string bias_json_text(const BiasReport& r);

}  // namespace pathex
