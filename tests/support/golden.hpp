// Golden-image comparison for headless renders.
//
// The final image (gamma-encoded RGBA8) is decoded to linear (power 2.2, the
// composite pass's default gamma) and compared with the committed golden PNG by RMSE
// over RGB. To regenerate after an intended change:
//     KILN_UPDATE_GOLDENS=1 ./build/bin/test_integration "[golden]"   (review, commit tests/goldens/)
#pragma once

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

#include "kiln/image_io.hpp"

namespace kiln::test {

inline double linearRmse(const FloatImage& a, const FloatImage& b) {
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                double d = std::pow(double(a.at(x, y)[c]), 2.2) - std::pow(double(b.at(x, y)[c]), 2.2);
                sum += d * d;
                ++n;
            }
    return std::sqrt(sum / double(n));
}

// Compares `img` with the golden at `path` (or writes it when KILN_UPDATE_GOLDENS is
// set) and returns the RMSE (0 when updating).
inline double compareWithGolden(const FloatImage& img, const std::string& path) {
    std::string error;
    if (std::getenv("KILN_UPDATE_GOLDENS")) {
        REQUIRE(writePng(path, img, 3, error));
        WARN("updated golden " << path);
        return 0.0;
    }
    // Round-trip through 8 bits so the comparison sees what the golden stores.
    FloatImage quantized = img;
    for (auto& v : quantized.pixels) v = std::round(std::clamp(v, 0.0f, 1.0f) * 255.0f) / 255.0f;
    FloatImage golden;
    INFO("regenerate with KILN_UPDATE_GOLDENS=1 (see tests/support/golden.hpp)");
    REQUIRE(readPng(path, golden, error));
    REQUIRE(golden.width == img.width);
    REQUIRE(golden.height == img.height);
    return linearRmse(quantized, golden);
}

}  // namespace kiln::test
