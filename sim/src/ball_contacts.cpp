// ball_contacts.cpp — balls: free flight with time-symmetric wall bounces, the lamp dome,
// tumblers (swept for fast balls) and each other (uniform-grid broad phase).
#include "internal.hpp"

namespace kiln::sim {

using namespace detail;

namespace {

// The lamp dome as a time-symmetric bounce. Semi-implicit Euler keeps
// E′ = ½|v|² + g·y − ½gΔt·v_y; writing u = v − ½gΔt·ŷ (the mid-step velocity),
// E′ = ½|u|² + g·y + const. If the step would end inside the dome, the start-of-step
// velocity is replaced by v₀′ = R_n(u₀) + ½gΔt·ŷ (u reflected about the dome normal at
// the start point): |u| and y are unchanged, so E′ is exactly kept, and the step then
// moves away from the dome. Returns true if it bounced.
bool bounceOffLamp(const Scene::Lamp& lamp, double e, double gy, double dt, const Vec3& x0, Vec3& v0, double radius) {
    const Vec3 c = lamp.center;
    const double reach = lamp.radius + radius;
    const Vec3 x1 = x0 + (v0 + Vec3(0, gy * dt, 0)) * dt;
    if (glm::dot(x1 - c, x1 - c) >= reach * reach) return false;
    const Vec3 d = x0 - c;
    const double dist = glm::length(d);
    if (dist < reach || dist < 1e-12) return false;  // started inside: collideBallLamp pushes it out
    const Vec3 n = d / dist;
    const Vec3 u = v0 + Vec3(0, 0.5 * gy * dt, 0);  // gy = −g: u = v − ½gΔt·ŷ
    const double un = glm::dot(u, n);
    if (un >= 0.0) return false;  // already leaving: a grazing step, leave it
    v0 = (u - (1.0 + e) * un * n) - Vec3(0, 0.5 * gy * dt, 0);
    return true;
}

}  // namespace

// physics.balls_keep_speed: the ball leaves at the speed it came, as the course design's
// reflection has it, so the balls keep their energy; the tumbler takes the impulse all
// the same (energy friction then takes out of the tumblers).
void World::keepSpeed(Vec3& u, double speed) const {
    const double now = glm::length(u);
    if (scene_.physics.ballsKeepSpeed && now > 1e-12) u *= speed / now;
}

void World::bounceOffTumblers(int bi, double gy, double dt, Vec3& v0) {
    // The tumblers as time-symmetric bounces too: if the step from x₀ would end inside a
    // tumbler (already moved this sub-step), the hit happens at the start instead, on the
    // mid-step velocity u = v₀ + ½g_yΔt·ŷ, against the tumbler's rolling-constrained
    // response at the point nearest x₀. The ball's E′ = ½|u|² + g·y + const and the
    // tumbler's energy then change by exactly the kinetic energy the impulse moves
    // between them (none lost for e = 1), and no position is pushed. A ball that starts
    // inside (pushed there by another contact) is left to resolveBallTumblerContact.
    Ball& ball = balls_[size_t(bi)];
    const Vec3 x0 = ball.position;
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        if (glm::length(x0 - tumblers_[size_t(i)].position) > std::max(shape_.top(), shape_.b()) + ball.radius + glm::length(v0) * dt + 0.5 * std::abs(gy) * dt * dt)
            continue;
        const Vec3 x1 = x0 + (v0 + Vec3(0, gy * dt, 0)) * dt;
        if (tumblerSdf(i, x1) >= ball.radius) continue;
        const double d0 = tumblerSdf(i, x0);
        if (d0 < ball.radius) continue;
        const Vec3 n = tumblerNormal(i, x0), h = x0 - d0 * n;
        Vec3 u = v0 + Vec3(0, 0.5 * gy * dt, 0);
        const double vn = glm::dot(u - pointVelocity(i, h), n);
        if (vn >= 0.0) continue;  // separating at the start: a graze, the push handles it
        const double k = 1.0 / ball.mass() + rollingInverseMass(i, h, n);
        const double jn = -(1.0 + scene_.physics.restitution.ballTumbler) * vn / k;
        const double speed = glm::length(u);
        u += (jn / ball.mass()) * n;
        keepSpeed(u, speed);
        applyRollingImpulse(i, h, -jn * n);
        wake(i);
        v0 = u - Vec3(0, 0.5 * gy * dt, 0);
        if (ball.kind == BallKind::Fireball) emitSparks(h, n, 10);
    }
}

void World::stepBall(int bi, double dt) {
    Ball& ball = balls_[size_t(bi)];
    const double gy = ball.kind == BallKind::Fireball ? 0.0 : -scene_.physics.gravity;
    const auto& rest = scene_.physics.restitution;
    Vec3 v0 = ball.velocity;
    const Vec3 x0 = ball.position;
    if (bounceOffLamp(scene_.lamp, rest.ballLamp, gy, dt, x0, v0, ball.radius) && ball.kind == BallKind::Fireball) {
        const Vec3 n = glm::normalize(x0 - scene_.lamp.center);
        emitSparks(scene_.lamp.center + n * scene_.lamp.radius, n, 6);
    }
    bounceOffTumblers(bi, gy, dt, v0);
    Vec3 v1 = v0;
    v1.y += gy * dt;
    Vec3 x1 = x0 + v1 * dt;
    const double limit = 1.0 - ball.radius;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(x1[k]) <= limit) continue;
        // Time-symmetric bounce: a step that would cross the wall becomes the time
        // reverse of the step that came in, v₁ = −e·v₀, x₁ = x₀ + v₁Δt. With e = 1 it
        // keeps E′ = ½v² + g·y − ½gΔt·v_y exactly (docs/physics.md §4), never lets the ball
        // through (it moves away from the wall from inside), and needs no time of impact.
        const double wall = x1[k] > 0 ? limit : -limit;
        v1[k] = -rest.ballBox * v0[k];
        x1[k] = x0[k] + v1[k] * dt;
        // A ball creeping along the floor (|v_y| < gΔt) may still cross, and one moving
        // more than the box per step would cross the opposite wall: hold it inside.
        x1[k] = std::clamp(x1[k], -limit, limit);
        Vec3 normal(0.0);
        normal[k] = wall > 0 ? -1.0 : 1.0;
        ball.angularVelocity = glm::cross(normal, v1) / ball.radius;  // rolling on the wall
        if (ball.kind == BallKind::Fireball) emitSparks(x1 - normal * ball.radius, normal, 6);
    }
    ball.velocity = v1;
    ball.position = x1;
}

void World::collideBallLamp(Ball& ball) {
    // Only for a ball that is inside the dome already (pushed there by another contact
    // or spawned there): push it out along the normal and reflect what moves inwards.
    const Vec3 c = scene_.lamp.center;
    const double reach = scene_.lamp.radius + ball.radius;
    const Vec3 d = ball.position - c;
    const double dist = glm::length(d);
    if (dist >= reach || dist < 1e-12) return;
    const Vec3 n = d / dist;
    ball.position = c + n * reach;
    ball.position.y = std::min(ball.position.y, 1.0 - ball.radius);
    const double vn = glm::dot(ball.velocity, n);
    if (vn < 0) ball.velocity -= (1.0 + scene_.physics.restitution.ballLamp) * vn * n;
}

void World::collideBallTumblers(int bi) {
    for (int i = 0; i < int(tumblers_.size()); ++i) {
        Ball& ball = balls_[size_t(bi)];
        // A fast ball (moved more than its radius this sub-step) could jump over a
        // tumbler: conservative advancement along its path finds the first touch.
        const Vec3 from = ballsBefore_[size_t(bi)], path = ball.position - from;
        const double len = glm::length(path);
        if (len > ball.radius) {
            const Tumbler& t = tumblers_[size_t(i)];
            // Bounding sphere about O (every point of the body is within y_t + t of it).
            const double s = std::clamp(glm::dot(t.position - from, path) / (len * len), 0.0, 1.0);
            if (glm::length(from + s * path - t.position) < shape_.top() + ball.radius) {
                double along = 0.0;  // metres along the path
                for (int iter = 0; iter < 64 && along < len; ++iter) {
                    const double d = tumblerSdf(i, from + path * (along / len)) - ball.radius;
                    if (d < 1e-4) {
                        // Touching: stop a hair inside, so the contact below resolves it.
                        ball.position = from + path * (std::min(len, along + 2e-4) / len);
                        break;
                    }
                    along += d;
                }
            }
        }
        resolveBallTumblerContact(bi, i);
    }
}

void World::moveBallKeepingEnergy(Ball& ball, const Vec3& to) {
    // A position correction (a ball pushed out of a tumbler that moved into it) changes
    // the ball's height and so its E′ = ½|u|² + g·y + const (u = v − ½gΔt·ŷ). Scaling u
    // to pay for the height keeps E′; only a ball too slow to pay gains the rest.
    const double g = ball.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    const double dt = substepDt_;
    const Vec3 half(0, 0.5 * g * dt, 0);
    const Vec3 u = ball.velocity - half;
    const double u2 = glm::dot(u, u), paid = 2.0 * g * (to.y - ball.position.y);
    ball.position = to;
    if (paid == 0.0 || u2 <= 0.0) return;
    ball.velocity = u * std::sqrt(std::max(0.0, 1.0 - paid / u2)) + half;
}

bool World::resolveBallTumblerContact(int bi, int i) {
    Ball& ball = balls_[size_t(bi)];
    const Tumbler& t = tumblers_[size_t(i)];
    if (glm::length(ball.position - t.position) > std::max(shape_.top(), shape_.b()) + ball.radius) return false;
    const double d = tumblerSdf(i, ball.position);
    if (d >= ball.radius) return false;
    const Vec3 n = tumblerNormal(i, ball.position);
    const Vec3 h = ball.position - d * n;  // the contact point on the surface
    moveBallKeepingEnergy(ball, ball.position + n * (ball.radius - d));
    // The impulse acts on the mid-step velocity u = v − ½gΔt·ŷ, the one the ball's E′
    // counts (½|u|² + g·y), so an elastic hit moves energy without making or losing any.
    const double g = ball.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    const Vec3 u = ball.velocity - Vec3(0, 0.5 * g * substepDt_, 0);
    const double vn = glm::dot(u - pointVelocity(i, h), n);
    if (vn >= 0.0) return true;
    // The tumbler answers with its rolling-constrained effective mass (the floor holds
    // its contact point), so the relative normal velocity becomes exactly −e·vn, and
    // with e = 1 the kinetic energy of ball + tumbler is kept.
    const double k = 1.0 / ball.mass() + rollingInverseMass(i, h, n);
    const double jn = -(1.0 + scene_.physics.restitution.ballTumbler) * vn / k;
    Vec3 after = u + (jn / ball.mass()) * n;
    keepSpeed(after, glm::length(u));
    ball.velocity = after + Vec3(0, 0.5 * g * substepDt_, 0);
    applyRollingImpulse(i, h, -jn * n);
    wake(i);
    if (ball.kind == BallKind::Fireball) emitSparks(h, n, 10);
    return true;
}

bool World::separateBallsFromTumblers() {
    bool movedTumbler = false;
    // After the wall clamp: a ball still overlapping a tumbler is pinned between it and a
    // wall (or another ball pushed it back). Move it out along the normal as far as the
    // walls allow, and move the tumbler horizontally away by what is left; the tumbler's
    // walls then run again. Velocities were settled by the contact impulses already.
    for (int bi = 0; bi < int(balls_.size()); ++bi) {
        Ball& ball = balls_[size_t(bi)];
        const double limit = 1.0 - ball.radius;
        for (int i = 0; i < int(tumblers_.size()); ++i) {
            if (glm::length(ball.position - tumblers_[size_t(i)].position) > std::max(shape_.top(), shape_.b()) + ball.radius) continue;
            const double d = tumblerSdf(i, ball.position);
            if (d >= ball.radius - 1e-9) continue;
            const Vec3 n = tumblerNormal(i, ball.position);
            const Vec3 before = ball.position;
            moveBallKeepingEnergy(ball, glm::clamp(ball.position + n * (ball.radius - d), Vec3(-limit), Vec3(limit)));
            const double left = ball.radius - tumblerSdf(i, ball.position);
            if (left <= 0.0) continue;
            Vec3 nh(n.x, 0.0, n.z);
            const double l = glm::length(nh);
            nh = l > 1e-9 ? nh / l : glm::normalize(Vec3(ball.position.x - before.x + 1e-12, 0.0, 0.0));
            tumblers_[size_t(i)].position -= nh * (left / std::max(l, 1.0 / 3.0));
            collideTumblerWalls(i);
            wake(i);
            movedTumbler = true;
        }
    }
    return movedTumbler;
}

void World::collideBallPairs() {
    const int n = int(balls_.size());
    pairChecks_ = 0;
    if (n < 2) return;
    if (n <= 32) {
        // Few balls: every pair in index order is cheaper than clearing and counting a
        // grid of up to 64³ cells (and just as deterministic).
        for (int i = 0; i < n; ++i)
            for (int j = i + 1; j < n; ++j) resolveBallBallContact(i, j);
        pairChecks_ = uint64_t(n) * uint64_t(n - 1) / 2;
        return;
    }
    // Uniform grid over the box, cell ≥ the largest diameter: a ball can only touch
    // balls in its own and the 26 neighbouring cells. Counting sort keeps it O(n) and
    // deterministic (pairs are visited in ball index order).
    double maxR = 0;
    for (auto& b : balls_) maxR = std::max(maxR, b.radius);
    const int dim = std::clamp(int(2.0 / (2.0 * maxR)), 1, 64);
    const double inv = dim / 2.0;
    auto cellOf = [&](const Vec3& p, int axis) { return std::clamp(int((p[axis] + 1.0) * inv), 0, dim - 1); };
    gridCells_.resize(size_t(n));
    gridStart_.assign(size_t(dim) * dim * dim + 1, 0);
    gridOrder_.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
        const Vec3& p = balls_[size_t(i)].position;
        gridCells_[size_t(i)] = (cellOf(p, 0) * dim + cellOf(p, 1)) * dim + cellOf(p, 2);
        ++gridStart_[size_t(gridCells_[size_t(i)]) + 1];
    }
    for (size_t c = 1; c < gridStart_.size(); ++c) gridStart_[c] += gridStart_[c - 1];
    gridCursor_.assign(gridStart_.begin(), gridStart_.end() - 1);
    for (int i = 0; i < n; ++i) gridOrder_[size_t(gridCursor_[size_t(gridCells_[size_t(i)])]++)] = i;
    // Each ball against later balls in its own cell, and against every ball in the 13
    // "forward" neighbour cells (the other 13 see this cell as their forward one).
    for (int i = 0; i < n; ++i) {
        const int c = gridCells_[size_t(i)];
        const int cx = c / (dim * dim), cy = (c / dim) % dim, cz = c % dim;
        pairChecks_ += uint64_t(gridStart_[size_t(c) + 1] - gridStart_[size_t(c)]);
        for (int k = gridStart_[size_t(c)]; k < gridStart_[size_t(c) + 1]; ++k) {
            const int j = gridOrder_[size_t(k)];
            if (j > i) resolveBallBallContact(i, j);
        }
        for (int dx = 0; dx <= 1; ++dx)
            for (int dy = dx ? -1 : 0; dy <= 1; ++dy)
                for (int dz = (dx || dy) ? -1 : 1; dz <= 1; ++dz) {
                    const int x = cx + dx, y = cy + dy, z = cz + dz;
                    if (x >= dim || y < 0 || y >= dim || z < 0 || z >= dim) continue;
                    const int cell = (x * dim + y) * dim + z;
                    pairChecks_ += uint64_t(gridStart_[size_t(cell) + 1] - gridStart_[size_t(cell)]);
                    for (int k = gridStart_[size_t(cell)]; k < gridStart_[size_t(cell) + 1]; ++k)
                        resolveBallBallContact(i, gridOrder_[size_t(k)]);
                }
    }
}

bool World::resolveBallBallContact(int ai, int bi) {
    Ball& a = balls_[size_t(ai)];
    Ball& b = balls_[size_t(bi)];
    Vec3 d = b.position - a.position;
    const double reach = a.radius + b.radius;
    const double dist2 = glm::dot(d, d);
    if (dist2 >= reach * reach) return false;
    const double dist = std::sqrt(dist2);
    // Coincident centres: no direction; separate along x (deterministic by index).
    const Vec3 n = dist > 1e-12 ? d / dist : Vec3(ai < bi ? 1.0 : -1.0, 0, 0);
    const double ma = a.mass(), mb = b.mass();
    // Separate in proportion to the other's mass (the centre of mass stays put, and with
    // it the pair's potential energy). A fireball feels no gravity: against a marble the
    // marble's push is paid from its own speed (moveBallKeepingEnergy).
    const double pen = reach - dist;
    const double ga = a.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    const double gb = b.kind == BallKind::Fireball ? 0.0 : scene_.physics.gravity;
    if (ga == gb) {
        a.position -= n * (pen * mb / (ma + mb));
        b.position += n * (pen * ma / (ma + mb));
    } else {
        moveBallKeepingEnergy(a, a.position - n * (pen * mb / (ma + mb)));
        moveBallKeepingEnergy(b, b.position + n * (pen * ma / (ma + mb)));
    }
    // The impulse from the mid-step velocities u = v − ½gΔt·ŷ (what E′ counts); for two
    // balls under the same gravity that is the same relative velocity as v's.
    const double halfDt = 0.5 * substepDt_;
    const double vn = glm::dot(b.velocity - a.velocity, n) + (ga - gb) * halfDt * n.y;
    if (vn < 0) {
        const double j = -(1.0 + scene_.physics.restitution.ballBall) * vn / (1.0 / ma + 1.0 / mb);
        a.velocity -= (j / ma) * n;
        b.velocity += (j / mb) * n;
    }
    const bool aFire = a.kind == BallKind::Fireball, bFire = b.kind == BallKind::Fireball;
    const Vec3 at = a.position + n * a.radius;
    if (aFire && b.kind == BallKind::Marble) ignite(bi, at);
    if (bFire && a.kind == BallKind::Marble) ignite(ai, at);
    if ((aFire || bFire) && vn < 0) emitSparks(at, n, 8);
    return true;
}
}  // namespace kiln::sim
