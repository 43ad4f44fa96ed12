// Rays through the placed meshes (kSceneMeshes): the host's two-level BVH
// (host/ray/ray_meshes.hpp; bound by kiln::bindRayMeshes at the bindings below),
// traversed nearest child first with a stack, triangles by Möller–Trumbore. A back face
// of a one-sided material is not hit (glTF culls it); where a material is alpha-masked
// the base colour's coverage at the hit decides (a cut-out lets the ray through).
// Needs common/instances.glsl; takes shader storage bindings 2–7 (kiln/scene_view.hpp).
#include "common/luminance.glsl"
struct KilnRayNode {
    vec3 lo;
    uint first;   // interior (count 0): children first, first + 1; leaf: first primitive
    vec3 hi;
    uint count;
};
struct KilnRayTriangle {
    vec3 v0;
    uint firstIndex;  // into kiln_rayIndices
    vec3 e1;
    uint mesh;
    vec3 e2;
    uint unused;
};
struct KilnRayInstance {
    vec4 worldToLocal[3];  // rows of the affine inverse of the model
    uint root;             // the mesh's root node
    uint instance;         // into kiln_instances
    uint baseVertex;
    uint twoSided;
};
struct KilnRayEmitter {  // an emitting triangle, world space
    vec3 v0;
    float cdf;         // cumulative share of the emitted power; the last is 1
    vec3 e1;
    uint rayInstance;  // into kiln_rayInstances
    vec3 e2;
    uint triangle;     // into kiln_rayTriangles
};
layout(std430, binding = 1) readonly buffer KilnRayEmitters { KilnRayEmitter kiln_rayEmitters[]; };
layout(std430, binding = 2) readonly buffer KilnRayNodes { KilnRayNode kiln_rayNodes[]; };
layout(std430, binding = 3) readonly buffer KilnRayTriangles { KilnRayTriangle kiln_rayTriangles[]; };
layout(std430, binding = 4) readonly buffer KilnRayInstances { KilnRayInstance kiln_rayInstances[]; };
// The scene's vertex streams as floats: position xyz + normal xyz, and uv + tangent xyzw.
layout(std430, binding = 5) readonly buffer KilnRayVertices { float kiln_rayVertices[]; };
layout(std430, binding = 6) readonly buffer KilnRaySurface { float kiln_raySurface[]; };
layout(std430, binding = 7) readonly buffer KilnRayIndices { uint kiln_rayIndices[]; };
layout(binding = 12) uniform sampler2DArray kiln_rayColorLayers;  // SceneView::materialTextures
layout(binding = 13) uniform sampler2DArray kiln_rayDataLayers;

uniform uint u_rayTopRoot;        // kiln::bindRayMeshes sets both
uniform uint u_rayInstanceCount;  // 0: no meshes
uniform uint u_rayEmitterCount;   // 0: no mesh emits
uniform float u_rayEmittedPower;  // Σ area × mean luminance over the emitters

struct KilnMeshHit {
    float t;
    uint rayInstance;  // into kiln_rayInstances
    uint triangle;     // into kiln_rayTriangles
    vec2 bary;         // of vertices 1 and 2
};

// Entry distance of the ray (o, 1/d) into the box, or a value ≥ tMax when it misses.
float kilnRayBoxEntry(vec3 o, vec3 invD, vec3 lo, vec3 hi, float tMin, float tMax) {
    vec3 a = (lo - o) * invD, b = (hi - o) * invD;
    vec3 near = min(a, b), far = max(a, b);
    float enter = max(max(near.x, near.y), max(near.z, tMin));
    float leave = min(min(far.x, far.y), min(far.z, tMax));
    return enter <= leave ? enter : 1e30;
}

// The children of an interior node that the ray (o, 1/d) enters before tMax, nearest
// first in `near`, the other in `far`: how many (0, 1 or 2).
int kilnRayChildren(KilnRayNode n, vec3 o, vec3 invD, float tMin, float tMax, out uint near, out uint far) {
    near = n.first, far = n.first + 1u;
    float tn = kilnRayBoxEntry(o, invD, kiln_rayNodes[near].lo, kiln_rayNodes[near].hi, tMin, tMax);
    float tf = kilnRayBoxEntry(o, invD, kiln_rayNodes[far].lo, kiln_rayNodes[far].hi, tMin, tMax);
    if (tf < tn) { uint s = near; near = far; far = s; float f = tn; tn = tf; tf = f; }
    return tn < tMax ? (tf < tMax ? 2 : 1) : 0;
}

uvec3 kilnRayTriangleVertices(KilnRayInstance inst, uint triangle) {
    uint f = kiln_rayTriangles[triangle].firstIndex;
    return uvec3(kiln_rayIndices[f], kiln_rayIndices[f + 1u], kiln_rayIndices[f + 2u]) + inst.baseVertex;
}
vec2 kilnRayUv(uint v) { return vec2(kiln_raySurface[6u * v], kiln_raySurface[6u * v + 1u]); }

// Whether a hit on a masked material's triangle is a hole (its coverage below the cutoff).
bool kilnRayCutOut(KilnRayInstance ri, uint triangle, vec2 bary) {
    KilnInstance m = kiln_instances[ri.instance];
    if (m.layers.w <= 0.0) return false;
    float coverage = m.baseColor.a;
    if (m.layers.x >= 0.0) {
        uvec3 v = kilnRayTriangleVertices(ri, triangle);
        vec2 uv = kilnRayUv(v.x) * (1.0 - bary.x - bary.y) + kilnRayUv(v.y) * bary.x + kilnRayUv(v.z) * bary.y;
        coverage *= textureLod(kiln_rayColorLayers, vec3(uv, m.layers.x), 0.0).a;
    }
    return coverage < m.layers.w;
}

// The nearest hit in (tMin, tMax); false if none. Rays in world space; d need not be unit.
bool kilnTraceMeshes(vec3 o, vec3 d, float tMin, float tMax, out KilnMeshHit hit) {
    hit = KilnMeshHit(tMax, 0u, 0u, vec2(0.0));
    if (u_rayInstanceCount == 0u) return false;
    bool found = false;
    // 48: host/ray/bvh.hpp kMaxBvhDepth, the deepest the host builds a hierarchy (a push
    // per level), so the `top < 48` guards below never drop a subtree.
    uint stack[48];
    int top = 0;
    // The top level's stack holds nodes; a leaf's instances are traced at once.
    vec3 invD = 1.0 / d;
    uint node = u_rayTopRoot;
    if (kilnRayBoxEntry(o, invD, kiln_rayNodes[node].lo, kiln_rayNodes[node].hi, tMin, hit.t) >= hit.t) return false;
    while (true) {
        KilnRayNode n = kiln_rayNodes[node];
        if (n.count == 0u) {
            uint a, b;
            int entered = kilnRayChildren(n, o, invD, tMin, hit.t, a, b);
            if (entered > 0) {
                if (entered > 1 && top < 48) stack[top++] = b;
                node = a;
                continue;
            }
        } else {
            for (uint k = n.first; k < n.first + n.count; ++k) {
                KilnRayInstance ri = kiln_rayInstances[k];
                vec3 lo = vec3(dot(ri.worldToLocal[0], vec4(o, 1.0)), dot(ri.worldToLocal[1], vec4(o, 1.0)),
                               dot(ri.worldToLocal[2], vec4(o, 1.0)));
                vec3 ld = vec3(dot(ri.worldToLocal[0].xyz, d), dot(ri.worldToLocal[1].xyz, d),
                               dot(ri.worldToLocal[2].xyz, d));
                vec3 linvD = 1.0 / ld;
                uint inner[48];
                int innerTop = 0;
                uint m = ri.root;
                if (kilnRayBoxEntry(lo, linvD, kiln_rayNodes[m].lo, kiln_rayNodes[m].hi, tMin, hit.t) >= hit.t) continue;
                while (true) {
                    KilnRayNode mn = kiln_rayNodes[m];
                    if (mn.count == 0u) {
                        uint a, b;
                        int entered = kilnRayChildren(mn, lo, linvD, tMin, hit.t, a, b);
                        if (entered > 0) {
                            if (entered > 1 && innerTop < 48) inner[innerTop++] = b;
                            m = a;
                            continue;
                        }
                    } else {
                        for (uint t = mn.first; t < mn.first + mn.count; ++t) {
                            KilnRayTriangle tri = kiln_rayTriangles[t];
                            vec3 p = cross(ld, tri.e2);
                            float det = dot(tri.e1, p);
                            // det = −d·(e1×e2): negative where the ray meets the winding's
                            // back, which a one-sided material does not show.
                            if (abs(det) < 1e-20 || (ri.twoSided == 0u && det < 0.0)) continue;
                            float inv = 1.0 / det;
                            vec3 s = lo - tri.v0;
                            float u = dot(s, p) * inv;
                            if (u < 0.0 || u > 1.0) continue;
                            vec3 q = cross(s, tri.e1);
                            float v = dot(ld, q) * inv;
                            if (v < 0.0 || u + v > 1.0) continue;
                            float tt = dot(tri.e2, q) * inv;
                            if (tt <= tMin || tt >= hit.t) continue;
                            if (kilnRayCutOut(ri, t, vec2(u, v))) continue;
                            hit = KilnMeshHit(tt, k, t, vec2(u, v));
                            found = true;
                        }
                    }
                    if (innerTop == 0) break;
                    m = inner[--innerTop];
                }
            }
        }
        if (top == 0) break;
        node = stack[--top];
    }
    return found;
}

// The surface at a hit, in world space: the geometric normal (the winding's, unit),
// the interpolated shading normal (unit; the normal map not applied), the texture
// coordinates and the tangent (xyz world, w the bitangent's sign).
struct KilnMeshSurface {
    vec3 geometricNormal;
    vec3 normal;
    vec2 uv;
    vec4 tangent;
    uint instance;  // into kiln_instances
};
KilnMeshSurface kilnMeshSurface(KilnMeshHit hit) {
    KilnRayInstance ri = kiln_rayInstances[hit.rayInstance];
    KilnRayTriangle tri = kiln_rayTriangles[hit.triangle];
    uvec3 v = kilnRayTriangleVertices(ri, hit.triangle);
    vec3 w = vec3(1.0 - hit.bary.x - hit.bary.y, hit.bary.x, hit.bary.y);
    // Normals go world-ward by the inverse's transpose: Mᵀ·n with M the rows given.
    mat3 worldToLocal = transpose(mat3(ri.worldToLocal[0].xyz, ri.worldToLocal[1].xyz, ri.worldToLocal[2].xyz));
    mat3 normalToWorld = transpose(worldToLocal);
    vec3 n = vec3(0.0), t = vec3(0.0);
    vec2 uv = vec2(0.0);
    float sign = 1.0;
    for (int k = 0; k < 3; ++k) {
        uint i = v[k];
        n += w[k] * vec3(kiln_rayVertices[6u * i + 3u], kiln_rayVertices[6u * i + 4u], kiln_rayVertices[6u * i + 5u]);
        uv += w[k] * kilnRayUv(i);
        t += w[k] * vec3(kiln_raySurface[6u * i + 2u], kiln_raySurface[6u * i + 3u], kiln_raySurface[6u * i + 4u]);
        sign = kiln_raySurface[6u * i + 5u];
    }
    KilnMeshSurface s;
    s.geometricNormal = normalize(normalToWorld * cross(tri.e1, tri.e2));
    s.normal = dot(n, n) > 0.0 ? normalize(normalToWorld * n) : s.geometricNormal;
    s.uv = uv;
    // Tangents are directions: they go world-ward by the model's linear part.
    s.tangent = vec4(inverse(worldToLocal) * t, sign);
    s.instance = ri.instance;
    return s;
}

// Next-event estimation toward the emitting triangles: one picked in proportion to its
// power (area × its material's mean luminance, GpuInstance::emissive), a point on it
// uniformly (u, v, w uniform in [0, 1)). `hit` names the triangle and the point as a
// ray hit would (kilnMeshSurface gives its material there); areaDensity is the sample's
// density per unit area, which kilnEmitterDensity gives for a point a path hit itself.
float kilnEmitterDensity(uint instance) {
    return u_rayEmittedPower > 0.0 ? kilnLuminance(kiln_instances[instance].emissive.rgb) / u_rayEmittedPower : 0.0;
}
struct KilnEmitterSample {
    vec3 position;
    vec3 normal;  // the winding's, unit
    KilnMeshHit hit;
    float areaDensity;
};
KilnEmitterSample kilnSampleEmitter(float u, float v, float w) {
    uint lo = 0u, hi = u_rayEmitterCount - 1u;
    while (lo < hi) {  // the first whose cumulative share reaches u
        uint mid = (lo + hi) / 2u;
        if (kiln_rayEmitters[mid].cdf < u) lo = mid + 1u; else hi = mid;
    }
    KilnRayEmitter e = kiln_rayEmitters[lo];
    float r = sqrt(v);
    vec2 bary = vec2(r * (1.0 - w), r * w);  // uniform over the triangle
    KilnEmitterSample s;
    s.position = e.v0 + e.e1 * bary.x + e.e2 * bary.y;
    s.normal = normalize(cross(e.e1, e.e2));
    s.hit = KilnMeshHit(0.0, e.rayInstance, e.triangle, bary);
    s.areaDensity = kilnEmitterDensity(kiln_rayInstances[e.rayInstance].instance);
    return s;
}
