#version 450 core
// Marks the tiles of the picture whose lamp light (composite's `direct`) an instance
// that changed since the pass's last run can have changed, and keeps this run's
// instances for the next. One invocation per instance from the first tumbler to the
// last fireball (the walls and the lamp changing redraw everything, composite.cpp; the
// particles write only their emission, which composite does not keep).
// An instance changes the G-buffer inside its box's screen rectangle, where it was and
// where it is. A shadow caster also changes the shadow map inside its box's rectangle in
// the map, and so the light of what lies in its shadow's pyramid (markShadow). A
// rectangle that reaches behind the camera or the lamp's eye marks everything.
#include "common/frame.glsl"
#include "common/shadow.glsl"
#include "common/instances.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 1) buffer PreviousInstances { KilnInstance previous[]; };
layout(std430, binding = 2) buffer TileMarks { uint tileMarks[]; };
// The boxes of the moved casters' shadow pyramids, for the receivers' pass to test
// (composite.cpp zeroes the count): a loop over every instance in each caster's
// invocation is dear with thousands of particles.
layout(std430, binding = 4) buffer ShadowPyramids { uint pyramidCount; vec4 pyramidBoxes[]; };
// KILN_PART 0: the shadow casters (tumblers, marbles), 1: the other instances (a
// caster's pyramid in the same program cost every invocation on llvmpipe, which runs
// a branch's both sides), 2: the receivers in the pyramids 0 recorded.
uniform uint u_from, u_to;        // the instances this dispatch compares: [u_from, u_to)
uniform uint u_end;               // the instances now end here (the first tumbler starts them)
uniform uint u_previousEnd;       // u_end at the last run
uniform uint u_tumblersEnd;       // the tumblers end here
uniform bool u_compare;           // false: no last run's instances to compare with, only keep these
uniform ivec2 u_tiles;            // tiles across and down
uniform int u_tileSize;
uniform float u_shadowReachTexels;  // how far from its point a pixel's filter reads the map
uniform vec2 u_shadowTexel;         // 1 / the map's size; 0: no map bound

void markPixels(vec2 lo, vec2 hi) {  // pixel coordinates, inclusive bounds grown by one
    ivec2 a = clamp(ivec2(floor(lo)) - 1, ivec2(0), u_tiles * u_tileSize - 1) / u_tileSize;
    ivec2 b = clamp(ivec2(ceil(hi)) + 1, ivec2(0), u_tiles * u_tileSize - 1) / u_tileSize;
    for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) tileMarks[y * u_tiles.x + x] = 1u;
}

void markEverything() { markPixels(vec2(0.0), vec2(u_tiles * u_tileSize)); }

// The rectangle [a, b] in normalized device coordinates that a world box's corners
// project to through `toClip`; false when one of them lies behind its eye.
bool projectBox(mat4 toClip, vec3 lo, vec3 hi, out vec2 a, out vec2 b) {
    a = vec2(1e30), b = vec2(-1e30);
    for (int i = 0; i < 8; ++i) {
        vec4 clip = toClip * vec4(mix(lo, hi, vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1)), 1.0);
        if (clip.w <= 1e-4) return false;
        a = min(a, clip.xy / clip.w), b = max(b, clip.xy / clip.w);
    }
    return true;
}

// The screen rectangle of a world box.
void markWorldBox(vec3 lo, vec3 hi) {
    vec2 a, b;
    if (!projectBox(u_viewProj, lo, hi, a, b)) { markEverything(); return; }
    markPixels((clamp(a, -1.0, 1.0) * 0.5 + 0.5) * u_outputSize.xy, (clamp(b, -1.0, 1.0) * 0.5 + 0.5) * u_outputSize.xy);
}

// An instance's box: a sphere's (marbles, fireballs: the unit sphere placed),
// or the tumbler's, its two balls' (its round cone is their convex hull: about its
// origin, the lower ball of radius b and the upper of radius t at y_t), 5 % wider for
// the mesh.
void instanceBox(KilnInstance inst, bool tumbler, out vec3 lo, out vec3 hi) {
    mat4 m = inst.model;
    float scale = max(length(m[0].xyz), max(length(m[1].xyz), length(m[2].xyz))) * 1.05;
    if (!tumbler) {
        lo = m[3].xyz - scale, hi = m[3].xyz + scale;
        return;
    }
    vec3 upper = (m * vec4(0.0, u_roundCone.w, 0.0, 1.0)).xyz;
    lo = min(m[3].xyz - scale * u_roundCone.x, upper - scale * u_roundCone.y);
    hi = max(m[3].xyz + scale * u_roundCone.x, upper + scale * u_roundCone.y);
}

// Where a caster's shadow can have changed: on what lies in the pyramid from the map's
// eye through the caster's rectangle in the map (grown by the filter's reach), from the
// caster's top down to the floor (nearer the lamp than the caster a depth test comes out
// lit either way). The walls there: for each wall, the pyramid's part within 1 cm of
// it, bounded by where its edges cross that slab and its corners inside it. The
// instances there, wherever they are: each one's own box, but those of no albedo (a
// burnt-out ball: no lamp light to change), in a second dispatch (KILN_PART 2) against
// the pyramids' boxes this one records. The dome, if the pyramid reaches it.
vec3 pyramid[8];  // corners: i & 3 the ray, i >> 2 top (0) or bottom (1)
const ivec2 kPyramidEdges[12] = ivec2[](ivec2(0, 1), ivec2(1, 3), ivec2(3, 2), ivec2(2, 0), ivec2(4, 5), ivec2(5, 7),
                                        ivec2(7, 6), ivec2(6, 4), ivec2(0, 4), ivec2(1, 5), ivec2(2, 6), ivec2(3, 7));

void markWallInPyramid(int axis, float side) {
    vec3 lo = vec3(1e30), hi = vec3(-1e30);
    const float slab = 0.01;
    for (int i = 0; i < 8; ++i)
        if (abs(pyramid[i][axis] - side) <= slab) lo = min(lo, pyramid[i]), hi = max(hi, pyramid[i]);
    for (int e = 0; e < 12; ++e) {
        vec3 p = pyramid[kPyramidEdges[e].x], q = pyramid[kPyramidEdges[e].y];
        for (int k = 0; k < 2; ++k) {
            float plane = side + (k == 0 ? -slab : slab);
            float t = (plane - p[axis]) / (q[axis] - p[axis]);
            if (q[axis] != p[axis] && t >= 0.0 && t <= 1.0) {
                vec3 c = mix(p, q, t);
                lo = min(lo, c), hi = max(hi, c);
            }
        }
    }
    lo = max(lo, vec3(-1.0 - slab)), hi = min(hi, vec3(1.0 + slab));  // the wall's extent
    if (all(lessThanEqual(lo, hi))) markWorldBox(lo, hi);
}

void markShadow(vec3 lo, vec3 hi) {
    mat4 toMap = lightViewProj();
    vec2 a, b;
    if (!projectBox(toMap, lo, hi, a, b)) { markEverything(); return; }
    vec2 reach = 2.0 * u_shadowReachTexels * u_shadowTexel;  // texels in the map's [-1, 1]
    a -= reach, b += reach;
    mat4 fromMap = inverse(toMap);
    vec3 eye = lightEye();
    // Receivers are offset 4 mm along their normal before the lookup (composite.frag).
    float top = hi.y + 0.01, bottom = -1.02;
    vec3 boxLo = vec3(1e30), boxHi = vec3(-1e30);
    for (int i = 0; i < 4; ++i) {
        vec4 q = fromMap * vec4(mix(a, b, vec2(i & 1, i >> 1)), 0.0, 1.0);
        vec3 dir = q.xyz / q.w - eye;
        if (dir.y >= -1e-6) { markEverything(); return; }
        for (int k = 0; k < 2; ++k) {
            vec3 p = eye + dir * (((k == 0 ? top : bottom) - eye.y) / dir.y);
            pyramid[i + 4 * k] = p;
            boxLo = min(boxLo, p), boxHi = max(boxHi, p);
        }
    }
    // The lamp's dome, where a caster reaches below its lowest point.
    if (top > u_lightPos.y - u_lightPos.w) markWorldBox(u_lightPos.xyz - u_lightPos.w, u_lightPos.xyz + u_lightPos.w);
    for (int wall = 0; wall < 6; ++wall)
        if ((u_closedFaces.x & (1u << wall)) != 0u) markWallInPyramid(wall >> 1, (wall & 1) == 0 ? -1.0 : 1.0);
    // The instances inside: each tests the recorded pyramids (KILN_PART 2).
    uint k = atomicAdd(pyramidCount, 1u);
    if (k < pyramidBoxes.length() / 2) pyramidBoxes[2u * k] = vec4(boxLo, 0.0), pyramidBoxes[2u * k + 1u] = vec4(boxHi, 0.0);
    else markEverything();
}

// One invocation a receiver: where its box meets a moved caster's pyramid, its box.
void markIfShadowed(uint r) {
    KilnInstance receiver = kiln_instances[r];
    if (receiver.albedo.rgb == vec3(0.0)) return;
    vec3 lo, hi;
    instanceBox(receiver, r < u_tumblersEnd, lo, hi);
    uint pyramids = min(pyramidCount, uint(pyramidBoxes.length() / 2));
    // Its pixels look the map up 4 mm off its surface (composite.frag).
    for (uint k = 0u; k < pyramids; ++k)
        if (all(lessThanEqual(max(lo - 0.01, pyramidBoxes[2u * k].xyz), min(hi + 0.01, pyramidBoxes[2u * k + 1u].xyz)))) {
            markWorldBox(lo, hi);
            return;
        }
}

bool sameInstance(KilnInstance x, KilnInstance y) {
    return x.model == y.model && x.albedo == y.albedo && x.emissive == y.emissive;
}

void main() {
    uint i = u_from + gl_GlobalInvocationID.x;
#if KILN_PART == 2
    if (i < u_end) markIfShadowed(i);
#else
    bool now = i < u_end, before = i < u_previousEnd;  // fireballs come and go at the end
    if (i >= u_to || (!now && !before)) return;
    if (u_compare && !(now && before && sameInstance(kiln_instances[i], previous[i]))) {
        for (int k = 0; k < 2; ++k) {
            if (!(k == 0 ? before : now)) continue;
            vec3 lo, hi;
            instanceBox(k == 0 ? previous[i] : kiln_instances[i], i < u_tumblersEnd, lo, hi);
            markWorldBox(lo, hi);
#if KILN_PART == 0
            if (u_shadowTexel.x > 0.0) markShadow(lo, hi);
#endif
        }
    }
    if (now) previous[i] = kiln_instances[i];
#endif
}
