// kiln/names.hpp — the one rule for pass ids and module names, and "did you mean ...?"
// for misspelt names.
//
// Suggestions are used for pass ids, module names, slots, outputs, parameters, enum choices and JSON
// keys. The distance is Damerau–Levenshtein in its optimal-string-alignment form
// (insert, delete, substitute, swap two neighbours: "sahdow" → "shadow" is 1).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace kiln {

// Pass ids and module names: [a-z0-9_], 1 to 64 characters (no path, "..", suffix).
inline constexpr std::size_t kMaxNameLength = 64;
inline constexpr const char* kNameRule = "[a-z0-9_]+ (at most 64 characters)";
bool isValidName(std::string_view s);

// User text quoted in a message, cut to `max` bytes: "abc…(+99994 bytes)". Keeps every
// message short whatever a file holds (a 1 MB id, a 60 000-character #include).
std::string elide(std::string_view s, size_t max = 80);


// Edit distance with adjacent transpositions, case-insensitive.
int editDistance(std::string_view a, std::string_view b);

// The candidate nearest to `name`, or "" when none is close enough to be a plausible
// typo (distance ≤ max(1, length/3)). Ties go to the earlier candidate.
std::string nearestName(std::string_view name, const std::vector<std::string>& candidates);

// ' (did you mean "x"?)' when there is a near name; otherwise, when the list is short,
// ' (<what>: a, b, c)' so the user sees the choices; otherwise "".
std::string suggestion(std::string_view name, const std::vector<std::string>& candidates,
                       std::string_view what = "available");

}  // namespace kiln
