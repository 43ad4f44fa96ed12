#version 450 core
// Voxelization, stage 2: project each triangle on the axis its normal is most aligned
// with, in voxels (an orthographic view of the voxel grid, [-1,1]³ in grid space, along
// x, y or z), and enlarge it by half a pixel diagonal so every voxel it touches gets a fragment (conservative rasterisation
// after Hasselgren et al., GPU Gems 2 ch. 42). The enlarged corners' world positions
// are extrapolated on the triangle's plane (the projection is affine, so this is exact).
// Each axis draws into a viewport of its own, apart from the others by whole tiles of
// llvmpipe's 64 × 64 (voxelize.cpp sets them up): a framebuffer as small as the voxels
// is one tile, and llvmpipe shades a tile on one thread.
#include "common/frame.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 vg_world[];
in vec3 vg_normal[];
flat in uint vg_instance[];

out vec3 v_world;
out vec3 v_normal;
flat out uint v_instance;
flat out int v_axis;      // 0: projected along x, 1: y, 2: z
flat out vec4 v_aabb;     // the triangle's 2D bounding box (+½ pixel), in pixels
flat out vec2 v_depthRange;  // min/max of the projection-axis coordinate over the triangle

uniform ivec3 u_grid;  // voxels per axis
uniform float u_conservative;

// Volume space → (2D on the projection plane, depth along the axis), all in [-1,1].
vec3 project(vec3 w, int axis) {
    return axis == 0 ? w.yzx : axis == 1 ? w.zxy : w.xyz;
}

void main() {
    vec3 e1 = vg_world[1] - vg_world[0], e2 = vg_world[2] - vg_world[0];
    vec3 g[3];
    for (int i = 0; i < 3; ++i) g[i] = kilnWorldToGrid(vg_world[i]);
    // The axis the triangle covers most pixels along (in voxel units: the cells need
    // not be cubes).
    vec3 cells = vec3(u_grid);
    vec3 fn = abs(cross((g[1] - g[0]) * cells, (g[2] - g[0]) * cells));
    int axis = (fn.x >= fn.y && fn.x >= fn.z) ? 0 : (fn.y >= fn.z ? 1 : 2);

    vec3 q[3];
    for (int i = 0; i < 3; ++i) q[i] = project(g[i], axis);
    vec2 p[3] = vec2[3](q[0].xy, q[1].xy, q[2].xy);
    vec2 pixels = project(cells, axis).xy;  // the viewport's size
    vec2 hp = u_conservative / pixels;      // half a pixel, in [-1,1] units

    // Counter-clockwise order in 2D, so edge normals point outwards.
    float area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
    if (abs(area) < 1e-12) {
        // Degenerate in projection (cannot happen for the dominant axis unless the
        // triangle itself is degenerate): nothing to voxelize.
        return;
    }
    vec2 o[3] = p;
    if (u_conservative > 0.0) {
        float s = area > 0.0 ? 1.0 : -1.0;
        // Each edge's line pushed out by hp·(|nx|+|ny|) (half the pixel diagonal along
        // its normal); new corner = intersection of the two pushed lines through it.
        vec3 lines[3];
        for (int i = 0; i < 3; ++i) {
            vec2 a = p[i], b = p[(i + 1) % 3];
            vec2 n = s * vec2(b.y - a.y, a.x - b.x);  // outward
            float len = length(n);
            n /= max(len, 1e-20);
            float c = -dot(n, a) - dot(hp, abs(n));  // n·x + c = 0, moved out
            lines[i] = vec3(n, c);
        }
        for (int i = 0; i < 3; ++i) {
            vec3 l0 = lines[(i + 2) % 3], l1 = lines[i];  // edges meeting at corner i
            vec3 x = cross(l0, l1);
            o[i] = abs(x.z) > 1e-12 ? x.xy / x.z : p[i];
        }
    }
    vec4 aabb = vec4(min(min(p[0], p[1]), p[2]) - hp, max(max(p[0], p[1]), p[2]) + hp);
    aabb = (aabb * 0.5 + 0.5) * pixels.xyxy;  // pixels
    vec2 depthRange = vec2(min(min(q[0].z, q[1].z), q[2].z), max(max(q[0].z, q[1].z), q[2].z));

    // Barycentrics of the enlarged corners w.r.t. the original 2D triangle.
    mat2 T = mat2(p[1] - p[0], p[2] - p[0]);
    mat2 Ti = inverse(T);
    for (int i = 0; i < 3; ++i) {
        vec2 uv = Ti * (o[i] - p[0]);
        v_world = vg_world[0] + uv.x * e1 + uv.y * e2;
        v_normal = vg_normal[0] + uv.x * (vg_normal[1] - vg_normal[0]) + uv.y * (vg_normal[2] - vg_normal[0]);
        v_instance = vg_instance[0];
        v_axis = axis;
        v_aabb = aabb;
        v_depthRange = depthRange;
        gl_Position = vec4(o[i], 0.0, 1.0);
        gl_ViewportIndex = axis;
        EmitVertex();
    }
    EndPrimitive();
}
