#include "kiln/image_io.hpp"

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace kiln {

std::vector<float> readTextureBox(GLuint texture, GLenum internalFormat, int level, int x, int y, int z, int w, int h,
                                  int d) {
    const size_t count = size_t(w) * size_t(h) * size_t(d);
    std::vector<float> rgba(count * 4, 0.0f);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    if (gl::isDepthFormat(internalFormat) || gl::isIntegerFormat(internalFormat)) {
        std::vector<float> one(count);
        std::vector<GLuint> ui(gl::isIntegerFormat(internalFormat) ? count : 0);
        if (!ui.empty())
            glGetTextureSubImage(texture, level, x, y, z, w, h, d, GL_RED_INTEGER, GL_UNSIGNED_INT,
                                 GLsizei(count * sizeof(GLuint)), ui.data());
        else
            glGetTextureSubImage(texture, level, x, y, z, w, h, d, GL_DEPTH_COMPONENT, GL_FLOAT,
                                 GLsizei(count * sizeof(float)), one.data());
        for (size_t i = 0; i < count; ++i) {
            const float v = ui.empty() ? one[i] : float(ui[i]);
            rgba[i * 4 + 0] = rgba[i * 4 + 1] = rgba[i * 4 + 2] = v;
            rgba[i * 4 + 3] = 1.0f;
        }
    } else {
        glGetTextureSubImage(texture, level, x, y, z, w, h, d, GL_RGBA, GL_FLOAT, GLsizei(count * 4 * sizeof(float)),
                             rgba.data());
    }
    return rgba;
}

FloatImage readTexture(GLuint texture, GLenum target, GLenum internalFormat, int width, int height, int level,
                       int layer) {
    FloatImage img;
    img.width = std::max(1, width >> level);
    img.height = std::max(1, height >> level);
    img.channels = 4;
    const int z = target == GL_TEXTURE_3D ? std::max(layer, 0) : 0;
    img.pixels = readTextureBox(texture, internalFormat, level, 0, 0, z, img.width, img.height, 1);
    return img;
}

bool writePng(const std::string& path, const FloatImage& img, int channels, std::string& error) {
    channels = std::clamp(channels, 1, 4);
    std::vector<unsigned char> bytes(static_cast<size_t>(img.width) * img.height * channels);
    for (int y = 0; y < img.height; ++y) {
        const int srcY = img.height - 1 - y;  // PNG is top-down
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.at(x, srcY);
            for (int c = 0; c < channels; ++c) {
                float v = std::isfinite(p[c]) ? std::clamp(p[c], 0.0f, 1.0f) : 0.0f;
                bytes[(static_cast<size_t>(y) * img.width + x) * channels + c] =
                    static_cast<unsigned char>(std::lround(v * 255.0f));
            }
        }
    }
    if (!stbi_write_png(path.c_str(), img.width, img.height, channels, bytes.data(), img.width * channels)) {
        error = path + ": cannot write PNG: " + std::strerror(errno);
        return false;
    }
    return true;
}

bool writeExr(const std::string& path, const FloatImage& img, std::string& error) {
    const int channels = img.channels >= 4 ? 4 : 3;
    std::vector<float> data(static_cast<size_t>(img.width) * img.height * channels);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < channels; ++c)
                data[(static_cast<size_t>(img.height - 1 - y) * img.width + x) * channels + c] =
                    c < img.channels ? img.at(x, y)[c] : 0.0f;
    const char* message = nullptr;
    if (SaveEXR(data.data(), img.width, img.height, channels, 0, path.c_str(), &message) < 0) {
        error = path + ": cannot write EXR: " + (message ? message : std::strerror(errno));
        if (message) FreeEXRErrorMessage(message);
        return false;
    }
    return true;
}

bool writePfm(const std::string& path, const FloatImage& img, std::string& error) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) {
        error = path + ": cannot write PFM: " + std::strerror(errno);
        return false;
    }
    static_assert(std::endian::native == std::endian::little, "the scale's sign below says little-endian");
    std::fprintf(f, "PF\n%d %d\n-1.0\n", img.width, img.height);  // a negative scale: little-endian
    std::vector<float> row(static_cast<size_t>(img.width) * 3);
    bool ok = true;
    for (int y = 0; y < img.height && ok; ++y) {
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) row[static_cast<size_t>(x) * 3 + c] = c < img.channels ? img.at(x, y)[c] : 0.0f;
        ok = std::fwrite(row.data(), sizeof(float), row.size(), f) == row.size();
    }
    ok = std::fclose(f) == 0 && ok;
    if (!ok) error = path + ": cannot write PFM: " + std::strerror(errno);
    return ok;
}

bool readExr(const std::string& path, FloatImage& out, std::string& error) {
    float* rgba = nullptr;
    int w = 0, h = 0;
    const char* message = nullptr;
    if (LoadEXR(&rgba, &w, &h, path.c_str(), &message) < 0) {
        error = path + ": cannot read EXR: " + (message ? message : "unknown error");
        if (message) FreeEXRErrorMessage(message);
        return false;
    }
    out.width = w, out.height = h, out.channels = 4;
    out.pixels.resize(static_cast<size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
        std::copy_n(rgba + static_cast<size_t>(h - 1 - y) * w * 4, static_cast<size_t>(w) * 4,
                    out.pixels.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(y) * w * 4));
    std::free(rgba);
    return true;
}

bool readPng(const std::string& path, FloatImage& out, std::string& error) {
    int w = 0, h = 0, n = 0;
    unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 4);
    if (!data) {
        error = path + ": cannot read PNG: " + (stbi_failure_reason() ? stbi_failure_reason() : "unknown");
        return false;
    }
    out.width = w;
    out.height = h;
    out.channels = 4;
    out.pixels.resize(static_cast<size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w * 4; ++x)
            out.pixels[static_cast<size_t>(h - 1 - y) * w * 4 + x] = data[static_cast<size_t>(y) * w * 4 + x] / 255.0f;
    stbi_image_free(data);
    return true;
}

}  // namespace kiln
