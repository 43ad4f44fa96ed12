#include "app/pixel_trace.hpp"

#include <algorithm>
#include <cmath>

#include "kiln/image_io.hpp"

namespace kiln::app {

namespace {

glm::vec4 readTexel(const TextureRef& t, glm::ivec3 texel) {
    const std::vector<float> v = readTextureBox(t.id, t.format, 0, texel.x, texel.y, texel.z, 1, 1, 1);
    return v.size() >= 4 ? glm::vec4(v[0], v[1], v[2], v[3]) : glm::vec4(0.0f);
}

glm::ivec2 texelOf(glm::vec2 uv, int width, int height) {
    return {std::clamp(int(std::floor(uv.x * float(width))), 0, width - 1),
            std::clamp(int(std::floor(uv.y * float(height))), 0, height - 1)};
}

// The world position behind the pixel, from the first depth texture rendered with the
// camera's planes; none when the pixel sees nothing (depth at the far plane).
void findWorld(const std::vector<run::NamedTexture>& textures, const glm::mat4& invViewProj, PixelTrace& trace) {
    for (const run::NamedTexture& t : textures) {
        if (t.ref.target != GL_TEXTURE_2D || !gl::isDepthFormat(t.ref.format) || !t.cameraDepth)
            continue;
        trace.depthTexture = t.pass + "." + t.name;
        const glm::ivec2 texel = texelOf(trace.uv, t.ref.width, t.ref.height);
        const float depth = readTexel(t.ref, {texel, 0}).r;
        if (depth >= 1.0f) return;
        const glm::vec4 clip(trace.uv * 2.0f - 1.0f, depth * 2.0f - 1.0f, 1.0f);
        const glm::vec4 world = invViewProj * clip;
        trace.world = glm::vec3(world) / world.w;
        return;
    }
}

}  // namespace

PixelTrace tracePixel(const run::Runtime& runtime, const glm::mat4& invViewProj, glm::vec4 voxelVolume, glm::vec3 voxelExtent,
                      glm::vec2 uv) {
    PixelTrace trace;
    trace.uv = glm::clamp(uv, glm::vec2(0.0f), glm::vec2(1.0f));
    const std::vector<run::NamedTexture> textures = runtime.textures();
    findWorld(textures, invViewProj, trace);
    for (const run::NamedTexture& t : textures) {
        if (!t.ref.bound || t.ref.id == 0 || t.stale) continue;  // left unwritten: nothing of this frame
        TraceRow row{t.pass, t.name, t.internal, t.ref.target == GL_TEXTURE_3D};
        if (!row.volume) {
            row.texel = {texelOf(trace.uv, t.ref.width, t.ref.height), 0};
            row.value = readTexel(t.ref, row.texel);
            row.read = true;
            trace.rows.push_back(row);
            continue;
        }
        const int tiles = std::max(1, t.tiles), blockWidth = std::max(1, t.ref.width / tiles);
        for (int tile = 0; tile < tiles; ++tile) {
            row.tile = tiles > 1 ? tile : -1;
            if (trace.world) {
                const glm::vec3 grid = (*trace.world - glm::vec3(voxelVolume)) / (voxelVolume.w * voxelExtent);
                const glm::vec3 p01 = glm::clamp((grid + 1.0f) * 0.5f, glm::vec3(0.0f), glm::vec3(0.999999f));
                row.texel = glm::ivec3(p01 * glm::vec3(blockWidth, t.ref.height, t.ref.depth));
                row.texel.x += tile * blockWidth;
                row.value = readTexel(t.ref, row.texel);
                row.read = true;
            }
            trace.rows.push_back(row);
        }
    }
    return trace;
}

}  // namespace kiln::app
