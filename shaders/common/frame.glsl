// The per-frame uniforms the host binds for every pass (kiln/scene_view.hpp GpuFrame).
const int kMaxPunctualLights = 16;  // kiln/scene_view.hpp
struct KilnPunctualLight {
    vec4 position;   // xyz, w = type (0 directional, 1 point, 2 spot)
    vec4 direction;  // xyz unit, where it shines; w = range (0: infinite)
    vec4 color;      // rgb × intensity; w = shadow atlas tile (-1: none)
    vec4 cone;       // spot: x cos(outer), y 1 / (cos(inner) − cos(outer))
    mat4 shadowViewProj;
};
layout(std140, binding = 0) uniform KilnFrame {
    mat4 u_view;
    mat4 u_proj;
    mat4 u_viewProj;
    mat4 u_invViewProj;
    vec4 u_cameraPos;    // xyz
    vec4 u_lightPos;     // the spherical area light: xyz centre, w radius
    vec4 u_lightColor;   // rgb × intensity, w = intensity
    vec4 u_outputSize;   // w, h, 1/w, 1/h
    vec4 u_time;         // seconds, dt, frame index
    vec4 u_ringsLight;   // the procedural rings material: rgb, w = rings per metre
    vec4 u_ringsDark;    // rgb
    vec4 u_roundCone;    // the round cones' shape: b, t, α (rad), y_t (upper centre above the lower)
    uvec4 u_closedFaces; // x: the voxel volume's faces with a wall, bit 2a: −axis a, 2a+1: +axis a
    vec4 u_sceneMin;     // the scene's bounds, world space
    vec4 u_sceneMax;
    vec4 u_voxelVolume;  // the voxel passes' box: xyz centre, w half its longest side (world)
    vec4 u_voxelExtent;  // xyz: the box's half extent per axis ÷ u_voxelVolume.w (the longest 1)
    uvec4 u_punctualCount;  // x: u_punctual[0 .. x) are lights
    KilnPunctualLight u_punctual[kMaxPunctualLights];
};

// The voxel volume: world space ↔ volume space (moved to the box's centre and divided
// by half its longest side: the box is [-e, e] with e = u_voxelExtent.xyz, one scale on
// every axis, where cones are traced) ↔ grid space (volume space ÷ e: the box as
// [-1,1]³, where the voxel passes rasterize and splat) ↔ texture space ([0,1]³). For a
// scene of [-1,1]³ every map is the identity, exactly.
vec3 kilnWorldToVolume(vec3 p) { return (p - u_voxelVolume.xyz) / u_voxelVolume.w; }
vec3 kilnVolumeToWorld(vec3 q) { return q * u_voxelVolume.w + u_voxelVolume.xyz; }
vec3 kilnVolumeToGrid(vec3 q) { return q / u_voxelExtent.xyz; }
vec3 kilnWorldToGrid(vec3 p) { return kilnVolumeToGrid(kilnWorldToVolume(p)); }
vec3 kilnGridToWorld(vec3 g) { return kilnVolumeToWorld(g * u_voxelExtent.xyz); }
vec3 kilnVolumeTexcoord(vec3 p) { return kilnWorldToGrid(p) * 0.5 + 0.5; }
// A voxel's side in world units along the longest axis of a grid of `res` there (the
// others' are within √2 of it: kiln::voxelGridShift).
float kilnVoxelSize(float res) { return 2.0 * u_voxelVolume.w / res; }
// A cell's sides in world units on a grid of `grid` cells per axis.
vec3 kilnCellSize(vec3 grid) { return 2.0 * u_voxelVolume.w * u_voxelExtent.xyz / grid; }
