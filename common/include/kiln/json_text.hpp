// kiln/json_text.hpp — what the JSON loaders (pipeline files in host/graph, scene files
// in sim/) need from the raw text before and beside nlohmann's parser: where a byte is
// (line and column, for messages), whether the nesting stays bounded, the text itself
// read with a bound, and how much of a value a message quotes. Header-only and GL-free, so the simulation library can use it
// without depending on the host.
#pragma once

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace kiln::json_text {

// User text quoted in a message, cut to `max` bytes: "abc…(+99994 bytes)". Keeps every
// message short whatever a file holds (a 10 MB array as a radius, a 1 MB id).
inline std::string elide(std::string_view s, size_t max) {
    if (s.size() <= max) return std::string(s);
    return std::string(s.substr(0, max)) + "…(+" + std::to_string(s.size() - max) + " bytes)";
}

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

// Reads the file at `path` into `text`, at most `maxBytes` of it: a directory, a device or
// a pipe (/dev/zero, which never ends) is refused by what it is, and a file that holds
// more than the bound by its size, without reading past it. On failure `error` says why,
// calling the file `what` ("scene file"), without its path: the caller names the file.
inline bool readBoundedFile(const std::filesystem::path& path, size_t maxBytes, const std::string& what,
                            std::string& text, std::string& error) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!ec && std::filesystem::is_directory(status)) return error = "is a directory, not a " + what, false;
    if (!ec && !std::filesystem::is_regular_file(status))
        return error = "is not a regular file (a device, a pipe or a socket), not a " + what, false;
    std::ifstream in(path, std::ios::binary);
    if (ec || !in) return error = "cannot read the " + what, false;
    text.assign(maxBytes + 1, '\0');
    in.read(text.data(), std::streamsize(text.size()));
    text.resize(size_t(in.gcount()));
    if (text.size() > maxBytes)
        return error = "the " + what + " holds more than " + std::to_string(maxBytes) + " bytes, the limit", false;
    return true;
}

}  // namespace kiln::json_text
