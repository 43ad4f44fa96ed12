#version 450 core
// Spheres (marbles, fireballs) traced, not tessellated: each one the screen rectangle
// its sphere projects into (two triangles, six vertices, instances [u_first, u_first +
// count) of the scene's instance buffer), sphere.frag intersecting each pixel's ray with
// it. llvmpipe sets up every triangle on the CPU, so many fireballs' 16 × 8 meshes are
// dear there, and their silhouettes are polygons.
#include "common/frame.glsl"
#include "common/instances.glsl"

uniform uint u_first;
flat out vec4 v_sphere;    // centre, radius
// The ray through the pixel in world space, scaled to step one metre of view depth a
// unit: affine in the screen, so interpolated exactly without perspective.
noperspective out vec3 v_ray;
flat out vec4 v_albedo;    // as gbuffer.vert's
flat out vec4 v_emissive;

// The NDC interval [lo, hi] along one screen axis that a sphere at view-space `along`
// (on that axis) and depth `depth` (> radius) projects into: the directions tangent to
// it, tan(α ± β) with tan α = along / depth, sin β = radius / distance. False when a
// tangent direction turns away from the view (the sphere spans 180° or more of it).
bool projectedInterval(float along, float depth, float radius, float scale, float offset, out vec2 interval) {
    float distance2 = along * along + depth * depth;
    float tangent2 = distance2 - radius * radius;
    if (depth <= radius || tangent2 <= 0.0) return false;
    float tanAlpha = along / depth, tanBeta = radius * inversesqrt(tangent2);
    float below = 1.0 + tanAlpha * tanBeta, above = 1.0 - tanAlpha * tanBeta;
    if (below <= 0.0 || above <= 0.0) return false;
    interval = scale * vec2((tanAlpha - tanBeta) / below, (tanAlpha + tanBeta) / above) - offset;
    return true;
}

void main() {
    KilnInstance inst = kiln_instances[u_first + uint(gl_VertexID / 6)];
    vec3 centre = kilnSphereCentre(inst);
    float radius = kilnSphereRadius(inst);
    v_sphere = vec4(centre, radius);
    v_albedo = inst.albedo;
    v_emissive = inst.emissive;
    // The camera looks down −z: depth = −z. x_ndc = P00 x / depth − P20 (y likewise).
    vec3 c = (u_view * vec4(centre, 1.0)).xyz;
    vec2 xs, ys;
    vec2 lo = vec2(-1.0), hi = vec2(1.0);  // the whole screen where the sphere reaches the camera's side
    if (projectedInterval(c.x, -c.z, radius, u_proj[0][0], u_proj[2][0], xs) &&
        projectedInterval(c.y, -c.z, radius, u_proj[1][1], u_proj[2][1], ys)) {
        // A pixel more each way: the rectangle must hold every pixel whose centre's ray hits.
        vec2 pixel = 2.0 * u_outputSize.zw;
        lo = max(vec2(xs.x, ys.x) - pixel, vec2(-1.0));
        hi = min(vec2(xs.y, ys.y) + pixel, vec2(1.0));
    }
    const ivec2 kCorners[6] = ivec2[](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(0, 1), ivec2(1, 0), ivec2(1, 1));
    ivec2 corner = kCorners[gl_VertexID % 6];
    vec2 ndc = mix(lo, hi, vec2(corner));
    gl_Position = vec4(ndc, 0.0, 1.0);
    vec2 slope = (ndc + vec2(u_proj[2][0], u_proj[2][1])) / vec2(u_proj[0][0], u_proj[1][1]);  // x / depth, y / depth
    v_ray = transpose(mat3(u_view)) * vec3(slope, -1.0);
}
