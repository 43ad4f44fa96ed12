// kiln/json_text.hpp — what the JSON loaders (pipeline files in host/graph, scene files
// in sim/) need from the raw text before and beside nlohmann's parser: where a byte is
// (line and column, for messages) and whether the nesting stays bounded. Header-only and
// GL-free, so the simulation library can use it without depending on the host.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string_view>

namespace kiln::json_text {

// 1-based line and column of byte `offset` (clamped to the text).
inline void lineColumn(std::string_view text, size_t offset, int& line, int& column) {
    line = 1, column = 1;
    const size_t end = std::min(offset, text.size());
    for (size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') ++line, column = 1;
        else ++column;
    }
}

// The offset of the first bracket that opens nesting level maxDepth + 1 (strings and
// their escapes skipped), or npos when the text stays within the bound. Run before
// parsing: nothing ever holds (copies, dumps, destroys) a deeper value.
inline size_t firstTooDeep(std::string_view text, int maxDepth) {
    int depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > maxDepth) return i;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return std::string_view::npos;
}

}  // namespace kiln::json_text
