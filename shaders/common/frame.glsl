// The per-frame uniforms the host binds for every pass (kiln/scene_view.hpp GpuFrame).
layout(std140, binding = 0) uniform KilnFrame {
    mat4 u_view;
    mat4 u_proj;
    mat4 u_viewProj;
    mat4 u_invViewProj;
    vec4 u_cameraPos;    // xyz
    vec4 u_lightPos;     // xyz = lamp centre, w = lamp radius
    vec4 u_lightColor;   // rgb × intensity, w = intensity
    vec4 u_outputSize;   // w, h, 1/w, 1/h
    vec4 u_time;         // seconds, dt, frame index
    vec4 u_woodLight;    // the floor's wood (scene file box.floor_wood): rgb, w = rings per metre
    vec4 u_woodDark;     // rgb
    vec4 u_tumblerShape; // round cone: b, t, α (rad), y_t (upper centre above the lower)
    uvec4 u_boxWalls;    // x: faces of [-1,1]³ with a wall, bit 2a: −axis a, 2a+1: +axis a
};
