// The lamp's light through the fire (voxelize's fire_cover on): the fraction of the lamp
// a point sees past the fireballs and their particles, which the shadow map (drawn
// without them, from one point of the lamp) cannot hide it by. The lamp is large, so
// it changes slowly away from the fire: voxelize evaluates it on a coarser grid than its
// voxels (transmittance_resolution; voxelize/fire_transmittance.comp, `lamp_transmittance`), which
// the voxels' lamp light (voxelize/resolve.comp) and cone_trace's traced pixels (alpha,
// for composite's lamp_through_fire) look up. For the particles' cone the lamp, as p
// sees it, is a disc of its apparent area: |d.y| of its rim's disc (from below) plus the
// rest of the circular segment it shows from the side, round the direction d to the
// shadow map's eye (the centroid of its cap; common/shadow.glsl). Needs
// common/shadow.glsl.
//   fireballs  each a disc of angular radius asin(r / distance) against 16 cells of the
//              lamp's cap (each a disc of its projected solid angle, weighted by its
//              share of the irradiance): the part of each cell it overlaps is hidden.
//              Few and about a voxel large: near exact here, where a voxel volume blurs
//              them (one 10 cm fireball under the lamp, through a cover volume, hid
//              far less of it than in fact: tests/gi/test_gi.cpp).
//   particles  hundreds, a third of a voxel: voxelize.fire holds their cross-sections per
//              voxel face (μ·h, mipped: the mean). One cone from p to the lamp, as wide
//              at each distance as the lamp's disc seen from p, sums the optical depth
//              (each sample the mean over the cone's width there), T = exp(−Σ μ·Δt):
//              the particles as a random medium. Steps half the cone's diameter apart.
// The fractions each let through multiply (the spheres lie independently).
layout(binding = 10) uniform sampler3D u_fire;

// The fireballs that may stand between p and the lamp, and fireball i of them (xyz its
// centre, w its radius; at most kFireMaxFireballs). The includer defines them
// (voxelize/fire_transmittance.comp: a list per workgroup in shared memory; every
// fireball read from the instance buffer in every loop was far dearer with many fireballs).
int fireballCount();
vec4 fireballSphere(int i);

const int kFireMaxSteps = 48;
const int kFireLampCells = 16;
const int kFireMaxFireballs = 64;

// The area two discs of radii a and b, their centres c apart, share.
float discOverlap(float a, float b, float c) {
    if (c >= a + b) return 0.0;
    if (c <= abs(a - b)) return 3.14159265 * min(a, b) * min(a, b);
    float lens = sqrt(max((-c + a + b) * (c + a - b) * (c - a + b) * (c + a + b), 0.0));
    return a * a * acos(clamp((c * c + a * a - b * b) / (2.0 * c * a), -1.0, 1.0)) +
           b * b * acos(clamp((c * c + b * b - a * a) / (2.0 * c * b), -1.0, 1.0)) - 0.5 * lens;
}

float fireTransmittance(vec3 p, vec3 n) {
    ivec3 cells = textureSize(u_fire, 0);
    float voxel = kilnVoxelSize(float(max(cells.x, max(cells.y, cells.z))));  // along the longest side
    vec3 origin = p + n * (0.5 * voxel);
    vec3 toLamp = lightEye() - origin;
    float dist = length(toLamp);
    vec3 dir = toLamp / max(dist, 1e-6);
    // The light leaves the emitter's surface: the march ends where the ray enters the
    // lamp's ball, not at the eye inside it (fire beside the dome is not in front of it).
    vec3 toCentre = u_lightPos.xyz - origin;
    float along = dot(toCentre, dir);
    float end = along - sqrt(max(along * along - dot(toCentre, toCentre) + u_lightPos.w * u_lightPos.w, 0.0));
    end = clamp(end, 0.0, dist);
    // The lamp's disc: its area as p sees it (height `below` under the ceiling).
    float radius = u_lightPos.w, below = clamp(kCeilingY - (u_lightPos.y - radius), 0.0, 2.0 * radius);
    float rim2 = max(radius * radius - (u_lightPos.y - kCeilingY) * (u_lightPos.y - kCeilingY), 0.0);
    float chord = radius - below;  // the ceiling's signed distance below the ball's centre
    float side = radius * radius * acos(clamp(chord / radius, -1.0, 1.0)) - chord * sqrt(rim2);
    float area = abs(dir.y) * 3.14159265 * rim2 + sqrt(max(1.0 - dir.y * dir.y, 0.0)) * side;
    float lampRadius = sqrt(area / 3.14159265);
    float spread = 2.0 * lampRadius / max(dist, 1e-6);  // the cone's width per metre from p

    // The fireballs against kFireLampCells equal-area cells of the cap (golden-angle
    // spiral, as light.glsl's quadrature), each weighted by its share of the lamp's
    // irradiance at p (cos θ_p cos θ_q / d²) and seen as a disc of its projected solid
    // angle: what each fireball's disc overlaps of each cell's is hidden. The cells give
    // the lamp its shape (a squat dome seen from the side is short, not a disc). The
    // first 64 fireballs (kiln-bench-skip's busiest scene has 50; beyond, the rest hide
    // nothing). Only those whose disc meets the lamp's ball's (a bound on the cap's) take
    // part; none: nothing to do (loops whose count is 0 for every lane cost nothing on
    // llvmpipe, where an `if` body runs for every lane).
    // The test, without inverse trigonometry: the angle between the directions to the
    // ball and the fireball below the sum of their angular radii, cos(apart) > cos(α + β).
    float toLampBall = max(length(toCentre), 1e-6);
    float sinLamp = min(radius / toLampBall, 1.0), cosLamp = sqrt(1.0 - sinLamp * sinLamp);
    vec3 towardsBall = toCentre / toLampBall;
    uvec2 inFront = uvec2(0u);  // bit i of word i / 32: fireball i may hide part of the lamp
    for (int i = 0; i < min(fireballCount(), kFireMaxFireballs); ++i) {
        vec4 ball = fireballSphere(i);
        vec3 toBall = ball.xyz - origin;
        float b = max(length(toBall), 1e-6), r = ball.w;
        float sinBall = min(r / b, 1.0), cosBall = sqrt(1.0 - sinBall * sinBall);
        float cosSum = cosLamp * cosBall - sinLamp * sinBall;  // cos(α + β); α + β ≥ π/2 when the ball holds p
        bool meets = sinBall >= 1.0 || dot(toBall / b, towardsBall) > cosSum;
        if (meets && b < end + r) inFront[i >> 5] |= 1u << (i & 31);
    }
    float through = 1.0;
    for (int pass = 0; pass < (any(notEqual(inFront, uvec2(0u))) ? 1 : 0); ++pass) {
        // The cells: direction, angular radius, distance and weight; then each fireball in
        // front against every cell, its own direction and angle found once.
        const float yLow = u_lightPos.y - radius, yHigh = min(kCeilingY, u_lightPos.y + radius);
        const float dy = (yHigh - yLow) / float(kFireLampCells);
        const float cellArea = 6.28318531 * radius * (yHigh - yLow) / float(kFireLampCells);
        const vec2 turn = vec2(cos(2.39996323), sin(2.39996323));
        vec2 around = vec2(1.0, 0.0);
        vec3 cellDir[kFireLampCells];
        float cellAngle[kFireLampCells], cellDistance[kFireLampCells], weight[kFireLampCells],
            covered[kFireLampCells];  // the fraction of each the fireballs hide (at most all of it)
        float seen = 0.0;
        for (int c = 0; c < kFireLampCells; ++c) {
            float h = yLow + (float(c) + 0.5) * dy - u_lightPos.y;
            float ring = sqrt(max(radius * radius - h * h, 0.0));
            vec3 nq = vec3(around.x * ring, h, around.y * ring) / radius;
            around = vec2(around.x * turn.x - around.y * turn.y, around.x * turn.y + around.y * turn.x);
            vec3 w = u_lightPos.xyz + nq * radius - origin;
            float d2 = dot(w, w);
            cellDistance[c] = sqrt(d2);
            cellDir[c] = w / cellDistance[c];
            float cosP = max(dot(n, cellDir[c]), 0.0), cosQ = max(-dot(nq, cellDir[c]), 0.0);
            weight[c] = cosP * cosQ / d2;
            cellAngle[c] = max(sqrt(cosQ * cellArea / (3.14159265 * d2)), 1e-6);
            covered[c] = 0.0;
            seen += weight[c];
        }
        for (int word = 0; word < 2; ++word)
            for (uint left = inFront[word]; left != 0u; left &= left - 1u) {
                vec4 ball = fireballSphere(32 * word + findLSB(left));
                vec3 toBall = ball.xyz - origin;
                float b = max(length(toBall), 1e-6), r = ball.w;
                float sinBall = min(r / b, 1.0), cosBall = sqrt(1.0 - sinBall * sinBall);
                float ballAngle = asin(sinBall);
                vec3 ballDir = toBall / b;
                for (int c = 0; c < kFireLampCells; ++c) {
                    // Apart by more than the two radii (cos below cos(α + β)), or behind the
                    // cell: nothing hidden, and no inverse cosines (a loop, for llvmpipe).
                    float cosine = dot(ballDir, cellDir[c]);
                    float sinCell = min(cellAngle[c], 1.0), cosCell = sqrt(1.0 - sinCell * sinCell);
                    bool meets = (sinBall >= 1.0 || cosine > cosCell * cosBall - sinCell * sinBall) &&
                                 b < cellDistance[c] + r;
                    for (int k = meets ? 1 : 0; k > 0; --k)
                        covered[c] += discOverlap(cellAngle[c], ballAngle, acos(clamp(cosine, -1.0, 1.0))) /
                                      (3.14159265 * cellAngle[c] * cellAngle[c]);
                }
            }
        float hidden = 0.0;
        for (int c = 0; c < kFireLampCells; ++c) hidden += weight[c] * min(covered[c], 1.0);
        through = seen > 0.0 ? 1.0 - hidden / seen : 1.0;
    }

    // No particles anywhere (the last mip level, the whole volume's mean, is 0): no march.
    int top = textureQueryLevels(u_fire) - 1;
    if (texelFetch(u_fire, ivec3(0), top).r == 0.0) return through;
    float depth = 0.0, t = 0.5 * voxel;
    for (int i = 0; i < kFireMaxSteps && t < end; ++i) {
        float diameter = max(voxel, spread * t);
        float spacing = 0.5 * diameter;
        // A mip level's texel, trilinearly filtered, spreads a sphere over about twice
        // the width (per axis σ = texel/2) of a disc of the same diameter (σ = d/4): a
        // level finer. Rounded to a whole level: llvmpipe then reads one level, not two.
        float mu = textureLod(u_fire, kilnVolumeTexcoord(origin + dir * t), round(log2(diameter / voxel) - 1.0)).r;  // μ·h
        depth += mu * min(spacing, end - t) / voxel;
        t += spacing;
    }
    return through * exp(-depth);
}
