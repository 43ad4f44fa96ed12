// kiln/image_io.hpp — reading textures back and writing them as PNG (8-bit, through
// stb_image_write) or OpenEXR (32-bit float, through tinyexr: HDR and depth that
// Blender, tev, RenderDoc and oiiotool open).
#pragma once

#include <string>
#include <vector>

#include "kiln/float_image.hpp"
#include "kiln/gl.hpp"

namespace kiln {

// Reads a box of texels of mip `level` as RGBA floats, x fastest, then y, then z:
// R32UI as its integer value, depth in r (g = b = r, a = 1).
std::vector<float> readTextureBox(GLuint texture, GLenum internalFormat, int level, int x, int y, int z, int w, int h,
                                  int d);
// Reads mip `level` of a 2D texture (or slice `layer` of a 3D one) as RGBA float.
FloatImage readTexture(GLuint texture, GLenum target, GLenum internalFormat, int width, int height, int level = 0,
                       int layer = -1);

// PNG of the first `channels` (1..4) values clamped to [0,1]; `flip` writes row 0 last
// (GL images are bottom-up). Returns false and sets `error` on failure.
bool writePng(const std::string& path, const FloatImage& img, int channels, std::string& error);
// OpenEXR, 32-bit float RGB (RGBA when the image has 4 channels), top row first as
// EXR expects; readExr gives RGBA floats bottom row first, like readTexture.
bool writeExr(const std::string& path, const FloatImage& img, std::string& error);
bool readExr(const std::string& path, FloatImage& out, std::string& error);
// Portable float map: 32-bit float RGB, little-endian, bottom row first (the format's own
// order, as GL's); readable by oiiotool, ImageMagick and most HDR viewers.
bool writePfm(const std::string& path, const FloatImage& img, std::string& error);

}  // namespace kiln

namespace kiln {
// Reads an 8-bit PNG as RGBA floats in [0,1], bottom row first (like readTexture).
bool readPng(const std::string& path, FloatImage& out, std::string& error);
}  // namespace kiln
