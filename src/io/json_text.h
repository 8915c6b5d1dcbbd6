// A JSON document as the text of nlohmann's dump(2) followed by a newline, byte for byte, in a
// fifth of the instructions.
//
// nlohmann's serializer passes every character of every string through a UTF-8 decoder and every
// character of the output through an adapter; histogram.json (a megabyte at 256 x 256, mostly
// keys, path strings and technique names) spent ~100 instructions a byte there, more than
// building the document. Here strings of printable ASCII without '"' or '\\' (all keys, paths
// and technique names) are copied as they are, numbers are formatted by the same routines
// (std::to_chars for integers, nlohmann's own shortest round-trip formatter for floats, null for
// non-finite ones), and anything else (escapes, UTF-8, binary values) is handed to nlohmann, so
// its errors (invalid UTF-8) are raised as before. Tested against dump(2) on the written reports
// and on documents built to reach every branch (tests/io/histogram_json_test.cpp).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace pathex {

// doc.dump(2) + "\n".
std::string json_text(const nlohmann::ordered_json& doc);

}  // namespace pathex
