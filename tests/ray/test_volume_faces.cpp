// Which faces of the voxel volume a scene's meshes close (ray/volume_faces.hpp): a room
// whose walls lie at the volume's faces closes those faces (over the part of them the
// scene covers), an opening or a model in the middle does not, and a face is found
// whichever way its triangles are wound.
#include <catch2/catch.hpp>

#include <vector>

#include "ray/volume_faces.hpp"

using namespace kiln::ray;

namespace {

struct Walls {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    // An axis-aligned square on the plane x[axis] = at, spanning [lo, hi] on the other two
    // axes, wound so that its one side faces `facing` (±1 along the axis).
    void square(int axis, float at, float lo, float hi, float facing) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        const uint32_t base = uint32_t(positions.size());
        for (auto [a, b] : {std::pair{lo, lo}, std::pair{hi, lo}, std::pair{hi, hi}, std::pair{lo, hi}}) {
            glm::vec3 p(0.0f);
            p[axis] = at, p[u] = a, p[v] = b;
            positions.push_back(p);
        }
        const bool flip = facing < 0.0f;
        for (uint32_t i : {0u, flip ? 2u : 1u, flip ? 1u : 2u, 0u, flip ? 3u : 2u, flip ? 2u : 3u})
            indices.push_back(base + i);
    }
    RayMeshData data() const {
        RayMeshData d;
        d.addMesh({positions, indices, 0});
        const std::vector<RayInstanceSource> one = {{0, glm::mat4(1.0f), 0, 0, false}};
        d.setInstances(one);
        return d;
    }
};

const glm::vec3 kLo(-2.0f), kHi(2.0f);  // the scenes' bounds: the volume's

// A cube volume (xyz centre, w half its side), `depth` on every axis.
uint32_t closedCubeFaces(const RayMeshData& meshes, glm::vec4 volume, glm::vec3 lo, glm::vec3 hi, float depth) {
    return closedVolumeFaces(meshes, glm::vec3(volume), glm::vec3(volume.w), lo, hi, glm::vec3(depth));
}

}  // namespace

TEST_CASE("a room of one-sided walls at the volume's faces closes all six, one left out opens its face",
          "[ray]") {
    const glm::vec4 volume(0.0f, 0.0f, 0.0f, 2.0f);  // the cube [-2, 2]³
    Walls room;
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-1.0f, 1.0f}) room.square(axis, 1.97f * side, -2.0f, 2.0f, -side);  // facing in
    CHECK(closedCubeFaces(room.data(), volume, kLo, kHi, 0.125f) == 0x3Fu);
    Walls open;
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-1.0f, 1.0f})
            if (!(axis == 2 && side > 0)) open.square(axis, 1.97f * side, -2.0f, 2.0f, -side);
    CHECK(closedCubeFaces(open.data(), volume, kLo, kHi, 0.125f) == 0x1Fu);  // +z open, as the box's front
    // Walls deeper in than `depth` do not close the faces (the voxels there are empty).
    CHECK(closedCubeFaces(room.data(), volume, kLo, kHi, 0.01f) == 0u);
    // A low room in a taller volume: its side walls close the side faces over the part
    // of them the room covers (above it the outermost voxels are empty either way).
    Walls low;
    for (int axis : {0, 2})
        for (float side : {-1.0f, 1.0f}) {
            const uint32_t first = uint32_t(low.positions.size());
            low.square(axis, 1.97f * side, -2.0f, 2.0f, -side);
            for (size_t k = first; k < low.positions.size(); ++k) low.positions[k].y = low.positions[k].y < 0 ? -2.0f : -1.0f;
        }
    CHECK(closedCubeFaces(low.data(), volume, kLo, glm::vec3(2.0f, -1.0f, 2.0f), 0.125f) == 0x33u);
    CHECK(closedCubeFaces(low.data(), volume, kLo, kHi, 0.125f) == 0u);  // judged over whole faces: a quarter
}

TEST_CASE("a wall with a hole of a fifth of its face, or a model in the middle, closes nothing", "[ray]") {
    const glm::vec4 volume(0.0f, 0.0f, 0.0f, 2.0f);
    Walls holed;  // the −x face from four strips around a 1.8 m square hole: 80 % covered
    holed.square(0, -1.98f, -2.0f, 2.0f, 1.0f);
    Walls frame;
    const float h = 0.9f;
    auto strip = [&](float y0, float y1, float z0, float z1) {
        const uint32_t base = uint32_t(frame.positions.size());
        for (glm::vec3 p : {glm::vec3(-1.98f, y0, z0), glm::vec3(-1.98f, y1, z0), glm::vec3(-1.98f, y1, z1),
                            glm::vec3(-1.98f, y0, z1)})
            frame.positions.push_back(p);
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) frame.indices.push_back(base + i);
    };
    strip(-2.0f, -h, -2.0f, 2.0f), strip(h, 2.0f, -2.0f, 2.0f), strip(-h, h, -2.0f, -h), strip(-h, h, h, 2.0f);
    CHECK(closedCubeFaces(holed.data(), volume, kLo, kHi, 0.125f) == 0x1u);
    CHECK(closedCubeFaces(frame.data(), volume, kLo, kHi, 0.125f) == 0u);  // 20 % of its rays pass
    Walls model;
    model.square(1, 0.0f, -1.0f, 1.0f, 1.0f);
    CHECK(closedCubeFaces(model.data(), volume, kLo, kHi, 0.125f) == 0u);
    CHECK(closedCubeFaces(RayMeshData{}, volume, kLo, kHi, 0.125f) == 0u);
}
