// The instance buffer of drawScene() (kiln/scene_view.hpp GpuInstance). Readable from
// any stage, e.g. a fragment shader given the instance index as a flat varying.
struct KilnInstance {
    mat4 model;
    vec4 albedo;     // rgb mean albedo, a = material (0 plain, 1 wood grain)
    vec4 emissive;   // rgb mean radiance, a = highlight
    vec4 baseColor;  // textured: × the base colour texture (rgb albedo, a coverage)
    vec4 emission;   // textured: × the emissive texture (radiance)
    vec4 layers;     // x base colour, y emissive, z normal map layer (-1 none), w alpha cutoff (0 opaque)
};
layout(std430, binding = 0) readonly buffer KilnInstances { KilnInstance kiln_instances[]; };

// Marbles, fireballs and particles are unit spheres placed by model = translate(centre)
// × scale(radius) (host/scene/scene_renderer.cpp).
vec3 kilnSphereCentre(KilnInstance inst) { return inst.model[3].xyz; }
float kilnSphereRadius(KilnInstance inst) { return length(inst.model[0].xyz); }
