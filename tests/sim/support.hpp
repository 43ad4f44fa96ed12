// What the simulation tests share: how much shorter the long runs are in the sanitized
// build, and the shipped scene.
#pragma once

#include <catch2/catch.hpp>

#include <string>

#include "kiln/sim/scene.hpp"

namespace kiln::sim::test {

// Sanitized runs are ~10× slower: the long stress runs use a tenth of the steps.
#ifdef KILN_SANITIZED_BUILD
inline constexpr int kScale = 10;
#else
inline constexpr int kScale = 1;
#endif

inline Scene shippedScene() {
    Scene s;
    std::string error;
    REQUIRE(loadScene(std::string(KILN_SOURCE_DIR) + "/scenes/cornell.json", s, error));
    return s;
}

// The shipped scene's bodies with every contact elastic and no friction: what keeps its
// energy exactly, for the conservation tests (the shipped scene damps its tumblers).
inline Scene energyKeepingScene() {
    Scene s;
    std::string error;
    REQUIRE(loadScene(std::string(KILN_SOURCE_DIR) + "/tests/sim/data/energy_keeping.json", s, error));
    return s;
}

}  // namespace kiln::sim::test
