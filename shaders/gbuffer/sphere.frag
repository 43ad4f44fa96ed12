#version 450 core
// A sphere traced through the pixel's centre (sphere.vert): its nearest hit's depth,
// normal, the instance's albedo and emission; no hit, no fragment. Exact where a mesh
// is a polygon: the silhouette, the normal, the depth.
#include "common/frame.glsl"
#include "gbuffer/highlight.glsl"

flat in vec4 v_sphere;
noperspective in vec3 v_ray;  // one metre of view depth a unit (sphere.vert)
flat in vec4 v_albedo;
flat in vec4 v_emissive;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_emissive;

void main() {
    // The ray's closest approach to the centre, then back along it to the surface (no
    // difference of two large squares: the radius is small beside the distance).
    vec3 toCentre = v_sphere.xyz - u_cameraPos.xyz;
    float lengthSquared = dot(v_ray, v_ray);
    float along = dot(toCentre, v_ray) / lengthSquared;
    vec3 offAxis = toCentre - along * v_ray;
    float h = v_sphere.w * v_sphere.w - dot(offAxis, offAxis);
    if (h < 0.0 || along <= 0.0) discard;
    float depth = along - sqrt(h / lengthSquared);  // the view depth of the hit, in metres
    vec3 hit = u_cameraPos.xyz + depth * v_ray;
    // Its window depth: z_ndc = (P22 z + P32) / −z at z = −depth.
    gl_FragDepth = 0.5 * (u_proj[3][2] / depth - u_proj[2][2]) + 0.5;
    vec3 emissive = emissionOf(v_emissive);
    o_albedo = vec4(v_albedo.rgb, 1.0);
    o_normal = vec4((hit - v_sphere.xyz) / v_sphere.w, 1.0);
    o_emissive = vec4(emissive, 1.0);
}
