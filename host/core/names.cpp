#include "kiln/names.hpp"

#include "kiln/json_text.hpp"

#include <algorithm>
#include <cctype>

namespace kiln {

bool isValidName(std::string_view s) {
    if (s.empty() || s.size() > kMaxNameLength) return false;
    for (char c : s)
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
    return true;
}


int editDistance(std::string_view a, std::string_view b) {
    const size_t n = a.size(), m = b.size();
    auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
    // Three rows suffice for the optimal-string-alignment recurrence.
    std::vector<int> prev2(m + 1), prev(m + 1), cur(m + 1);
    for (size_t j = 0; j <= m; ++j) prev[j] = static_cast<int>(j);
    for (size_t i = 1; i <= n; ++i) {
        cur[0] = static_cast<int>(i);
        for (size_t j = 1; j <= m; ++j) {
            const int cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
            int d = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
                d = std::min(d, prev2[j - 2] + 1);
            cur[j] = d;
        }
        std::swap(prev2, prev);
        std::swap(prev, cur);
    }
    return prev[m];
}

std::string elide(std::string_view s, size_t max) { return json_text::elide(s, max); }

namespace {
// Names in suggestions: shown at most this long.
constexpr size_t kShownNameLength = 48;
// Longer than this, a name is no typo of anything (and the O(n·m) distance is skipped).
constexpr size_t kSuggestableLength = 256;

std::string shown(std::string_view s) { return elide(s, kShownNameLength); }
}  // namespace

std::string nearestName(std::string_view name, const std::vector<std::string>& candidates) {
    if (name.size() > kSuggestableLength) return {};
    const int limit = std::max<int>(1, static_cast<int>(name.size()) / 3);
    int best = limit + 1;
    const std::string* found = nullptr;
    for (const std::string& c : candidates) {
        // The distance is at least the difference in length.
        if (c == name || c.size() > name.size() + size_t(limit) || name.size() > c.size() + size_t(limit)) continue;
        const int d = editDistance(name, c);
        if (d < best) {
            best = d;
            found = &c;
        }
    }
    return found ? *found : std::string();
}

std::string suggestion(std::string_view name, const std::vector<std::string>& candidates, std::string_view what) {
    std::string near = nearestName(name, candidates);
    if (!near.empty()) return " (did you mean \"" + shown(near) + "\"?)";
    if (candidates.empty() || candidates.size() > 10) return {};
    std::string s = " (";
    s += what;
    s += ": ";
    for (size_t i = 0; i < candidates.size(); ++i) {
        if (i) s += ", ";
        s += shown(candidates[i]);
    }
    return s + ")";
}

}  // namespace kiln
