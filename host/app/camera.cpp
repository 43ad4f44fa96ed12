#include "app/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "kiln/scene_view.hpp"

namespace kiln::app {

namespace {
// The unit vector from the target to an orbit camera at yaw, pitch: minus where it looks.
glm::vec3 back(float yaw, float pitch) {
    return glm::vec3(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
}
}  // namespace

glm::vec3 Camera::position() const { return mode == Mode::Fly ? eye : target + distance * back(yaw, pitch); }

glm::vec3 Camera::forward() const { return -back(yaw, pitch); }

glm::mat4 Camera::view() const {
    if (mode == Mode::Orbit) return glm::lookAt(position(), target, glm::vec3(0, 1, 0));
    return glm::lookAt(eye, eye + forward(), glm::vec3(0, 1, 0));
}

glm::mat4 Camera::projection(float aspect) const { return glm::perspective(fovY, aspect, kCameraNear, farPlane); }

void Camera::rayThrough(double x, double y, int width, int height, glm::vec3& origin, glm::vec3& direction) const {
    const glm::mat4 inv = glm::inverse(projection(float(width) / float(height)) * view());
    const float nx = float(2.0 * (x + 0.5) / width - 1.0), ny = float(1.0 - 2.0 * (y + 0.5) / height);
    glm::vec4 nearPoint = inv * glm::vec4(nx, ny, -1.0f, 1.0f), farPoint = inv * glm::vec4(nx, ny, 1.0f, 1.0f);
    origin = position();
    direction = glm::normalize(glm::vec3(farPoint) / farPoint.w - glm::vec3(nearPoint) / nearPoint.w);
}

void Camera::toFly() {
    if (mode == Mode::Fly) return;
    eye = position();
    mode = Mode::Fly;
}

void Camera::toOrbit() {
    if (mode == Mode::Orbit) return;
    target = eye + forward() * distance;
    mode = Mode::Orbit;
}

void Camera::fly(glm::vec3 move) {
    toFly();
    const glm::vec3 f = forward();
    const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
    eye += right * move.x + glm::vec3(0, 1, 0) * move.y + f * move.z;
}

void Camera::lookFrom(glm::vec3 at, glm::vec3 along, float fov) {
    mode = Mode::Fly;
    eye = at;
    const glm::vec3 f = glm::normalize(along);
    // Short of straight up or down, where +y as up leaves no view.
    pitch = std::clamp(std::asin(std::clamp(-f.y, -1.0f, 1.0f)), -1.55f, 1.55f);
    yaw = std::atan2(-f.x, -f.z);
    fovY = fov;
}

}  // namespace kiln::app
