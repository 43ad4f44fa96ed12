// The instance buffer of drawScene() (kiln/scene_view.hpp GpuInstance). Readable from
// any stage, e.g. a fragment shader given the instance index as a flat varying.
struct KilnInstance {
    mat4 model;
    vec4 albedo;    // rgb, a = material (0 plain, 1 wood grain)
    vec4 emissive;  // rgb radiance, a = highlight
};
layout(std430, binding = 0) readonly buffer KilnInstances { KilnInstance kiln_instances[]; };

// Marbles, fireballs and particles are unit spheres placed by model = translate(centre)
// × scale(radius) (host/scene/scene_renderer.cpp).
vec3 kilnSphereCentre(KilnInstance inst) { return inst.model[3].xyz; }
float kilnSphereRadius(KilnInstance inst) { return length(inst.model[0].xyz); }
