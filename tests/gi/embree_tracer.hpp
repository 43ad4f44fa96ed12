// A second, independent estimator for the reference: a CPU path tracer on Debian's
// Embree over the same glTF triangles and materials (read with the model loader, placed
// by its own instance transforms — none of the host's BVH, buffers or shaders), Lambert
// with the materials' factors (no textures), emission found by BSDF sampling and the
// punctual lights by shadow rays. Tests only: the product's reference is the GPU's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "kiln/float_image.hpp"
#include "model/model.hpp"

namespace kiln::test {

struct CpuTraceSettings {
    int width = 0, height = 0;
    glm::mat4 invViewProj{1.0f};  // the camera's, as the GPU reference uses it
    int samples = 64;
    int maxBounces = 64;
    int rouletteStart = 3;
    uint32_t seed = 1;
};

// Renders `model` (every material double-sided) and returns the mean radiance per pixel,
// rows bottom up as FloatImage holds them (the GL convention). False with `error` set
// when Embree cannot build the scene.
bool traceWithEmbree(const model::Model& model, const CpuTraceSettings& settings, FloatImage& out, std::string& error);

}  // namespace kiln::test
