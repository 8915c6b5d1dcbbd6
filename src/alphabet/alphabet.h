// The alphabet of full-path strings (DESIGN §1) and what hangs off it: the four letters, the light
// and sensor types with the letter pairs they contribute, validation of full-path strings, and
// their decomposition into chains (DESIGN §3).
//
// Letters are numbered in ASCII order (D < E < L < S). That order is the automaton's column order
// and the tie-break of every "shortest, then lexicographic" answer, so witnesses are stable.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace pathex {

enum Letter : std::uint8_t { kD = 0, kE = 1, kL = 2, kS = 3 };
inline constexpr int kNumLetters = 4;
inline constexpr std::array<char, kNumLetters> kLetterChar = {'D', 'E', 'L', 'S'};
using LetterMask = std::uint8_t;  // bit i set = letter i allowed
inline constexpr LetterMask kAllLetters = 0xF;
inline constexpr LetterMask kScatterMask = (1u << kS) | (1u << kD);

inline constexpr char letter_char(int l) { return kLetterChar[l]; }
// The letter for an uppercase character, or nullopt.
std::optional<Letter> letter_from_char(char c);

enum class LightType { kArea, kDistant, kPoint, kLaser };
enum class SensorType { kLens, kPinhole, kOrthographic, kSpotmeter };
inline constexpr std::array<LightType, 4> kAllLightTypes = {LightType::kArea, LightType::kDistant,
                                                            LightType::kPoint, LightType::kLaser};
inline constexpr std::array<SensorType, 4> kAllSensorTypes = {
    SensorType::kLens, SensorType::kPinhole, SensorType::kOrthographic, SensorType::kSpotmeter};

// c0 c1 for a light: area "DD", distant "DS", point "SD", laser "SS".
std::string light_letters(LightType t);
// c(k+1) c(k+2) for a sensor: lens "DD", pinhole "DS", orthographic "SD", spot meter "SS".
std::string sensor_letters(SensorType t);
std::string to_string(LightType t);   // "area", "distant", "point", "laser"
std::string to_string(SensorType t);  // "lens", "pinhole", "orthographic", "spotmeter"
std::optional<LightType> light_type_from_string(std::string_view s);
std::optional<SensorType> sensor_type_from_string(std::string_view s);
// The light type whose letters are `two` ("SD" -> point), if any.
std::optional<LightType> light_type_from_letters(std::string_view two);
std::optional<SensorType> sensor_type_from_letters(std::string_view two);

// A validated full-path string L c0 … c(k+2) E, k ≥ 1.
struct FullPath {
  std::string text;
  int k() const { return static_cast<int>(text.size()) - 5; }  // number of edges
  char c(int i) const { return text[static_cast<std::size_t>(i) + 1]; }  // scattering letter c_i
};

// The character at byte `pos` of `text` as messages show it: 'x'; a whole UTF-8 sequence such as
// 'é' or 'Ψ' rather than its first byte; "byte 0xC3" for a control byte or a byte that does not
// start a valid sequence. Messages built from it are valid UTF-8 whatever the input.
std::string describe_char_at(std::string_view text, std::size_t pos);

// Checks shape and letters; errors carry the 1-based column of the first offending character.
Result<FullPath> parse_full_path(std::string_view s, std::size_t max_length);

// One chain: the letters from one separator to the next, both included (DESIGN §3). `from` and
// `to` index the scattering letters c_i.
struct Chain {
  std::string letters;
  int from = 0;
  int to = 0;
};
// Separators are c0, c(k+2) and every D; `LDSDDSSDSE` -> DSD(0..2) DD(2..3) DSSD(3..6) DS(6..7).
std::vector<Chain> chains(const FullPath& p);

}  // namespace pathex
