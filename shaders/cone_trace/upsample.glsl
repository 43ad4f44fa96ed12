// Shared by the trace (cone_trace.frag) and the upsample (upsample.frag): which
// G-buffer texel a strided sample traced, and world positions from the depth buffer.
// Needs common/frame.glsl.

// Sample ij of a stride-s trace is the G-buffer texel s·ij + s/2 (the block's centre,
// rounded down), clamped to the image.
ivec2 traceTexel(ivec2 ij, int stride) {
    return min(ij * stride + stride / 2, ivec2(u_outputSize.xy) - 1);
}

vec3 worldAtTexel(sampler2D depthMap, ivec2 px) {
    float depth = texelFetch(depthMap, px, 0).r;
    vec2 ndc = (vec2(px) + 0.5) * u_outputSize.zw * 2.0 - 1.0;
    vec4 w = u_invViewProj * vec4(ndc, depth * 2.0 - 1.0, 1.0);
    return w.xyz / w.w;
}
