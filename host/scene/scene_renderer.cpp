#include "scene/scene_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "kiln/hash.hpp"
#include "scene/mesh.hpp"

namespace kiln::scene {

namespace {

// `keys` (a depth's 32 bits over an index) in order of the depths, largest first, ties
// in index order: a least-significant-byte-first radix sort of the upper halves, four
// passes. With 4 000 particles 0.02 ms a frame where std::sort took 0.17.
void sortFarToNear(std::vector<uint64_t>& keys, std::vector<uint64_t>& scratch) {
    scratch.resize(keys.size());
    for (int shift = 32; shift < 64; shift += 8) {
        std::array<size_t, 257> start{};
        for (uint64_t k : keys) ++start[((k >> shift) & 255u) + 1];
        for (size_t i = 0; i < 256; ++i) start[i + 1] += start[i];
        for (uint64_t k : keys) scratch[start[(k >> shift) & 255u]++] = k;
        keys.swap(scratch);
    }
}

// A depth's key for sortFarToNear over index i: its bits made to rise with the value,
// then flipped, so that the farthest sorts first.
uint64_t farFirstKey(float depth, uint32_t i) {
    uint32_t bits;
    std::memcpy(&bits, &depth, sizeof bits);
    bits = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
    return (uint64_t(~bits) << 32) | i;
}

}  // namespace

void SceneRenderer::buildMeshes(const SceneLook& look) {
    auto tumbler = [&](const TumblerMesh& m) {
        return makeTumbler(look.tumblerB, look.tumblerT, look.tumblerAlpha, m.slices, m.stacks,
                           m.inflated ? areaPreservingInflation(look.tumblerB, m.slices) : 0.0f);
    };
    std::array<MeshData, kMeshCount> data = {
        makeQuad(),
        makeLampDome(look.lampCentre, look.lampRadius, 3, 1.0f),
        tumbler(kTumblerNear),    // the camera's near,
        tumbler(kTumblerFar),     // far,
        tumbler(kTumblerShadow),  // Lod::Medium (the shadow map),
        tumbler(kTumblerVoxels),  // Lod::Low (voxelization)
        makeUvSphere(kSphereSegments[0], 16),  // spheres by size on screen (sphereLevelFor): near,
        makeUvSphere(kSphereSegments[1], 8),   // mid,
        makeUvSphere(kSphereSegments[2], 6),   // far, and for voxelization
        makeParticle(),
    };
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;
    for (int i = 0; i < kMeshCount; ++i) {
        meshes_[i] = {static_cast<uint32_t>(indices.size()), static_cast<uint32_t>(data[i].indices.size()),
                      static_cast<uint32_t>(vertices.size())};
        vertices.insert(vertices.end(), data[i].vertices.begin(), data[i].vertices.end());
        indices.insert(indices.end(), data[i].indices.begin(), data[i].indices.end());
    }
    vertexBuffer_ = gl::Buffer::create(static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(), 0,
                                       "scene.vertices");
    indexBuffer_ = gl::Buffer::create(static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(), 0,
                                      "scene.indices");
    if (!vao_) {
        vao_ = gl::createVertexArray();
        const GLuint vao = vao_.id();
        gl::label(GL_VERTEX_ARRAY, vao, "scene.vao");
        glEnableVertexArrayAttrib(vao, 0);
        glEnableVertexArrayAttrib(vao, 1);
        glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
        glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, normal));
        glVertexArrayAttribBinding(vao, 0, 0);
        glVertexArrayAttribBinding(vao, 1, 0);
        glEnableVertexArrayAttrib(vao, 2);
        glVertexArrayAttribIFormat(vao, 2, 1, GL_UNSIGNED_INT, 0);
        glVertexArrayAttribBinding(vao, 2, 1);
        glVertexArrayBindingDivisor(vao, 1, 1);
    }
    glVertexArrayVertexBuffer(vao_.id(), 0, vertexBuffer_.id(), 0, sizeof(Vertex));
    glVertexArrayElementBuffer(vao_.id(), indexBuffer_.id());
}

void SceneRenderer::setLook(const SceneLook& look) {
    buildMeshes(look);
    staticInstances_.clear();
    auto wall = [&](glm::mat4 m, glm::vec3 albedo, float material) {
        staticInstances_.push_back({m, glm::vec4(albedo, material), glm::vec4(look.wallEmission, 0.0f)});
    };
    // The quad faces +y at y = 0; each wall is it rotated so its normal points into the room.
    const glm::mat4 I(1.0f);
    wall(glm::translate(I, {0, -1, 0}), look.woodLight, 1.0f);                                           // floor
    wall(glm::rotate(glm::translate(I, {0, 1, 0}), glm::radians(180.0f), {1, 0, 0}), look.other, 0.0f);  // ceiling
    wall(glm::rotate(glm::translate(I, {-1, 0, 0}), glm::radians(-90.0f), {0, 0, 1}), look.left, 0.0f);  // left
    wall(glm::rotate(glm::translate(I, {1, 0, 0}), glm::radians(90.0f), {0, 0, 1}), look.right, 0.0f);   // right
    wall(glm::rotate(glm::translate(I, {0, 0, -1}), glm::radians(90.0f), {1, 0, 0}), look.other, 0.0f);  // back
    if (look.closed) wall(glm::rotate(glm::translate(I, {0, 0, 1}), glm::radians(-90.0f), {1, 0, 0}), look.other, 0.0f);
    const size_t walls = staticInstances_.size();
    // The lamp dome: its mesh is already in world space.
    staticInstances_.push_back(
        {I, glm::vec4(look.lampColor, 0.0f), glm::vec4(look.lampColor * look.lampIntensity, 0.0f)});
    // The tumbler's mesh about its origin (the lower ball's centre): the upper ball's top.
    tumblerRadius_ = tumblerBoundingRadius(look.tumblerB, look.tumblerT, look.tumblerAlpha);
    movedUnbounded_ = true;
    // New meshes change what every category looks like, whatever its instances say.
    for (int i = 0; i < kSceneGeometryCount; ++i) ++versions_[i], hashes_[i] = 0;
    noteContents(kSceneBox, staticInstances_.data(), walls);
    noteContents(kSceneLamp, staticInstances_.data() + walls, 1);
    dirty_ = true;
}

void SceneRenderer::noteContents(SceneCategory c, const GpuInstance* begin, size_t count) {
    const uint64_t h = hashWords(begin, count * sizeof(GpuInstance), fnv1a(&count, sizeof count));
    const int k = sceneCategoryIndex(c);
    counts_[k] = static_cast<uint32_t>(count);
    if (h != hashes_[k]) hashes_[k] = h, ++versions_[k];
}

void SceneRenderer::setBodies(const std::vector<BodyInstance>& bodies) {
    // Grouped by category so each category is one contiguous instance range.
    bodyInstances_.clear();
    for (SceneCategory c : {kSceneTumblers, kSceneMarbles, kSceneFireballs}) {
        const size_t first = bodyInstances_.size();
        for (auto& b : bodies)
            if (b.category == c)
                bodyInstances_.push_back(
                    {b.model, glm::vec4(b.albedo, 0.0f), glm::vec4(b.emissive, b.highlighted ? 1.0f : 0.0f)});
        noteContents(c, bodyInstances_.data() + first, bodyInstances_.size() - first);
    }
    noteMovedBodies();
    dirty_ = true;
}

// Bodies are matched by their place in the list (upload() reorders bodyInstances_, so
// the list as given is kept apart); one added or removed cannot be bounded so.
void SceneRenderer::noteMovedBodies() {
    if (bodyInstances_.size() != givenBodies_.size()) movedUnbounded_ = true;
    auto sphere = [&](const GpuInstance& g, size_t i) {
        const float scale = std::max({glm::length(glm::vec3(g.model[0])), glm::length(glm::vec3(g.model[1])),
                                      glm::length(glm::vec3(g.model[2]))});
        const float meshRadius = i < count(kSceneTumblers) ? tumblerRadius_ : 1.0f;
        return glm::vec4(glm::vec3(g.model[3]), scale * meshRadius);
    };
    if (!movedUnbounded_)
        for (size_t i = 0; i < bodyInstances_.size(); ++i)
            if (std::memcmp(&bodyInstances_[i], &givenBodies_[i], sizeof(GpuInstance)) != 0) {
                movedBodies_.push_back(sphere(givenBodies_[i], i));
                movedBodies_.push_back(sphere(bodyInstances_[i], i));
            }
    givenBodies_ = bodyInstances_;
}

std::optional<std::vector<glm::vec4>> SceneRenderer::takeMovedBodies() {
    std::optional<std::vector<glm::vec4>> moved;
    if (!movedUnbounded_) moved = std::move(movedBodies_);
    movedBodies_.clear();
    movedUnbounded_ = false;
    return moved;
}

void SceneRenderer::setParticles(const std::vector<ParticleInstance>& particles) {
    particleInstances_.clear();
    for (auto& p : particles) {
        glm::mat4 m = glm::scale(glm::translate(glm::mat4(1.0f), p.position), glm::vec3(p.radius));
        particleInstances_.push_back({m, glm::vec4(0.0f), glm::vec4(p.emissive, 0.0f)});
    }
    noteContents(kSceneParticles, particleInstances_.data(), particleInstances_.size());
    dirty_ = true;
}

void SceneRenderer::setViewer(glm::vec3 eye, glm::vec3 forward, float pixelsPerUnit) {
    if (eye == eye_ && forward == forward_ && pixelsPerUnit == pixelsPerUnit_) return;
    eye_ = eye;
    forward_ = forward;
    pixelsPerUnit_ = pixelsPerUnit;
    dirty_ = true;  // the spheres' levels and the particles' order follow the camera (their contents do not)
}

// At a third of the triangles for the usual 20–40-px marble (measured: 100 marbles at
// 720² cost 1.21× the 3-marble frame with one 24-segment mesh, 1.08× with these).
void SceneRenderer::chooseLevels() {
    // The pixels across the screen of a length `radius` at instance g's origin.
    auto onScreenPx = [&](const GpuInstance& g, float radius) {
        return radius / std::max(glm::length(glm::vec3(g.model[3]) - eye_), 1e-3f) * pixelsPerUnit_;
    };
    size_t first = 0;
    int k = 0;
    for (SceneCategory c : {kSceneTumblers, kSceneMarbles, kSceneFireballs}) {
        const size_t n = count(c);
        if (c == kSceneTumblers) {
            // One mesh for all: the largest on screen decides.
            float largestPx = 0.0f;
            for (size_t i = first; i < first + n; ++i) {
                const GpuInstance& g = bodyInstances_[i];
                largestPx = std::max(largestPx, onScreenPx(g, tumblerRadius_ * glm::length(glm::vec3(g.model[1]))));
            }
            tumblersNear_ = largestPx >= kTumblerNearPx;
        } else {
            auto level = [&](const GpuInstance& g) {
                return sphereLevelFor(onScreenPx(g, glm::length(glm::vec3(g.model[0]))));
            };
            auto begin = bodyInstances_.begin() + std::ptrdiff_t(first), end = begin + std::ptrdiff_t(n);
            auto mid = std::stable_partition(begin, end, [&](const GpuInstance& g) { return level(g) == 0; });
            auto far = std::stable_partition(mid, end, [&](const GpuInstance& g) { return level(g) == 1; });
            sphereLevels_[size_t(k++)] = {uint32_t(mid - begin), uint32_t(far - mid), uint32_t(end - far)};
        }
        first += n;
    }
}

void SceneRenderer::rebuildGroups() {
    groups_.clear();
    uint32_t cursor = 0;
    auto add = [&](MeshId mesh, SceneCategory cat) {  // one mesh at every level
        const uint32_t n = count(cat);
        if (n == 0) return;
        groups_.push_back({mesh, cat, Lod::High, true, cursor, n});
        cursor += n;
    };
    auto addSpheres = [&](SceneCategory cat, const std::array<uint32_t, 3>& levels) {
        const MeshId meshes[3] = {kSphereHigh, kSphereMid, kSphereLow};
        uint32_t at = cursor;
        for (int i = 0; i < 3; ++i) {
            if (levels[size_t(i)] > 0) groups_.push_back({meshes[i], cat, Lod::High, false, at, levels[size_t(i)]});
            at += levels[size_t(i)];
        }
        if (count(cat) > 0) {
            groups_.push_back({kSphereHigh, cat, Lod::Fine, false, cursor, count(cat)});
            groups_.push_back({kSphereMid, cat, Lod::Medium, false, cursor, count(cat)});
            groups_.push_back({kSphereLow, cat, Lod::Low, false, cursor, count(cat)});
        }
        cursor += count(cat);
    };
    // The order of the instance buffer: static, bodies by category (spheres near to
    // far), particles.
    add(kQuad, kSceneBox);
    add(kLamp, kSceneLamp);
    if (const uint32_t n = count(kSceneTumblers); n > 0) {
        const MeshId camera = tumblersNear_ ? kTumblerNearMesh : kTumblerFarMesh;
        groups_.push_back({camera, kSceneTumblers, Lod::High, false, cursor, n});
        groups_.push_back({kTumblerNearMesh, kSceneTumblers, Lod::Fine, false, cursor, n});
        groups_.push_back({kTumblerShadowMesh, kSceneTumblers, Lod::Medium, false, cursor, n});
        groups_.push_back({kTumblerVoxelMesh, kSceneTumblers, Lod::Low, false, cursor, n});
        cursor += n;
    }
    addSpheres(kSceneMarbles, sphereLevels_[0]);
    addSpheres(kSceneFireballs, sphereLevels_[1]);
    add(kParticle, kSceneParticles);
}

void SceneRenderer::upload() {
    if (!dirty_) return;
    chooseLevels();
    rebuildGroups();
    std::vector<GpuInstance> all;
    all.reserve(staticInstances_.size() + bodyInstances_.size() + particleInstances_.size());
    all.insert(all.end(), staticInstances_.begin(), staticInstances_.end());
    all.insert(all.end(), bodyInstances_.begin(), bodyInstances_.end());
    // The particles far to near along the view: the G-buffer draws them without writing
    // depth (passes/gbuffer), so where two cover a pixel the nearer must come last, as
    // a depth test against their centres' depths would have it.
    particleOrder_.resize(particleInstances_.size());
    for (size_t i = 0; i < particleInstances_.size(); ++i)
        particleOrder_[i] = farFirstKey(glm::dot(glm::vec3(particleInstances_[i].model[3]) - eye_, forward_), uint32_t(i));
    sortFarToNear(particleOrder_, sortScratch_);
    for (uint64_t key : particleOrder_) all.push_back(particleInstances_[uint32_t(key)]);
    if (all.size() > instanceCapacity_) {
        instanceCapacity_ = std::max<size_t>(all.size() * 2, 256);
        instanceBuffer_ = gl::Buffer::create(static_cast<GLsizeiptr>(instanceCapacity_ * sizeof(GpuInstance)), nullptr,
                                             GL_DYNAMIC_STORAGE_BIT, "scene.instances");
        std::vector<uint32_t> ids(instanceCapacity_);
        for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<uint32_t>(i);
        instanceIds_ = gl::Buffer::create(static_cast<GLsizeiptr>(ids.size() * sizeof(uint32_t)), ids.data(), 0,
                                          "scene.instance_ids");
        glVertexArrayVertexBuffer(vao_.id(), 1, instanceIds_.id(), 0, sizeof(uint32_t));
    }
    glNamedBufferSubData(instanceBuffer_.id(), 0, static_cast<GLsizeiptr>(all.size() * sizeof(GpuInstance)), all.data());
    dirty_ = false;
}

void SceneRenderer::bindInstances() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kInstanceBinding, instanceBuffer_.id());
}

template <class Visit>
void SceneRenderer::forEachGroupDrawn(const DrawFilter& filter, Visit visit) const {
    for (auto& g : groups_)
        if ((filter.categories & g.category) && (g.anyLod || g.lod == filter.lod)) visit(g);
}

uint64_t SceneRenderer::triangles(const DrawFilter& filter) const {
    uint64_t n = 0;
    forEachGroupDrawn(filter, [&](const Group& g) { n += uint64_t(meshes_[g.mesh].indexCount / 3) * g.count; });
    return n;
}

void SceneRenderer::draw(const DrawFilter& filter) const {
    if (!instanceBuffer_) return;
    glBindVertexArray(vao_.id());
    bindInstances();
    forEachGroupDrawn(filter, [&](const Group& g) {
        const MeshRange& m = meshes_[g.mesh];
        // The per-instance attribute reads 0, 1, 2, … starting at `first`, so the shader
        // indexes the instance buffer with it (no gl_BaseInstance needed: GL 4.5 core).
        glDrawElementsInstancedBaseVertexBaseInstance(
            GL_TRIANGLES, static_cast<GLsizei>(m.indexCount), GL_UNSIGNED_INT,
            reinterpret_cast<const void*>(static_cast<uintptr_t>(m.firstIndex) * 4), static_cast<GLsizei>(g.count),
            static_cast<GLint>(m.baseVertex), g.first);
    });
    glBindVertexArray(0);
}

}  // namespace kiln::scene
