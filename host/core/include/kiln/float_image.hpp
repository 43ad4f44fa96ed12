// kiln/float_image.hpp — an image of floats as read back from a texture (no GL here,
// so GL-free code such as the error metrics can use it).
#pragma once

#include <cstddef>
#include <vector>

namespace kiln {

struct FloatImage {
    int width = 0, height = 0, channels = 4;
    std::vector<float> pixels;  // row 0 = bottom (GL convention)
    const float* at(int x, int y) const { return &pixels[(static_cast<size_t>(y) * width + x) * channels]; }
    float* at(int x, int y) { return &pixels[(static_cast<size_t>(y) * width + x) * channels]; }
};

}  // namespace kiln
