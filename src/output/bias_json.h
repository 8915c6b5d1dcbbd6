// bias.json (keys in README "pathex bias"): what `pathex bias` writes, what the check file's
// `missed` requirement reports and `trace --missed` shares.
#pragma once

#include <nlohmann/json.hpp>

#include "bias/bias.h"

namespace pathex {

nlohmann::ordered_json to_json(const BiasReport& r);

}  // namespace pathex
