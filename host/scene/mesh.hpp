// scene/mesh.hpp — the scene's meshes, generated on the CPU on each scene load: a unit
// wall quad, the icosphere lamp dome, the tumbler (round cone) and spheres, each in two levels of
// detail, and the particles' octahedron. Indexed triangles; position + normal per vertex.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace kiln::scene {

struct Vertex {
    glm::vec3 position;
    glm::vec3 normal;
};

struct MeshData {
    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;
};

// The square [-1,1]² in the xz plane at y = 0, facing +y.
MeshData makeQuad();
// Icosphere of `radius` about `centre`, subdivided `level` times, keeping only the
// triangles with a vertex below `clipY` (the part of the lamp inside the box). Normals
// point outward (into the room).
MeshData makeLampDome(glm::vec3 centre, float radius, int level, float clipY);
MeshData makeUvSphere(int slices, int stacks);  // unit radius
// The particles' mesh: an octahedron with its vertices at 1.35, which gives it the
// unit sphere's mean projected area (surface/4: 6.93·1.35²/4 ≈ π), so a particle
// covers as much screen and as many voxels as a sphere would, from 8 triangles
// instead of a sphere's 120 (9 000 particles are 72 000 triangles, not 1.1 million).
// Normals are radial: interpolated, they shade like a sphere.
MeshData makeParticle();
// A round cone: lower sphere radius b at the origin, upper sphere radius t at
// (0, (b − t)/sin α, 0), joined by the tangent cone. `slices` around, `stacks` per cap,
// every vertex moved `inflate` along its normal (0: inscribed in the round cone).
MeshData makeTumbler(float b, float t, float alpha, int slices, int stacks, float inflate = 0.0f);
// How far to move an n-sided inscribed polygon's vertices out so that it has its
// circle's area: r·(1/√(n·sin(2π/n)/(2π)) − 1) (the shadow of a coarse caster as large
// as the round one's).
float areaPreservingInflation(float r, int n);

}  // namespace kiln::scene
