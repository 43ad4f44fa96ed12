// The box's walls as voxelize keeps them (passes/voxelize/voxelize.cpp, keep_static):
// rasterized once, each of their fragments is recorded here with what its lamp light
// depends on, and every frame static_light.comp lights the records again and adds that
// light to their voxels. Everything else a wall's fragment adds (its count, albedo,
// normal, emission) is in the static sums the frame's sums start from.
struct StaticFragment {
    vec4 world;   // xyz: the fragment's point; w: the lamp's unshadowed irradiance there, red
    vec4 normal;  // xyz: its unit normal; w: the irradiance, green
    vec4 albedo;  // rgb; a: the irradiance, blue (surface.glsl lampIrradiance: only the
                  // shadow changes from frame to frame)
    ivec4 voxel;  // xyz: the first voxel of its depth span; w: axis | voxels in the span << 2
};
layout(std430, binding = 3) buffer StaticFragments {
    uint u_recorded;  // fragments recorded (may exceed u_capacity: the pass then grows the buffer)
    uint u_capacity;
    uint u_unused0, u_unused1;
    StaticFragment u_fragments[];
};
