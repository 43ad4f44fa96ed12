// kiln/hash.hpp — FNV-1a, the host's one content hash (plan signatures, scene
// content versions, file contents for the watcher). Not cryptographic: it tells
// "changed" from "unchanged", nothing more.
#pragma once

#include <cstddef>
#include <cstdint>
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

}  // namespace kiln
