#include "frame.glsl"

// The lamp, defined once (scene file `lamp`): the part of the sphere u_lightPos (xyz
// centre, w radius) below the ceiling y = 1, a Lambertian emitter of radiance
// u_lightColor.rgb. Its irradiance at p on a surface with unit normal n, before
// visibility, is E = L · Φ, Φ = ∫ max(n·ω, 0) dω over the directions ω that meet the
// emitter: its projected solid angle. Diffuse outgoing radiance = albedo/π · E ·
// visibility. Shared by composite (PCF shadows) and voxelize (hard shadows);
// passes/reference samples the same emitter, so the rasterized frame and the reference
// agree on the lamp without a fudge factor. Two ways to evaluate it:
//
// KILN_LAMP_CONTOUR 1 (default): exact up to a polygon of KILN_LAMP_SAMPLES vertices.
//   The emitter is convex (a ball cut by a plane), so the directions that meet it are
//   bounded by its silhouette: the arc of the ball's tangent circle below the ceiling,
//   closed by the arc of the rim (where the dome meets the ceiling) that stands in for
//   the cut-off part. Φ of a spherical polygon clipped to the horizon n·ω ≥ 0 is
//   Lambert's contour sum ½ Σ θ_i n·(v_i × v_i+1)/|v_i × v_i+1| (Arvo 1995). No
//   singularity: the integrand lives on the unit sphere of directions, so the error
//   does not grow next to the dome (tests/gi/test_lamp.cpp: within 0.3 % of a fine
//   quadrature down to 1 mm from it). Each arc's inner vertices sit a factor
//   √(Δ/sin Δ) out from its circle (Δ: the angle between vertices), so the polygon
//   has the circle's area instead of falling short by the chords' segments.
// KILN_LAMP_CONTOUR 0: the area form ∫_cap L cos θ_p cos θ_q / d² dA by a fixed
//   KILN_LAMP_SAMPLES-point quadrature, equal-area points on the cap (Archimedes) on
//   a golden-angle spiral. Near the dome the integrand is near-singular: bright lobes
//   and dark bands on the ceiling around it (the course design's lamp; kept to compare).
#ifndef KILN_LAMP_SAMPLES
#define KILN_LAMP_SAMPLES 32
#endif
#ifndef KILN_LAMP_CONTOUR
#define KILN_LAMP_CONTOUR 1
#endif
const float kCeilingY = 1.0;

#if KILN_LAMP_CONTOUR
// Lambert's term of one great-circle edge a → b (unit vectors): θ · n·(a×b)/|a×b|, with
// θ/sin θ from the rational fit of Hill & Heitz's "Real-Time Area Lighting: a Journey
// from Research to Production" (2016) instead of an atan and a division per edge (the fit
// is of θ/(2π sin θ)).
// lambertEdgeVector: the same edge's term as a vector, θ · (a×b)/|a×b| (its n·… is
// lambertEdge).
vec3 lambertEdgeVector(vec3 a, vec3 b) {
    float x = dot(a, b), y = abs(x);
    float v = (0.8543985 + (0.4965155 + 0.0145206 * y) * y) / (3.4175940 + (4.1616724 + y) * y);
    float thetaOverSin = x > 0.0 ? v : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - v;
    return cross(a, b) * (thetaOverSin * 6.28318531);
}
float lambertEdge(vec3 a, vec3 b, vec3 n) { return dot(n, lambertEdgeVector(a, b)); }

// The silhouette as a closed loop of vertices: the tangent arc (vertices 0 …
// tangentCount − 1), then the rim arc's inner vertices.
struct LampOutline {
    vec3 tangentCentre, tangentU, tangentV;  // tangent circle: centre + r·(cos φ U + sin φ V)
    float tangentRadius, phiStart, phiSpan;  // φ from phiStart over phiSpan
    int tangentCount;                        // vertices on it (both ends included when it is an arc)
    vec3 rimCentre;                          // rim circle: centre + r·(cos θ, 0, sin θ)
    float rimRadius, thetaStart, thetaSpan;  // θ over the arc, ends excluded when it closes a tangent arc
    int rimCount;
};

vec3 circlePoint(vec3 centre, vec3 u, vec3 v, float r, float angle) { return centre + r * (cos(angle) * u + sin(angle) * v); }

// Walks the outline's vertices in order without a sine or cosine per vertex: each arc's
// (cos, sin) turns by its step's rotation.
struct OutlineWalk {
    vec2 turn, at;    // rotation per step; (cos, sin) of the current angle
    float grow;       // inner vertices' radius factor √(Δ/sin Δ)
    bool onRim;
};

OutlineWalk startArc(float start, float step) {
    float grow = abs(step) > 1e-4 ? sqrt(abs(step) / sin(abs(step))) : 1.0;
    return OutlineWalk(vec2(cos(step), sin(step)), vec2(cos(start), sin(start)), grow, false);
}

// The walk from the outline's vertex 0, along the tangent arc (both its ends are
// vertices when the rim closes it).
OutlineWalk startOutline(LampOutline o) {
    return startArc(o.phiStart, o.phiSpan / float(o.rimCount > 0 ? o.tangentCount - 1 : o.tangentCount));
}

// Vertex i (walked in order from 0) in world space; advances the walk.
vec3 nextOutlineVertex(LampOutline o, int i, inout OutlineWalk w) {
    if (i == o.tangentCount) {  // onto the rim
        bool closes = o.tangentCount > 0;
        float step = o.thetaSpan / float(closes ? o.rimCount + 1 : o.rimCount);
        w = startArc(o.thetaStart + (closes ? step : 0.0), step);
        w.onRim = true;
    }
    vec3 v;
    if (w.onRim) {
        v = o.rimCentre + (o.rimRadius * w.grow) * vec3(w.at.x, 0.0, w.at.y);
    } else {
        bool end = o.rimCount > 0 && (i == 0 || i == o.tangentCount - 1);  // on the ceiling: exact
        v = o.tangentCentre + (o.tangentRadius * (end ? 1.0 : w.grow)) * (w.at.x * o.tangentU + w.at.y * o.tangentV);
    }
    w.at = vec2(w.at.x * w.turn.x - w.at.y * w.turn.y, w.at.x * w.turn.y + w.at.y * w.turn.x);
    return v;
}

// The emitter's outline as seen from p (moved a hair below the ceiling when above it);
// false when p sees nothing of it (inside the ball, or no emitter below the ceiling).
// axis: the unit direction from p to the ball's centre.
bool lampOutline(inout vec3 p, out LampOutline o, out vec3 axis) {
    const vec3 c = u_lightPos.xyz;
    const float radius = u_lightPos.w;
    const float rim2 = radius * radius - (c.y - kCeilingY) * (c.y - kCeilingY);
    o = LampOutline(vec3(0.0), vec3(0.0), vec3(0.0), 0.0, 0.0, 0.0, 0, vec3(0.0), 0.0, 0.0, 0.0, 0);
    axis = vec3(0.0, 1.0, 0.0);
    if (c.y - radius >= kCeilingY) return false;  // nothing below the ceiling
    p.y = min(p.y, kCeilingY - 1e-5);             // a ceiling point reconstructed a hair above it
    vec3 toCentre = c - p;
    float d2 = dot(toCentre, toCentre);
    if (d2 <= radius * radius * (1.0 + 1e-6)) return false;  // inside the lamp
    float d = sqrt(d2);
    axis = toCentre / d;

    o.tangentCentre = c - (radius * radius / d) * axis;
    o.tangentRadius = radius * sqrt(1.0 - radius * radius / d2);
    // U: up, made perpendicular to the axis (V is then horizontal); any perpendicular
    // when the axis is vertical.
    vec3 up = vec3(0.0, 1.0, 0.0) - axis.y * axis;
    float upLength = length(up);
    o.tangentU = upLength > 1e-6 ? up / upLength : normalize(cross(axis, vec3(1.0, 0.0, 0.0)));
    o.tangentV = cross(axis, o.tangentU);
    o.rimCentre = vec3(c.x, kCeilingY, c.z);
    o.rimRadius = sqrt(max(rim2, 0.0));
    // A tangent point's height is tangentCentre.y + r·U.y·cos φ: below the ceiling
    // where cos φ ≤ kappa.
    float rise = o.tangentRadius * o.tangentU.y;
    float headroom = kCeilingY - o.tangentCentre.y;
    const int count = KILN_LAMP_SAMPLES;
    if (rim2 <= 0.0 || rise <= headroom) {
        // The whole tangent circle is below the ceiling: the ball's own silhouette.
        o.tangentCount = count, o.rimCount = 0;
        o.phiStart = 0.0, o.phiSpan = 6.28318531;
    } else if (-rise >= headroom) {
        // All of it above: the emitter is seen through its rim alone.
        o.tangentCount = 0, o.rimCount = count;
        o.thetaStart = 0.0, o.thetaSpan = 6.28318531;
    } else {
        float phi0 = acos(clamp(headroom / rise, -1.0, 1.0));
        o.tangentCount = count / 2 + 1, o.rimCount = count - o.tangentCount;
        o.phiStart = phi0, o.phiSpan = 6.28318531 - 2.0 * phi0;
        // The rim arc from the tangent arc's last vertex back to its first, on the side
        // of the cut-off top of the tangent circle (φ = 0).
        vec3 a = circlePoint(o.tangentCentre, o.tangentU, o.tangentV, o.tangentRadius, phi0) - o.rimCentre;
        vec3 b = circlePoint(o.tangentCentre, o.tangentU, o.tangentV, o.tangentRadius, -phi0) - o.rimCentre;
        vec3 top = o.tangentCentre + o.tangentRadius * o.tangentU - o.rimCentre;
        float thetaA = atan(a.z, a.x), thetaB = atan(b.z, b.x), thetaTop = atan(top.z, top.x);
        float forward = mod(thetaA - thetaB, 6.28318531);  // B → A counter-clockwise
        bool viaTop = mod(thetaTop - thetaB, 6.28318531) < forward;
        o.thetaStart = thetaB, o.thetaSpan = viaTop ? forward : forward - 6.28318531;
    }
    return true;
}

// The emitter's vector irradiance ÷ its radiance at p (Arvo 1995): F with Φ = n·F for
// every normal n whose horizon leaves the whole emitter in front (n·F ≤ 0 when all of
// it is behind; in between, clipping makes Φ ≥ max(n·F, 0)). Independent of n, smooth
// in p: composite's lamp_model `field` stores it on a grid.
vec3 lampVector(vec3 p) {
    LampOutline o;
    vec3 axis;
    if (!lampOutline(p, o, axis)) return vec3(0.0);
    const int count = KILN_LAMP_SAMPLES;
    OutlineWalk walk = startOutline(o);
    const vec3 first = normalize(nextOutlineVertex(o, 0, walk) - p);
    vec3 previous = first, sum = vec3(0.0);
    for (int i = 1; i <= count; ++i) {
        vec3 current = i < count ? normalize(nextOutlineVertex(o, i, walk) - p) : first;
        sum += lambertEdgeVector(previous, current);
        previous = current;
    }
    return 0.5 * (dot(sum, axis) < 0.0 ? -sum : sum);
}

// The emitter's projected solid angle Φ from p on a surface with normal n.
float lampProjectedSolidAngle(vec3 p, vec3 n) {
    LampOutline o;
    vec3 axis;
    if (!lampOutline(p, o, axis)) return 0.0;
    const int count = KILN_LAMP_SAMPLES;

    // Lambert's sum over the loop, clipped to the horizon n·ω ≥ 0. An edge with one end
    // below it is cut where it crosses (the crossing replaces that end). The region is
    // the projection of a convex body, so it crosses at most once each way: one edge
    // along the horizon joins the exit to the entry. Branch-free (llvmpipe runs both
    // sides of a branch): one Lambert term per vertex; the last edge closes the loop on
    // the first vertex.
    OutlineWalk walk = startOutline(o);
    const vec3 first = normalize(nextOutlineVertex(o, 0, walk) - p);
    const float dFirst = dot(n, first);
    vec3 previous = first;
    float dPrevious = dFirst;
    vec3 exit = vec3(0.0), entry = vec3(0.0);
    float sum = 0.0;
    for (int i = 1; i <= count; ++i) {  // every case has `count` vertices in all
        vec3 current = first;
        float dCurrent = dFirst;
        if (i < count) {
            current = normalize(nextOutlineVertex(o, i, walk) - p);
            dCurrent = dot(n, current);
        }
        bool aboveA = dPrevious >= 0.0, aboveB = dCurrent >= 0.0;
        vec3 crossing = normalize((dPrevious * current - dCurrent * previous) / (aboveA == aboveB ? 1.0 : dPrevious - dCurrent));
        exit = aboveA && !aboveB ? crossing : exit;
        entry = !aboveA && aboveB ? crossing : entry;
        float term = lambertEdge(aboveA ? previous : crossing, aboveB ? current : crossing, n);
        sum += aboveA || aboveB ? term : 0.0;
        previous = current, dPrevious = dCurrent;
    }
    sum += lambertEdge(exit, entry, n);  // zero when nothing crossed (both stay 0)
    return 0.5 * abs(sum);
}

vec3 lampLight(vec3 p, vec3 n) { return u_lightColor.rgb * lampProjectedSolidAngle(p, n); }
#else
vec3 lampLight(vec3 p, vec3 n) {
    const vec3 c = u_lightPos.xyz;
    const float radius = u_lightPos.w;
    const float yLow = c.y - radius, yHigh = min(kCeilingY, c.y + radius);
    if (yHigh <= yLow) return vec3(0.0);
    const float dy = (yHigh - yLow) / float(KILN_LAMP_SAMPLES);
    const vec2 turn = vec2(cos(2.39996323), sin(2.39996323));  // the golden angle
    vec2 dir = vec2(1.0, 0.0);
    float sum = 0.0;
    for (int i = 0; i < KILN_LAMP_SAMPLES; ++i) {
        const float h = yLow + (float(i) + 0.5) * dy - c.y;
        const vec3 nq = vec3(dir.x * sqrt(max(radius * radius - h * h, 0.0)), h, dir.y * sqrt(max(radius * radius - h * h, 0.0))) / radius;
        const vec3 w = c + nq * radius - p;
        const float d2 = dot(w, w);
        sum += max(dot(n, w), 0.0) * max(-dot(nq, w), 0.0) / (d2 * d2);
        dir = vec2(dir.x * turn.x - dir.y * turn.y, dir.x * turn.y + dir.y * turn.x);
    }
    const float area = 6.28318531 * radius * (yHigh - yLow);
    return u_lightColor.rgb * (sum * area / float(KILN_LAMP_SAMPLES));
}
#endif
