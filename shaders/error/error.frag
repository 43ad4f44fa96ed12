#version 450 core
#include "common/luminance.glsl"
#include "common/tonemap.glsl"

in vec2 v_uv;
layout(location = 0) out vec4 o_color;

layout(binding = 0) uniform sampler2D u_image;
layout(binding = 1) uniform sampler2D u_reference;
uniform int u_mode;    // 0 relative (false colour), 1 signed, 2 split
uniform float u_scale;
uniform float u_split;
uniform float u_legendPx;  // the legend strip's height in pixels (0: none)

// Black → blue → green → yellow → white over t ∈ [0, 1].
vec3 falseColour(float t) {
    t = clamp(t, 0.0, 1.0);
    vec3 c = mix(vec3(0.0), vec3(0.1, 0.2, 1.0), smoothstep(0.0, 0.25, t));
    c = mix(c, vec3(0.1, 0.9, 0.2), smoothstep(0.25, 0.5, t));
    c = mix(c, vec3(1.0, 0.9, 0.1), smoothstep(0.5, 0.75, t));
    return mix(c, vec3(1.0), smoothstep(0.75, 1.0, t));
}

void main() {
    vec3 image = texture(u_image, v_uv).rgb, reference = texture(u_reference, v_uv).rgb;
    if (u_mode == 2) {
        vec3 shown = v_uv.x < u_split ? image : reference;
        float edge = abs(v_uv.x - u_split) < 0.002 ? 1.0 : 0.0;
        o_color = vec4(mix(displayEncode(shown, kTonemapAces, 2.2), vec3(1.0), edge), 1.0);
        return;
    }
    if (u_mode != 2 && gl_FragCoord.y < u_legendPx) {
        // The map itself, left to right; dark ticks in the strip's upper half at each
        // decade (relative) or at 0 (signed).
        float t = v_uv.x, px = 1.0 / fwidth(v_uv.x);
        vec3 c = u_mode == 0 ? falseColour(t) : (t > 0.5 ? vec3(1.0, 2.0 - 2.0 * t, 2.0 - 2.0 * t) : vec3(2.0 * t, 2.0 * t, 1.0));
        float ticks = u_mode == 0 ? 4.0 : 2.0;
        bool tick = abs(t * ticks - round(t * ticks)) * px / ticks < 1.0 && gl_FragCoord.y > 0.5 * u_legendPx;
        o_color = vec4(tick ? vec3(0.0) : c, 1.0);
        return;
    }
    vec3 d = image - reference;
    if (u_mode == 1) {
        float s = kilnLuminance(d) / u_scale;
        o_color = vec4(s > 0.0 ? vec3(1.0, 1.0 - s, 1.0 - s) : vec3(1.0 + s, 1.0 + s, 1.0), 1.0);
        o_color.rgb = clamp(o_color.rgb, 0.0, 1.0);
        return;
    }
    vec3 rel = d * d / (reference * reference + 0.01);
    float e = (rel.r + rel.g + rel.b) / 3.0;
    o_color = vec4(falseColour((log(max(e, 1e-4)) / log(10.0) + 4.0) / 4.0), 1.0);  // 1e-4 … 1
}
