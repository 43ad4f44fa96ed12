#version 450 core
// The brightest luminance of the input: each invocation scans a 4×4 tile, the group
// reduces in shared memory, one atomicMax per group. Non-negative floats order like
// their bit patterns, so the maximum is kept as uint bits.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_color;
layout(std430, binding = 1) buffer MaxLum { uint u_maxBits; };
shared float s_max[64];

void main() {
    ivec2 size = textureSize(u_color, 0);
    ivec2 base = ivec2(gl_GlobalInvocationID.xy) * 4;
    float m = 0.0;
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            ivec2 p = base + ivec2(x, y);
            if (all(lessThan(p, size))) {
                vec3 c = texelFetch(u_color, p, 0).rgb;
                float l = dot(c, vec3(0.2126, 0.7152, 0.0722));
                if (l > m) m = l;  // NaN never wins
            }
        }
    s_max[gl_LocalInvocationIndex] = m;
    barrier();
    for (uint s = 32u; s > 0u; s >>= 1) {
        if (gl_LocalInvocationIndex < s) s_max[gl_LocalInvocationIndex] = max(s_max[gl_LocalInvocationIndex], s_max[gl_LocalInvocationIndex + s]);
        barrier();
    }
    if (gl_LocalInvocationIndex == 0u) atomicMax(u_maxBits, floatBitsToUint(min(s_max[0], 65504.0)));
}
