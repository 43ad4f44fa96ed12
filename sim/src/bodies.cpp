// bodies.cpp — what a body looks like: model matrices, ball and particle colours.
#include "internal.hpp"

namespace kiln::sim {

void Tumbler::modelMatrix(float out[16]) const {
    const Mat3 r = rotation();
    for (int c = 0; c < 3; ++c) {
        for (int row = 0; row < 3; ++row) out[c * 4 + row] = float(r[c][row]);
        out[c * 4 + 3] = 0.0f;
    }
    out[12] = float(position.x), out[13] = float(position.y), out[14] = float(position.z), out[15] = 1.0f;
}

double Particle::radius() const {
    const double f = std::clamp(life / maxLife, 0.0, 1.0);
    return kind == ParticleKind::Ash ? size * (0.4 + 0.6 * f) : size * f;
}

Vec3 Particle::emission() const {
    const double f = std::clamp(life / maxLife, 0.0, 1.0);
    switch (kind) {
        case ParticleKind::Fire: return Vec3(4.0, 1.6, 0.4) * f;
        case ParticleKind::Spark: return Vec3(6.0, 4.0, 1.5) * f;
        case ParticleKind::Ash: {
            // Glows while large; once it has shrunk below 60 % it cools quickly to black.
            const double glow = std::clamp((f - 0.35) / 0.25, 0.0, 1.0);
            return Vec3(2.5, 0.9, 0.2) * glow * glow;
        }
    }
    return Vec3(0.0);
}

Vec3 Ball::albedo() const {
    if (kind != BallKind::Burning) return color;
    return color * (1.0 - std::min(1.0, burnTime / kBurnDuration));
}

Vec3 Ball::emissiveColor() const {
    switch (kind) {
        case BallKind::Marble: return Vec3(0.0);
        case BallKind::Fireball: return color;
        case BallKind::Burning: return Vec3(1.0, 0.4, 0.1);
    }
    return Vec3(0.0);
}

double Ball::emissiveStrength() const {
    switch (kind) {
        case BallKind::Marble: return 0.0;
        case BallKind::Fireball: return 6.0;
        case BallKind::Burning: return 3.0 * (1.0 - 0.7 * std::min(1.0, burnTime / kBurnDuration));
    }
    return 0.0;
}
}  // namespace kiln::sim
