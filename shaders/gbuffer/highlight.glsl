// The emission a G-buffer surface writes: the instance's, and a glow on the picked one
// (GpuInstance::emissive: rgb radiance, a = highlight 0/1).
vec3 emissionOf(vec4 instanceEmissive) {
    return instanceEmissive.rgb + (instanceEmissive.a > 0.5 ? vec3(0.25, 0.2, 0.05) : vec3(0.0));
}
