#version 450 core
// Per-pixel diffuse cone tracing: every pixel (stride 1), or one pixel per stride×stride
// block: then sample ij traces the G-buffer texel stride·ij + stride/2 (traceTexel in
// upsample.glsl) and also writes that surface's plane for upsample.frag. Alpha: the
// cone-traced ambient visibility, or (cone_trace.lamp) the lamp's projected solid angle,
// or (`lamp_transmittance` bound) the fraction of the lamp seen past the fire.
// A compute shader, one invocation a sample, over the rectangle u_rect: llvmpipe shades
// a framebuffer in tiles of 64 × 64 pixels, one thread a tile, so a strided trace
// drawn as fragments (64 × 64 samples at 720²) ran on one of the machine's threads,
// where its workgroups spread over all of them.
#include "common/frame.glsl"
#include "trace.glsl"
#if KILN_LAMP_IN_ALPHA
#include "common/light.glsl"
#endif
#if KILN_HAS_LAMP_TRANSMITTANCE
// voxelize.lamp_transmittance: the fraction of the lamp seen past the fire (common/fire.glsl).
layout(binding = 10) uniform sampler3D u_lampTransmittance;
#endif
#include "upsample.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D u_normal;
layout(binding = 1) uniform sampler2D u_depth;
uniform int u_stride;
uniform ivec4 u_rect;  // the samples to trace: x, y, width, height

// `samples` (strided) or `indirect` (stride 1), and KILN_STRIDED each sample's surface,
// xyz = unit normal, w = n·p; 0 off geometry.
layout(rgba16f, binding = 0) uniform writeonly image2D u_traced;
#if KILN_STRIDED
layout(rgba16f, binding = 1) uniform writeonly image2D u_planes;
#endif

#if KILN_REUSE
// Temporal reuse (cone_trace.reuse_frames > 1, strided traces only). A sample within
// u_reuseTolerance of where last frame's nearest sample was traced, with a normal
// within ~6° of its, keeps that sample's light for up to u_reuseFrames − 1 frames
// (a distance, not a plane test: on a plane seen at a grazing angle, the nearest
// sample on screen can be tens of centimetres away on it); tiles of 8×8 samples
// retrace in turn (one in u_reuseFrames a frame), so a static surface's light is never
// older than that. Whole tiles skip the trace together: llvmpipe leaves a loop once no
// lane needs it, but runs an `if` body for every lane.
layout(binding = 7) uniform sampler2D u_history;        // last frame's samples
layout(binding = 8) uniform sampler2D u_historyPlanes;  // their surfaces
layout(binding = 9) uniform sampler2D u_historyAges;    // frames each had been kept, and where it was traced
uniform mat4 u_prevViewProj;
uniform int u_reuseFrames;
uniform int u_frame;             // which tiles retrace this frame
uniform float u_reuseTolerance;  // world units
// x: frames this sample's light has been kept; yzw: the point traced.
layout(rgba32f, binding = 2) uniform writeonly image2D u_ages;

// Last frame's sample nearest the point p (h, and its age and traced point in kept),
// and whether its surface is p's.
bool reusable(vec3 p, vec3 n, out ivec2 h, out vec4 kept) {
    vec4 clip = u_prevViewProj * vec4(p, 1.0);
    vec2 px = (clip.xy / max(clip.w, 1e-6) * 0.5 + 0.5) * u_outputSize.xy;  // last frame's pixel coordinates
    // Sample h traced texel stride·h + stride/2, centred at that + 0.5.
    h = ivec2(floor((px - 0.5 - float(u_stride / 2)) / float(u_stride) + 0.5));
    ivec2 size = textureSize(u_history, 0);
    bool inside = clip.w > 0.0 && all(greaterThanEqual(h, ivec2(0))) && all(lessThan(h, size));
    h = clamp(h, ivec2(0), size - 1);
    kept = texelFetch(u_historyAges, h, 0);
    return inside && dot(texelFetch(u_historyPlanes, h, 0).xyz, n) > 0.995 && distance(kept.yzw, p) < u_reuseTolerance;
}
#endif

void store(ivec2 ij, vec4 indirect, vec4 plane) {
    imageStore(u_traced, ij, indirect);
#if KILN_STRIDED
    imageStore(u_planes, ij, plane);
#endif
}

void main() {
    if (any(greaterThanEqual(ivec2(gl_GlobalInvocationID.xy), u_rect.zw))) return;
    ivec2 ij = u_rect.xy + ivec2(gl_GlobalInvocationID.xy);
    ivec2 src = traceTexel(ij, u_stride);
    vec4 n4 = texelFetch(u_normal, src, 0);
    if (n4.w < 0.5) {
        store(ij, vec4(0.0, 0.0, 0.0, 1.0), vec4(0.0));
#if KILN_REUSE
        imageStore(u_ages, ij, vec4(0.0, vec3(1e4)));  // off geometry: nowhere
#endif
        return;
    }
    vec3 p = worldAtTexel(u_depth, src);
    vec3 n = normalize(n4.xyz);
#if KILN_REUSE
    ivec2 h;
    vec4 kept;
    bool same = reusable(p, n, h, kept);
    float age = kept.x;
    ivec2 tile = ij / 8;
    bool due = (tile.x + 3 * tile.y + u_frame) % u_reuseFrames == 0;
    bool trace = due || !same || age >= float(u_reuseFrames - 1);
    vec4 indirect = texelFetch(u_history, h, 0);
    vec4 age4 = vec4(age + 1.0, kept.yzw);
    for (int k = trace ? 0 : 1; k < 1; ++k) {
#else
    vec4 indirect;
    {  // every sample traced (a loop around it, even a constant one, cost more)
#endif
        indirect = traceDiffuse(p, n);
#if KILN_LAMP_IN_ALPHA
        // The lamp's unshadowed irradiance ÷ its radiance (smooth on a surface, like the
        // indirect light): traced here at one pixel in stride², upsampled with it.
        indirect.a = lampProjectedSolidAngle(p, n);
#elif KILN_HAS_LAMP_TRANSMITTANCE
        indirect.a = textureLod(u_lampTransmittance, kilnVolumeTexcoord(p), 0.0).r;  // upsampled for composite
#endif
#if KILN_REUSE
        age4 = vec4(0.0, p);
#endif
    }
    // The plane's offset from the voxel volume's centre: half floats hold it to the
    // scene's scale wherever the scene lies (from the world origin, 40 m away they
    // held it to 3 cm).
    store(ij, indirect, vec4(n, dot(n, p - u_voxelVolume.xyz)));
#if KILN_REUSE
    imageStore(u_ages, ij, age4);
#endif
}
