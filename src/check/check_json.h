// `pathex check --json`: the outcome of every requirement of a check file as one JSON document
// (the file, the counts passed and failed, and per requirement its case, renderer, scene, bound,
// verdict, counterexample with its chains, and a missed-light requirement's measurement).
#pragma once

#include <string>
#include <vector>

#include "check/check_file.h"

namespace pathex {

// The report of `outcomes` (decide_check's, for `file`), indented by two, without a final newline.
std::string check_json(const std::string& file, const std::vector<Outcome>& outcomes);

}  // namespace pathex
