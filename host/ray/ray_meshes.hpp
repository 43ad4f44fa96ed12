// ray/ray_meshes.hpp — the placed meshes as a ray tracer reads them: a BVH per mesh
// over its triangles (in the mesh's own space) and one over the instances, flattened
// into the buffers shaders/common/ray_meshes.glsl traverses. Plain CPU data: the scene
// renderer uploads it (SceneView::rayMeshes).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "ray/bvh.hpp"

namespace kiln::ray {

// One triangle in leaf order: a vertex and two edges (what the ray test needs), and
// where its three indices start in the scene's index buffer (for the attributes).
struct RayTriangle {
    glm::vec3 v0;
    uint32_t firstIndex;
    glm::vec3 e1;
    uint32_t mesh;  // the mesh's bottom-level root, for messages and tests
    glm::vec3 e2;
    uint32_t unused = 0;
};
static_assert(sizeof(RayTriangle) == 48);

// One instance of a mesh (std430, ray_meshes.glsl KilnRayInstance).
struct RayInstance {
    glm::vec4 worldToLocal[3];  // rows of the affine inverse of the instance's model
    uint32_t root;              // its mesh's bottom-level root in the node buffer
    uint32_t instance;          // into the scene's instance buffer (its material)
    uint32_t baseVertex;        // added to the mesh's indices
    uint32_t twoSided;          // 0: a back face is not hit (glTF's one-sided material)
};
static_assert(sizeof(RayInstance) == 64);

// What a mesh's triangles are read from: positions by index (baseVertex already added).
// An emitting triangle, in world space, for sampling the light it gives: its cumulative
// share of every emitter's power (area × the material's mean luminance), so a uniform
// number picks one in proportion to its power.
struct RayEmitter {
    glm::vec3 v0;
    float cdf;          // Σ of the shares up to and with this one; the last is 1
    glm::vec3 e1;
    uint32_t instance;  // into RayMeshData::instances()
    glm::vec3 e2;
    uint32_t triangle;  // into RayMeshData::triangles()
};
static_assert(sizeof(RayEmitter) == 48);

struct RayMeshSource {
    std::span<const glm::vec3> positions;  // the mesh's vertices
    std::span<const uint32_t> indices;     // its triangles, three each
    uint32_t firstIndex;                   // where `indices` starts in the scene's index buffer
};

struct RayInstanceSource {
    uint32_t mesh;      // into the meshes given to addMesh, in their order
    glm::mat4 model;    // mesh space → world (affine, invertible)
    uint32_t instance;  // into the scene's instance buffer
    uint32_t baseVertex;
    bool twoSided;
    float emitted = 0.0f;  // the material's mean emitted luminance (0: it gives no light)
};

// The nearest triangle a ray meets (RayMeshData::nearestHit).
struct RayHit {
    float t = INFINITY;
    uint32_t instance = UINT32_MAX;  // into RayMeshData::instances()
    uint32_t triangle = 0;           // into RayMeshData::triangles()
    glm::vec2 barycentric{0.0f};     // of v0 + u·e1 + v·e2
    bool found() const { return instance != UINT32_MAX; }
};

class RayMeshData {
public:
    // Adds a mesh's hierarchy; meshes are numbered in the order they are added.
    void addMesh(const RayMeshSource&);
    // The top level over the instances (replacing the last one).
    void setInstances(std::span<const RayInstanceSource>);

    const std::vector<BvhNode>& nodes() const { return nodes_; }
    const std::vector<RayTriangle>& triangles() const { return triangles_; }
    const std::vector<RayInstance>& instances() const { return instances_; }
    // The emitting instances' triangles, and their power (Σ area × luminance).
    const std::vector<RayEmitter>& emitters() const { return emitters_; }
    float emittedPower() const { return emittedPower_; }
    // The top level's root in nodes(), valid when instances() is not empty.
    uint32_t topRoot() const { return topRoot_; }
    size_t meshCount() const { return meshRoots_.size(); }
    // The nearest triangle along o + t·d for t in (0, tMax), found as ray_meshes.glsl
    // finds it (the same walk and triangle test; a one-sided instance's back faces are
    // not hit; with `oneSided` false every triangle is hit from either side). Alpha
    // cut-outs are not honoured: the CPU holds no textures. For picking what a pixel
    // shows, testing where surfaces are, and checking the GPU's hits.
    RayHit nearestHit(glm::vec3 origin, glm::vec3 direction, float tMax = INFINITY, bool oneSided = true) const;

private:
    std::vector<BvhNode> nodes_;  // every mesh's hierarchy, then the top level's
    size_t meshNodes_ = 0;        // nodes_[0 .. meshNodes_) are the meshes'
    std::vector<RayTriangle> triangles_;
    std::vector<RayInstance> instances_;
    std::vector<RayEmitter> emitters_;
    float emittedPower_ = 0.0f;
    struct Range { uint32_t first = 0, count = 0; };
    std::vector<Range> meshTriangles_;  // per mesh: its triangles in triangles_
    std::vector<uint32_t> meshRoots_;  // per mesh: its root (UINT32_MAX: no triangles)
    std::vector<Aabb> meshBounds_;
    uint32_t topRoot_ = 0;
};

}  // namespace kiln::ray
