// kiln/scene_view.hpp — what a pass sees of the scene: the frame uniforms (camera,
// lights, output size, time, bounds), how many instances of each kind there are, and a version
// per SceneCategory (kiln/declare.hpp) so the host can skip passes whose inputs did
// not change. Built by the host once per frame, in one place (host/app/app.cpp);
// read-only for passes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "kiln/declare.hpp"

namespace kiln {

// How finely the moving bodies are meshed. High: as fine as the camera's picture needs
// (each sphere picks one of three meshes by its size on screen, the round cones one of
// two by the largest's); Low: the coarse meshes, for passes that see the scene at low
// resolution (voxelize); Medium: every body at its middle mesh (round cones 24 slices,
// spheres 16 segments), for a view of middling resolution that is not the camera's (a
// shadow map); Fine: every body at its finest mesh whatever the camera sees (a large
// shadow map).
enum class Lod : uint8_t { High, Low, Medium, Fine };

// What drawScene() draws: the geometry bits of SceneCategory (kSceneGeometry,
// kSceneShadowCasters, kSceneRoundCones | kSceneSpheres, ...) at a level of detail.
// Which of the placed meshes (kSceneMeshes) by their material's sides: one-sided ones
// may be drawn with back faces culled, double-sided ones not. Other categories are
// drawn whatever it says.
enum class Sides : uint8_t { Any, OneSided, TwoSided };

struct DrawFilter {
    uint32_t categories = kSceneGeometry;
    Lod lod = Lod::High;
    Sides sides = Sides::Any;
};

// Per-instance data as the shaders see it (std430, binding kInstanceBinding); keep in
// sync with shaders/common/instances.glsl.
struct alignas(16) GpuInstance {
    glm::mat4 model;
    glm::vec4 albedo;    // rgb: the mean albedo (a textured surface's averaged over its texture,
                         //   for passes that see the scene coarsely), a = material (0 plain,
                         //   1 the procedural rings of GpuFrame::ringsLight/ringsDark)
    glm::vec4 emissive;  // rgb: the mean emitted radiance (already × strength), a = highlight
                         //   (picked) 0/1
    // The placed meshes' materials (kSceneMeshes; other categories leave these at their
    // defaults and read albedo and emissive): per texel, albedo = baseColor.rgb × the base colour texture, coverage
    // = baseColor.a × its alpha, radiance = emission.rgb × the emissive texture.
    glm::vec4 baseColor{1.0f};
    glm::vec4 emission{0.0f};
    glm::vec4 layers{-1.0f, -1.0f, -1.0f, 0.0f};  // x base colour, y emissive (layers of
                         //   SceneView::materialTextures[0]), z normal map (of [1]); -1 none;
                         //   w: the alpha cutoff (0: opaque)
};

// The punctual lights the frame holds at most (glTF's KHR_lights_punctual), and how
// many of the first of them cast shadows (the `lights` pass's shadow atlas, one tile
// each); the rest light unshadowed.
inline constexpr int kMaxPunctualLights = 16;
inline constexpr int kMaxShadowedLights = 4;

// One punctual light (std140, in GpuFrame). Radiometry as KHR_lights_punctual: a point
// or spot light's irradiance at distance d is color / d² (times the range window and
// the cone), a directional light's is color.
struct GpuPunctualLight {
    glm::vec4 position;   // xyz world, w = type (0 directional, 1 point, 2 spot)
    glm::vec4 direction;  // xyz unit, where it shines; w = range (0: infinite)
    glm::vec4 color;      // rgb × intensity; w = the shadow atlas tile (-1: unshadowed)
    glm::vec4 cone;       // spot: x cos(outer), y 1 / (cos(inner) − cos(outer)); zw unused
    glm::mat4 shadowViewProj;  // world → the tile's clip space (orthographic or perspective)
};

// The per-frame uniform block (std140, binding kFrameBinding); keep in sync with
// shaders/common/frame.glsl.
struct GpuFrame {
    glm::mat4 view, proj, viewProj, invViewProj;
    glm::vec4 cameraPos;     // xyz, w unused
    glm::vec4 lightPos;      // the spherical area light: xyz centre, w radius (0: none)
    glm::vec4 lightColor;    // rgb × intensity, w = intensity
    glm::vec4 outputSize;    // w, h, 1/w, 1/h
    glm::vec4 time;          // seconds, dt, frame index, unused
    glm::vec4 ringsLight;    // the procedural rings material (GpuInstance::albedo.a = 1):
    glm::vec4 ringsDark;     //   rgb light / dark, ringsLight.w = rings per metre
    glm::vec4 roundCone;     // the shape of every kSceneRoundCones instance, in its model
                             //   space: lower sphere radius b at the origin, upper radius t
                             //   at (0, y_t, 0), half-angle α (rad): (b, t, α, y_t)
    glm::uvec4 closedFaces;  // x: the voxel volume's faces closed by a wall in its outermost
                             //   voxels (a cone that reaches one stops), bit 2a for −axis a,
                             //   2a+1 for +axis a; 0: every face open
    glm::vec4 sceneMin;      // the scene's bounds (every instance's, world space); w unused
    glm::vec4 sceneMax;
    // The volume the voxel passes cover, the scene's bounds (voxelVolumeAround): xyz its
    // centre, w half its longest side, world space. Volume space is the world moved to
    // the centre and divided by w, so the volume is [-e, e] there with e = voxelExtent.xyz
    // (the longest axis's 1) and distances keep one scale on every axis; the grid's
    // texture coordinates are volume space ÷ e, mapped to [0,1]³ (frame.glsl's
    // kilnWorldToVolume, kilnVolumeTexcoord and kin).
    glm::vec4 voxelVolume{0.0f, 0.0f, 0.0f, 1.0f};
    glm::vec4 voxelExtent{1.0f, 1.0f, 1.0f, 0.0f};  // xyz: e, w unused
    glm::uvec4 punctualCount;  // x: lights[0 .. x) hold punctual lights
    GpuPunctualLight punctual[kMaxPunctualLights];
};

// The voxel volume of a scene with bounds [lo, hi] (GpuFrame::voxelVolume): centred on
// them, w half their longest side. A scene of [-1,1]³ gets exactly that cube.
inline glm::vec4 voxelVolumeAround(glm::vec3 lo, glm::vec3 hi) {
    const glm::vec3 half = 0.5f * (hi - lo);
    const float halfSide = std::max(std::max(half.x, half.y), std::max(half.z, 1e-3f));
    return glm::vec4(0.5f * (lo + hi), halfSide);
}

// Its extent on each axis over the longest (GpuFrame::voxelExtent): the volume is the
// bounds themselves, so a room's walls lie in the grid's outermost cells (a face the
// scene closes, GpuFrame::closedFaces, then holds them), not inside empty space that
// coarse lookups would average them with. At least 1/64 on every axis.
inline glm::vec3 voxelExtentAround(glm::vec3 lo, glm::vec3 hi) {
    const glm::vec3 half = glm::max(0.5f * (hi - lo), glm::vec3(0.0f));
    const float longest = std::max(std::max(half.x, half.y), std::max(half.z, 1e-3f));
    return glm::clamp(half / longest, glm::vec3(1.0f / 64.0f), glm::vec3(1.0f));
}

// How many times a voxel grid's side (the resolution, along the longest axis) halves
// along each axis of a volume of that extent: the power of two nearest the extent, at
// most 1/4, so every level of a mip chain halves exactly. A cell is then at most √2
// longer or shorter along a short axis than along the longest (exactly a cube where the
// extent is a power of two, as a cube's 1, 1, 1), and a scene flatter than a
// quarter gets cells flatter than cubes.
inline glm::ivec3 voxelGridShift(glm::vec3 extent) {
    glm::ivec3 shift;
    for (int a = 0; a < 3; ++a)
        shift[a] = std::clamp(int(std::lround(-std::log2(std::max(extent[a], 1e-6f)))), 0, 2);
    return shift;
}

// GpuFrame::closedFaces.x of a volume closed on every face, or on all but +z.
constexpr uint32_t closedFaceBits(bool closed) { return closed ? 0x3Fu : 0x1Fu; }

// The host camera's clip planes (GpuFrame::proj): what a pass that rasterises from the
// camera declares as its depth output's depthNear/depthFar (the texture viewer
// linearises depth with them). A scene that reaches past kCameraFar gets a farther
// plane; GpuFrame::proj is then the one to read.
inline constexpr float kCameraNear = 0.05f, kCameraFar = 20.0f;

inline constexpr unsigned kFrameBinding = 0;      // uniform block
inline constexpr unsigned kInstanceBinding = 0;   // shader storage block

// Bit index of a single SceneCategory bit (kSceneRoundCones → 3); -1 for a mask.
constexpr int sceneCategoryIndex(uint32_t c) {
    for (int i = 0; i < kSceneCategoryCount; ++i)
        if (c == (1u << i)) return i;
    return -1;
}

// The placed meshes (kSceneMeshes) as a ray tracer reads them: a bounding volume
// hierarchy per mesh over its triangles and one over the instances, with the scene's
// vertex and index buffers, traversed by shaders/common/ray_meshes.glsl
// (kilnTraceMeshes, kilnMeshSurface). A compute pass binds them with
// kiln::bindRayMeshes (kiln/pass.hpp). Rebuilt when the placed models change; the
// moving bodies are not in it (their shapes are exact: a sphere or a round cone placed
// by its GpuInstance::model).
//
// The emitting triangles (a material with emission) are listed apart, in world space,
// with their cumulative share of the emitted power (area × the material's mean
// luminance), for next-event estimation: kilnSampleEmitter picks one by power and a
// point on it uniformly; kilnEmitterDensity gives the same density for a point a path
// found by itself (multiple importance sampling).
struct RayMeshes {
    uint32_t nodes = 0, triangles = 0, instances = 0;  // GL buffer names (0: no meshes)
    uint32_t vertices = 0, surface = 0, indices = 0;   // the scene's vertex streams and indices
    uint32_t emitters = 0;                             // 0: nothing emits
    uint32_t topRoot = 0;                              // the instances' root node
    uint32_t instanceCount = 0;
    uint32_t emitterCount = 0;
    float emittedPower = 0.0f;  // Σ area × mean luminance over the emitters
    uint64_t triangleCount = 0;
};
// Shader storage bindings of ray_meshes.glsl (with the instances' at 0, the eight OpenGL
// 4.5 guarantees a compute shader), and the texture units of its material lookups
// (cut-outs, and the shader's own reads through kiln_rayColorLayers).
inline constexpr unsigned kRayEmitterBinding = 1, kRayNodeBinding = 2, kRayTriangleBinding = 3,
                          kRayInstanceBinding = 4, kRayVertexBinding = 5, kRaySurfaceBinding = 6,
                          kRayIndexBinding = 7;
inline constexpr unsigned kRayColorLayersUnit = 12, kRayDataLayersUnit = 13;

struct SceneView {
    GpuFrame frame{};
    RayMeshes rayMeshes;
    // The placed meshes' textures: GL_TEXTURE_2D_ARRAY names, [0] sRGB colour (base colour
    // and emissive layers), [1] linear data (normal maps, rgb = xyz × 0.5 + 0.5 in tangent
    // space); layers chosen by GpuInstance::layers. 0 when the scene has none.
    uint32_t materialTextures[2] = {0, 0};
    // Bumped by the host whenever that category changed (geometry: its instance
    // contents; lights: a light; camera: the view-projection; time: a step).
    uint64_t versions[kSceneCategoryCount] = {};
    uint32_t counts[kSceneGeometryCount] = {};  // instances per geometry category

    // The instance buffer holds the geometry categories in bit order (planes, the light's
    // surface, meshes, round cones, spheres, glowing spheres, particles); this is where
    // `single` starts.
    uint32_t firstInstance(SceneCategory single) const {
        uint32_t n = 0;
        for (int i = 0; i < sceneCategoryIndex(single); ++i) n += counts[i];
        return n;
    }
    uint64_t version(SceneCategory single) const { return versions[sceneCategoryIndex(single)]; }
    // Instances in the geometry categories of `mask` (kSceneShadowCasters: round cones + spheres).
    uint32_t count(uint32_t mask) const {
        uint32_t n = 0;
        for (int i = 0; i < kSceneGeometryCount; ++i)
            if (mask & (1u << i)) n += counts[i];
        return n;
    }
};

}  // namespace kiln
