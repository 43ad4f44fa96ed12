// kiln/image_io.hpp — reading textures back and writing them as PNG (8-bit, through
// stb_image_write) or PFM (32-bit float, for HDR and depth).
#pragma once

#include <string>
#include <vector>

#include "kiln/gl.hpp"

namespace kiln {

struct FloatImage {
    int width = 0, height = 0, channels = 4;
    std::vector<float> pixels;  // row 0 = bottom (GL convention)
    const float* at(int x, int y) const { return &pixels[(static_cast<size_t>(y) * width + x) * channels]; }
};

// Reads mip `level` of a 2D texture (or slice `layer` of a 3D one) as RGBA float.
FloatImage readTexture(GLuint texture, GLenum target, GLenum internalFormat, int width, int height, int level = 0,
                       int layer = -1);

// PNG of the first `channels` (1..4) values clamped to [0,1]; `flip` writes row 0 last
// (GL images are bottom-up). Returns false and sets `error` on failure.
bool writePng(const std::string& path, const FloatImage& img, int channels, std::string& error);
bool writePfm(const std::string& path, const FloatImage& img, std::string& error);

}  // namespace kiln

namespace kiln {
// Reads an 8-bit PNG as RGBA floats in [0,1], bottom row first (like readTexture).
bool readPng(const std::string& path, FloatImage& out, std::string& error);
}  // namespace kiln
