#include "app/camera.hpp"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace kiln::app {

glm::vec3 OrbitCamera::position() const {
    return target + distance * glm::vec3(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
}

glm::mat4 OrbitCamera::view() const { return glm::lookAt(position(), target, glm::vec3(0, 1, 0)); }

glm::mat4 OrbitCamera::projection(float aspect) const { return glm::perspective(fovY, aspect, 0.05f, 20.0f); }

}  // namespace kiln::app
