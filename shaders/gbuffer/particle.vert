#version 450 core
// Particles as points: one vertex per particle (instances [u_first, u_first + count) of
// the scene's instance buffer), sized to the sphere's projected diameter;
// particle.frag makes each a glowing disc.
#include "common/frame.glsl"
#include "common/instances.glsl"

uniform uint u_first;
// The emission as a flat varying (read once a point, not once a fragment: gbuffer.vert).
flat out vec3 v_emissive;

void main() {
    KilnInstance inst = kiln_instances[u_first + uint(gl_VertexID)];
    float radius = kilnSphereRadius(inst);
    gl_Position = u_viewProj * vec4(kilnSphereCentre(inst), 1.0);
    // Diameter in pixels: 2r · (focal length in pixels) / depth.
    gl_PointSize = max(2.0 * radius * u_proj[1][1] * 0.5 * u_outputSize.y / max(gl_Position.w, 1e-4), 1.0);
    v_emissive = inst.emissive.rgb;
}
