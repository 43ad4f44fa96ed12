// The lamp's vector irradiance on an axisymmetric grid (common/lamp_field.comp builds
// it; composite and voxelize, lamp_model `field`, read it): where the grid's nodes lie,
// how a point finds them, and the projected solid angle from what it reads.
// Needs common/frame.glsl (u_lightPos) and common/light.glsl (kCeilingY).

// ρ of the grid's last column: the box's vertical edge farthest from the lamp's axis.
float lampFieldRadius() { return length(vec2(1.0) + abs(u_lightPos.xz)); }

// F at p (÷ the lamp's radiance), read from the grid (texel centres on the nodes).
vec3 lampFieldAt(sampler2D field, vec3 p) {
    vec2 d = p.xz - u_lightPos.xz;
    float rho = length(d);
    vec2 size = vec2(textureSize(field, 0));
    vec2 rhoY = vec2(rho / lampFieldRadius(), clamp(p.y, -1.0, 1.0) * 0.5 + 0.5);
    vec2 f = textureLod(field, (min(rhoY, 1.0) * (size - 1.0) + 0.5) / size, 0.0).xy;
    vec2 radial = rho > 0.0 ? d / rho : vec2(0.0);
    return vec3(radial.x * f.x, f.y, radial.y * f.x);
}

// Whether the plane through p with normal n leaves part of the lamp behind it: the
// lowest point of the emitter (the ball below the ceiling) along n, against p's.
bool lampCutByHorizon(vec3 p, vec3 n) {
    vec3 lowest = u_lightPos.xyz - u_lightPos.w * n;
    float rim2 = u_lightPos.w * u_lightPos.w - (u_lightPos.y - kCeilingY) * (u_lightPos.y - kCeilingY);
    float reach = lowest.y <= kCeilingY ? dot(n, lowest)
                                        : dot(n, vec3(u_lightPos.x, kCeilingY, u_lightPos.z)) - sqrt(max(rim2, 0.0)) * length(n.xz);
    return reach < dot(n, p);
}

// The projected solid angle Φ of the lamp from p on a surface with normal n, given F.
// Where the whole lamp is in front of the horizon, Φ = n·F exactly. Where the horizon
// cuts it, n·F falls short of the clipped Φ (a dim band on curved bodies): there the
// lamp is taken as the ball F describes (sin²σ = |F|/π, centred along F) and Φ is that
// ball's horizon-clipped form (Snyder 1996, as in Lagarde & de Rousiers 2014, "Moving
// Frostbite to PBR", §4.7.2). It makes composite dearer on llvmpipe (the same in a
// loop run at most once, which llvmpipe leaves when no pixel of a group needs it); a
// cheaper wrap, |F| (cos θ + sin σ)² / (4 sin σ), cost less but was further from the
// per-pixel contour in that band than n·F itself (tests/gi/test_lamp.cpp).
float lampFieldSolidAngle(vec3 F, vec3 p, vec3 n) {
    float projected = dot(n, F);
    float magnitude = length(F);
    float solidAngle = max(projected, 0.0);
    float sinSigma2 = min(magnitude / 3.14159265, 1.0);
    bool clipped = magnitude > 0.0 && projected * projected < sinSigma2 * magnitude * magnitude;  // cos²θ < sin²σ
    if (clipped && lampCutByHorizon(p, n)) {
        float cosTheta = clamp(projected / magnitude, -1.0, 1.0);
        float sinTheta = sqrt(max(1.0 - cosTheta * cosTheta, 1e-8));
        float x = sqrt(max(1.0 / sinSigma2 - 1.0, 0.0));
        float y = clamp(-x * cosTheta / sinTheta, -1.0, 1.0);
        float sinThetaSqrtY = sinTheta * sqrt(1.0 - y * y);
        solidAngle = max((cosTheta * acos(y) - x * sinThetaSqrtY) * sinSigma2 + atan(sinThetaSqrtY, x), 0.0);
    }
    return solidAngle;
}
