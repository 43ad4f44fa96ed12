// graph/suggest.hpp — "did you mean ...?" for misspelt names.
//
// Used for pass ids, module names, slots, outputs, parameters, enum choices and JSON
// keys. The distance is Damerau–Levenshtein in its optimal-string-alignment form
// (insert, delete, substitute, swap two neighbours: "sahdow" → "shadow" is 1).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace kiln::graph {

// Edit distance with adjacent transpositions, case-insensitive.
int editDistance(std::string_view a, std::string_view b);

// The candidate nearest to `name`, or "" when none is close enough to be a plausible
// typo (distance ≤ max(1, length/3)). Ties go to the earlier candidate.
std::string nearestName(std::string_view name, const std::vector<std::string>& candidates);

// ' (did you mean "x"?)' when there is a near name; otherwise, when the list is short,
// ' (<what>: a, b, c)' so the user sees the choices; otherwise "".
std::string suggestion(std::string_view name, const std::vector<std::string>& candidates,
                       std::string_view what = "available");

}  // namespace kiln::graph
