#version 450 core
// The debug view's texture display (host/app/texture_viewer.cpp): one texel per
// u_zoom screen pixels, nearest-neighbour (texelFetch), so what is drawn is what the
// value readout reports. Channel selection, a range remap, false colour for one
// channel, depth linearised with the producing camera's planes, a mip level, a slice
// of a 3D texture, and a checkerboard under alpha.
// KILN_DISPLAY_PLAIN 1: the variant for a float 2D texture shown as it is (its RGB,
// mip 0, no tonemap, checkerboard, legend or depth): the window's main image every
// frame. The general shader's branches on uniforms cost llvmpipe every pixel whichever
// way they go.
#ifndef KILN_DISPLAY_PLAIN
#define KILN_DISPLAY_PLAIN 0
#endif
#include "common/tonemap.glsl"

out vec4 o_color;
layout(binding = 0) uniform sampler2D u_tex2d;
layout(binding = 1) uniform sampler3D u_tex3d;
layout(binding = 2) uniform usampler2D u_utex2d;   // R32UI (voxel counts, sums)
layout(binding = 3) uniform usampler3D u_utex3d;
uniform int u_kind;          // 0 float 2D, 1 float 3D, 2 uint 2D, 3 uint 3D
uniform int u_channel;       // 0 RGB, 1 R, 2 G, 3 B, 4 A
uniform vec2 u_range;        // shown value v maps to (v - x) / (y - x)
uniform bool u_falseColor;   // one channel through the turbo map
uniform vec2 u_depthPlanes;  // near, far (> 0: linearise; shown in metres)
uniform int u_mip;
uniform int u_slice;         // 3D: texel index along u_axis
uniform int u_axis;          // 3D: 0 x, 1 y, 2 z
uniform bool u_checker;      // blend over a checkerboard by alpha
uniform bool u_tonemap;      // radiance: ACES + gamma 2.2 as composite shows it, then the range
// Screen → texel: texel = (gl_FragCoord.xy - u_canvasOrigin - u_canvasSize / 2) / u_zoom + u_center
// (TextureViewer::texelAt is the same mapping for the cursor).
uniform vec2 u_canvasOrigin;
uniform vec2 u_canvasSize;
uniform vec2 u_center;       // texel-space point at the canvas centre
uniform float u_zoom;        // screen pixels per texel

// Turbo (Google, 2019), polynomial fit by Ruofei Du: perceptually ordered, no black.
vec3 turbo(float x) {
    x = clamp(x, 0.0, 1.0);
    const vec4 kR4 = vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234);
    const vec4 kG4 = vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333);
    const vec4 kB4 = vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771);
    const vec2 kR2 = vec2(-152.94239396, 59.28637943);
    const vec2 kG2 = vec2(4.27729857, 2.82956604);
    const vec2 kB2 = vec2(-89.90310912, 27.34824973);
    vec4 v4 = vec4(1.0, x, x * x, x * x * x);
    vec2 v2 = v4.zw * v4.z;
    return vec3(dot(v4, kR4) + dot(v2, kR2), dot(v4, kG4) + dot(v2, kG2), dot(v4, kB4) + dot(v2, kB2));
}

ivec3 levelSize() {
    if (u_kind == 0) return ivec3(textureSize(u_tex2d, u_mip), 1);
    if (u_kind == 1) return textureSize(u_tex3d, u_mip);
    if (u_kind == 2) return ivec3(textureSize(u_utex2d, u_mip), 1);
    return textureSize(u_utex3d, u_mip);
}

uniform float u_legend;       // > 0: a strip this many pixels tall along the canvas's bottom
                              // shows the map from the range's low end (left) to its high end

void main() {
#if KILN_DISPLAY_PLAIN
    vec2 t = (gl_FragCoord.xy - u_canvasOrigin - u_canvasSize * 0.5) / u_zoom + u_center;
    ivec2 texel = ivec2(floor(t));
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, textureSize(u_tex2d, 0)))) {
        o_color = vec4(0.08, 0.08, 0.09, 1.0);
        return;
    }
    vec4 v = texelFetch(u_tex2d, texel, 0);
    vec3 c = clamp((v.rgb - u_range.x) / max(u_range.y - u_range.x, 1e-20), 0.0, 1.0);
    if (any(isnan(v)) || any(isinf(v))) c = vec3(1.0, 0.0, 1.0);
    o_color = vec4(c, 1.0);
#else
    // The legend: the same map the texels go through, so it cannot disagree with them.
    if (gl_FragCoord.y - u_canvasOrigin.y < u_legend) {
        float x = (gl_FragCoord.x - u_canvasOrigin.x) / max(u_canvasSize.x - 1.0, 1.0);
        o_color = vec4(u_falseColor ? turbo(x) : vec3(x), 1.0);
        return;
    }
    vec2 t = (gl_FragCoord.xy - u_canvasOrigin - u_canvasSize * 0.5) / u_zoom + u_center;
    ivec3 size = levelSize();
    ivec2 planeSize = u_kind == 1 || u_kind == 3 ? (u_axis == 0 ? size.yz : u_axis == 1 ? size.xz : size.xy) : size.xy;
    ivec2 texel = ivec2(floor(t));
    // Outside the texture: a dark backdrop, so its edge is visible at any zoom.
    if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, planeSize))) {
        o_color = vec4(0.08, 0.08, 0.09, 1.0);
        return;
    }
    ivec3 p3 = u_axis == 0 ? ivec3(u_slice, texel) : u_axis == 1 ? ivec3(texel.x, u_slice, texel.y) : ivec3(texel, u_slice);
    vec4 v;
    if (u_kind == 0) v = texelFetch(u_tex2d, texel, u_mip);
    else if (u_kind == 1) v = texelFetch(u_tex3d, p3, u_mip);
    else if (u_kind == 2) v = vec4(texelFetch(u_utex2d, texel, u_mip));
    else v = vec4(texelFetch(u_utex3d, p3, u_mip));

    if (u_depthPlanes.x > 0.0) {
        float n = u_depthPlanes.x, f = u_depthPlanes.y, z = v.r * 2.0 - 1.0;
        v = vec4(vec3(2.0 * n * f / (f + n - z * (f - n))), 1.0);
    }
    float span = max(u_range.y - u_range.x, 1e-20);
    vec3 c;
    if (u_channel == 0) {
        c = ((u_tonemap ? displayEncode(v.rgb, kTonemapAces, 2.2) : v.rgb) - u_range.x) / span;
    } else {
        float s = (v[u_channel - 1] - u_range.x) / span;
        c = u_falseColor ? turbo(s) : vec3(s);
    }
    c = clamp(c, 0.0, 1.0);
    if (u_checker) {
        vec2 cell = floor((gl_FragCoord.xy - u_canvasOrigin) / 8.0);
        vec3 board = vec3(mod(cell.x + cell.y, 2.0) < 1.0 ? 0.35 : 0.6);
        c = mix(board, c, clamp(v.a, 0.0, 1.0));
    }
    // NaN/Inf stand out in magenta whatever the range.
    if (any(isnan(v)) || any(isinf(v))) c = vec3(1.0, 0.0, 1.0);
    o_color = vec4(c, 1.0);
#endif
}
