// app/pixel_trace.hpp — "why is this pixel wrong?" in one click: the value of every
// texture of every pass at one pixel of the image, in the order the passes ran, with the
// pass that wrote it. A 2D texture is read where the pixel falls in it (its centre's
// uv × that texture's size: a half-size bloom at the matching texel); a 3D texture (the
// voxels over the voxel volume) at the world position the camera's depth gives the pixel,
// in every tile of a tiled atlas.
#pragma once

#include <glm/glm.hpp>

#include <optional>
#include <string>
#include <vector>

#include "run/runtime.hpp"

namespace kiln::app {

struct TraceRow {
    std::string pass, name;
    bool internal = false;
    bool volume = false;      // a 3D texture, read at the world position
    int tile = -1;            // which block of a tiled atlas; -1: not tiled
    glm::ivec3 texel{0};      // level 0
    glm::vec4 value{0.0f};    // as stored: floats, integers as floats, depth in r
    bool read = false;        // false: no value (a 3D texture and the pixel sees no surface)
};

struct PixelTrace {
    glm::vec2 uv{0.0f};                 // the pixel's centre, [0,1]², y up
    std::optional<glm::vec3> world;     // where the camera's depth puts it (none: the far plane)
    std::string depthTexture;           // "pass.name" of that depth
    std::vector<TraceRow> rows;
};

// `invViewProj`: the camera's, for the frame the textures hold; `voxelVolume` and
// `voxelExtent` that frame's (GpuFrame's), where a 3D texture is read. The camera's depth is
// the 2D depth texture declared with the camera's planes (kCameraNear, kCameraFar).
PixelTrace tracePixel(const run::Runtime&, const glm::mat4& invViewProj, glm::vec4 voxelVolume, glm::vec3 voxelExtent,
                      glm::vec2 uv);

}  // namespace kiln::app
