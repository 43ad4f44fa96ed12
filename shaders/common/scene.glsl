// Vertex inputs of drawScene() plus the frame uniforms and the instance buffer.
// Include from a vertex shader that draws the scene's meshes.
#include "frame.glsl"
#include "instances.glsl"

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in uint a_instance;   // index into kiln_instances

KilnInstance kilnInstance() { return kiln_instances[a_instance]; }

// Every model matrix is a similarity (rotation, translation, uniform scale; see
// host/scene/scene_renderer.cpp), so mat3(model) maps a normal up to its length: no
// per-vertex inverse (on llvmpipe the vertex stage runs on the CPU). Normalize after
// interpolation.
vec3 kilnWorldNormal(KilnInstance inst, vec3 n) { return mat3(inst.model) * n; }
