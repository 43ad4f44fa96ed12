#version 450 core
// Anisotropic mip level (Crassin et al. 2011), all six directions of one parent voxel
// per invocation. Direction i ∈ {+x,−x,+y,−y,+z,−z}; its chain lives in the octant
// (i&1, (i>>1)&1, i>>2) of the atlas (passes/voxel_mip/voxel_mip.cpp). The value for
// direction D = the mean over the 4 child pairs along D's axis of the front-to-back
// composite (front = the child met first travelling along D).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(rgba16f, binding = 0) uniform readonly image3D u_src;   // the iso level 0, or the previous atlas level
layout(rgba16f, binding = 1) uniform writeonly image3D u_dst;  // atlas level (octant side u_size)

uniform int u_fromBase;  // 1: the source is the isotropic base (the same for every direction)
uniform int u_size;      // parent voxels per side at this level

ivec3 octant(int i) { return ivec3(i & 1, (i >> 1) & 1, i >> 2); }

vec4 over(vec4 front, vec4 back) { return front + (1.0 - front.a) * back; }

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, ivec3(u_size)))) return;
    for (int i = 0; i < 6; ++i) {
        ivec3 base = 2 * v + (u_fromBase == 1 ? ivec3(0) : octant(i) * (2 * u_size));
        vec4 c[8];
        for (int k = 0; k < 8; ++k) c[k] = imageLoad(u_src, base + ivec3(k & 1, (k >> 1) & 1, k >> 2));
        int axis = i >> 1;
        bool negative = (i & 1) == 1;
        // Child index bit for the axis: x → 1, y → 2, z → 4.
        int bit = 1 << axis;
        vec4 sum = vec4(0.0);
        for (int k = 0; k < 8; ++k) {
            if ((k & bit) != 0) continue;          // k = the low child of a pair
            vec4 lo = c[k], hi = c[k | bit];
            sum += negative ? over(hi, lo) : over(lo, hi);
        }
        imageStore(u_dst, v + octant(i) * u_size, sum * 0.25);
    }
}
