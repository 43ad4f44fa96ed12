// kiln/hash.hpp — FNV-1a, the host's content hash (plan signatures, file contents for
// the watcher), and hashWords, its word-wise cousin for the scene's instances each
// frame. Not cryptographic: they tell "changed" from "unchanged", nothing more.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace kiln {

inline constexpr uint64_t kFnvOffsetBasis = 1469598103934665603ull;

// Continues `h` over `n` bytes, so a hash can be built from several pieces.
inline uint64_t fnv1a(const void* data, std::size_t n, uint64_t h = kFnvOffsetBasis) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
    return h;
}
inline uint64_t fnv1a(std::string_view s, uint64_t h = kFnvOffsetBasis) { return fnv1a(s.data(), s.size(), h); }

// For large arrays hashed every frame (thousands of instances, where bytewise fnv1a costs
// a visible share of the frame): 8-byte words, each XORed in, multiplied by an odd
// constant and its high half folded down (without the fold a difference in a word's top
// bits never reaches the low ones, and two such differences cancel); the tail bytewise.
// Every step is a bijection of the hash for a given word. Its values differ from fnv1a's.
inline uint64_t hashWords(const void* data, std::size_t n, uint64_t h = kFnvOffsetBasis) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t word;
        std::memcpy(&word, bytes + i, 8);
        h = (h ^ word) * 0x9E3779B97F4A7C15ull;
        h ^= h >> 32;
    }
    return fnv1a(bytes + i, n - i, h);
}

}  // namespace kiln
