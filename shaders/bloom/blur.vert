#version 450 core
// The rectangle round every texel bloom/bright.comp found above the threshold, grown by
// the blur's reach (KILN_BLUR_RADIUS texels each way: the horizontal pass's light
// spreads that far across, the vertical pass's that far again down): outside it the
// blurred light is exactly zero, and the pass has cleared its target to black, so only
// the rectangle is drawn (6 vertices, no buffers; the emitters on screen — the dome, the
// fireballs and their sparks — fill about a quarter of the picture). Collapsed to a
// point when nothing passed. Read here once a vertex: read once a fragment, the flag
// cost a noticeable share of the pass on llvmpipe.
layout(std430, binding = 1) readonly buffer AnyBright { uint u_anyBright, u_minX, u_minY, u_maxX, u_maxY; };
uniform vec2 u_targetSize;  // texels of the target, the bright pass's size

const vec2 kCorners[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(0, 1), vec2(0, 1), vec2(1, 0), vec2(1, 1));

void main() {
    if (u_anyBright == 0u) {
        gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec2 lo = max(vec2(u_minX, u_minY) - float(KILN_BLUR_RADIUS), vec2(0.0));
    vec2 hi = min(vec2(u_maxX, u_maxY) + 1.0 + float(KILN_BLUR_RADIUS), u_targetSize);
    gl_Position = vec4(mix(lo, hi, kCorners[gl_VertexID]) / u_targetSize * 2.0 - 1.0, 0.0, 1.0);
}
