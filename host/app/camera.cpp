#include "app/camera.hpp"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "kiln/scene_view.hpp"

namespace kiln::app {

glm::vec3 OrbitCamera::position() const {
    return target + distance * glm::vec3(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
}

glm::mat4 OrbitCamera::view() const { return glm::lookAt(position(), target, glm::vec3(0, 1, 0)); }

glm::mat4 OrbitCamera::projection(float aspect) const { return glm::perspective(fovY, aspect, kCameraNear, kCameraFar); }

void OrbitCamera::rayThrough(double x, double y, int width, int height, glm::vec3& origin,
                             glm::vec3& direction) const {
    const glm::mat4 inv = glm::inverse(projection(float(width) / float(height)) * view());
    const float nx = float(2.0 * (x + 0.5) / width - 1.0), ny = float(1.0 - 2.0 * (y + 0.5) / height);
    glm::vec4 nearPoint = inv * glm::vec4(nx, ny, -1.0f, 1.0f), farPoint = inv * glm::vec4(nx, ny, 1.0f, 1.0f);
    origin = position();
    direction = glm::normalize(glm::vec3(farPoint) / farPoint.w - glm::vec3(nearPoint) / nearPoint.w);
}

}  // namespace kiln::app
