// kiln/hash.hpp: the content hashes the host tells "changed" from "unchanged" by.
#include <catch2/catch.hpp>

#include <kiln/hash.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <set>

TEST_CASE("hash: hashWords tells every single-bit change of an array from the others and from none", "[hash]") {
    // 8-byte words and a tail of 5 bytes: every byte flipped in turn, each bit of it,
    // gives a hash unlike the original's and unlike every other flip's (a step that
    // lost a word's bits, or a tail left out, would repeat one; word-wise FNV-1a, with
    // no fold of the high half, repeats 41: a top bit's difference stays the top bit).
    std::array<unsigned char, 8 * 12 + 5> data{};
    for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i * 37 + 11);
    const uint64_t original = kiln::hashWords(data.data(), data.size());
    CHECK(kiln::hashWords(data.data(), data.size()) == original);
    std::set<uint64_t> seen{original};
    for (size_t i = 0; i < data.size(); ++i)
        for (int bit = 0; bit < 8; ++bit) {
            auto flipped = data;
            flipped[i] ^= static_cast<unsigned char>(1u << bit);
            INFO("byte " << i << ", bit " << bit);
            CHECK(seen.insert(kiln::hashWords(flipped.data(), flipped.size())).second);
        }
    // Two words' top bits flipped together do not cancel (they did without the fold).
    auto both = data;
    both[15] ^= 0x80u, both[23] ^= 0x80u;
    CHECK(kiln::hashWords(both.data(), both.size()) != original);
    // The length takes part: a shorter prefix hashes otherwise.
    CHECK(kiln::hashWords(data.data(), data.size() - 1) != original);
    // It continues from a given hash, as fnv1a does.
    CHECK(kiln::hashWords(data.data(), data.size(), 7) != original);
}
