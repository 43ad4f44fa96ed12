// The analytic scene the reference traces: the same instances the rasterizer draws
// (common/instances.glsl), read as exact shapes instead of meshes.
//   box walls   the quad (y = 0, |x|, |z| ≤ 1, normal +y) placed by the instance's model
//   lamp        the sphere u_lightPos below the ceiling y = 1 (its instance: material)
//   tumblers    the round cone u_roundCone placed by the model (rigid)
//   spheres     marbles, fireballs, particles: model = translate × scale(radius)
//   meshes      the placed models' triangles, through the host's BVH (common/ray_meshes.glsl)
// Ranges come from the host's category counts (u_first/u_count, SceneView order).
#include "common/frame.glsl"
#include "common/instances.glsl"
#include "common/ray_meshes.glsl"

const int kBox = 0, kLamp = 1, kMeshes = 2, kTumblers = 3, kMarbles = 4, kFireballs = 5, kParticles = 6;
uniform int u_first[7];
uniform int u_count[7];

const float kNoHit = 1e30;

struct Hit {
    float t;
    vec3 normal;   // outward, unit (meshes: see `mesh`)
    int instance;  // -1: nothing
    bool onMesh;   // a placed mesh's triangle: kilnMeshSurface(mesh) gives the surface
    KilnMeshHit mesh;
};

// Rigid model: world → local without a general inverse.
vec3 toLocal(mat4 m, vec3 p) { return transpose(mat3(m)) * (p - m[3].xyz); }
vec3 dirToLocal(mat4 m, vec3 d) { return transpose(mat3(m)) * d; }

// Smallest root of |o + t·d − c|² = r² beyond tMin, kNoHit if none (d unit).
float sphereEntry(vec3 o, vec3 d, vec3 c, float r, float tMin) {
    vec3 oc = o - c;
    float b = dot(oc, d);
    float disc = b * b - (dot(oc, oc) - r * r);
    if (disc < 0.0) return kNoHit;
    float s = sqrt(disc);
    float t = -b - s;
    if (t > tMin) return t;
    t = -b + s;
    return t > tMin ? t : kNoHit;
}

// The round cone in its local frame (lower sphere radius b at the origin, upper sphere
// radius t at (0, y_t, 0), the side tangent to both at half-angle α; kiln/sim/shape.hpp):
// the convex hull is the union of both balls and the frustum between the tangent
// circles, so the first hit is the nearest first hit of the three.
float roundConeHit(vec3 o, vec3 d, float tMin, out vec3 normal) {
    const float b = u_roundCone.x, tr = u_roundCone.y, yt = u_roundCone.w;
    const float sa = sin(u_roundCone.z), ca = cos(u_roundCone.z);
    float best = kNoHit;
    float t0 = sphereEntry(o, d, vec3(0.0), b, tMin);
    if (t0 < best) best = t0, normal = (o + t0 * d) / b;
    float t1 = sphereEntry(o, d, vec3(0.0, yt, 0.0), tr, tMin);
    if (t1 < best) best = t1, normal = (o + t1 * d - vec3(0.0, yt, 0.0)) / tr;
    // Side: r·cos α = b − y·sin α (b − y·sin α ≥ 0), i.e. (x²+z²)cos²α = (b − y sin α)²,
    // valid between the tangent circles: 0 ≤ y·cos α − r·sin α ≤ y_t·cos α.
    const float c2 = ca * ca;
    const float A = (d.x * d.x + d.z * d.z) * c2 - d.y * d.y * sa * sa;
    const float B = (o.x * d.x + o.z * d.z) * c2 + (b - o.y * sa) * d.y * sa;
    const float C = (o.x * o.x + o.z * o.z) * c2 - (b - o.y * sa) * (b - o.y * sa);
    if (abs(A) > 1e-12) {
        float disc = B * B - A * C;
        if (disc >= 0.0) {
            float s = sqrt(disc);
            float roots[2] = float[2]((-B - s) / A, (-B + s) / A);
            if (roots[0] > roots[1]) roots = float[2](roots[1], roots[0]);
            for (int k = 0; k < 2; ++k) {
                float t = roots[k];
                if (t <= tMin || t >= best) continue;
                vec3 p = o + t * d;
                float r = length(p.xz);
                float kk = p.y * ca - r * sa;
                if (b - p.y * sa < 0.0 || kk < 0.0 || kk > yt * ca || r < 1e-9) continue;
                best = t;
                normal = vec3(p.x / r * ca, sa, p.z / r * ca);
                break;
            }
        }
    }
    return best;
}

uint g_rays = 0u;  // rays this invocation traced (the pass's `rays` output)

Hit traceScene(vec3 o, vec3 d, float tMin) {
    ++g_rays;
    Hit h = Hit(kNoHit, vec3(0.0), -1, false, KilnMeshHit(0.0, 0u, 0u, vec2(0.0)));
    for (int i = u_first[kBox]; i < u_first[kBox] + u_count[kBox]; ++i) {
        mat4 m = kiln_instances[i].model;
        vec3 n = m[1].xyz;
        float dn = dot(d, n);
        if (abs(dn) < 1e-12) continue;
        float t = dot(m[3].xyz - o, n) / dn;
        if (t <= tMin || t >= h.t) continue;
        vec3 q = toLocal(m, o + t * d);
        if (abs(q.x) > 1.0 || abs(q.z) > 1.0) continue;
        h.t = t, h.normal = n, h.instance = i;
    }
    if (u_count[kLamp] > 0) {
        vec3 c = u_lightPos.xyz;
        float r = u_lightPos.w;
        float t = sphereEntry(o, d, c, r, tMin);
        if (t < h.t && o.y + t * d.y <= kCeilingY) h.t = t, h.normal = (o + t * d - c) / r, h.instance = u_first[kLamp];
    }
    for (int i = u_first[kTumblers]; i < u_first[kTumblers] + u_count[kTumblers]; ++i) {
        mat4 m = kiln_instances[i].model;
        // Bounding sphere first: the cone's axis midpoint, radius half the height + b.
        vec3 mid = (m * vec4(0.0, 0.5 * u_roundCone.w, 0.0, 1.0)).xyz;
        float reach = 0.5 * u_roundCone.w + u_roundCone.x;
        vec3 om = o - mid;
        float bb = dot(om, d);
        if (bb * bb - dot(om, om) + reach * reach < 0.0) continue;
        vec3 n;
        float t = roundConeHit(toLocal(m, o), dirToLocal(m, d), tMin, n);
        if (t < h.t) h.t = t, h.normal = mat3(m) * n, h.instance = i;
    }
    for (int i = u_first[kMarbles]; i < u_first[kParticles] + u_count[kParticles]; ++i) {
        mat4 m = kiln_instances[i].model;
        vec3 c = m[3].xyz;
        float r = length(m[0].xyz);
        float t = sphereEntry(o, d, c, r, tMin);
        if (t < h.t) h.t = t, h.normal = (o + t * d - c) / r, h.instance = i;
    }
    KilnMeshHit m;
    if (kilnTraceMeshes(o, d, tMin, h.t, m)) {
        h.t = m.t, h.instance = int(kiln_rayInstances[m.rayInstance].instance);
        h.onMesh = true, h.mesh = m;
    }
    return h;
}
