// app/camera.hpp — an orbit camera around the box centre.
#pragma once

#include <glm/glm.hpp>

namespace kiln::app {

struct OrbitCamera {
    float yaw = 0.0f;        // radians about +y; 0 looks down −z from +z
    float pitch = 0.0f;      // radians; positive looks down
    float distance = 3.9f;   // from the target
    float fovY = 0.6632f;    // 38°: the box opening just fills a square view
    glm::vec3 target{0.0f};

    glm::vec3 position() const;
    glm::mat4 view() const;
    glm::mat4 projection(float aspect) const;
    // The world-space ray through a window pixel (origin at the camera, unit direction);
    // x, y in pixels from the top-left corner, as GLFW reports the cursor.
    void rayThrough(double x, double y, int width, int height, glm::vec3& origin, glm::vec3& direction) const;
};

}  // namespace kiln::app
