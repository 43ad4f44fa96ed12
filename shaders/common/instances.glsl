// The instance buffer of drawScene() (kiln/scene_view.hpp GpuInstance). Readable from
// any stage, e.g. a fragment shader given the instance index as a flat varying.
struct KilnInstance {
    mat4 model;
    vec4 albedo;    // rgb, a = material (0 plain, 1 wood grain)
    vec4 emissive;  // rgb radiance, a = highlight
};
layout(std430, binding = 0) readonly buffer KilnInstances { KilnInstance kiln_instances[]; };
