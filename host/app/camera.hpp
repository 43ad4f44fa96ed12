// app/camera.hpp — the view: an orbit camera around a target (the box centre by
// default), or a fly camera with its own eye (interiors, a glTF file's camera).
#pragma once

#include <glm/glm.hpp>

#include "kiln/scene_view.hpp"

namespace kiln::app {

struct Camera {
    enum class Mode { Orbit, Fly };
    Mode mode = Mode::Orbit;
    float yaw = 0.0f;        // radians about +y; 0 looks down −z from +z
    float pitch = 0.0f;      // radians; positive looks down
    float distance = 3.9f;   // orbit: from the target
    float fovY = 0.6632f;    // 38°: the box opening just fills a square view
    glm::vec3 target{0.0f};  // orbit: what it circles
    glm::vec3 eye{0.0f};     // fly: where it is
    float farPlane = kCameraFar;  // farther for a scene larger than the box (App::buildView)

    glm::vec3 position() const;
    glm::vec3 forward() const;  // unit: where it looks
    glm::mat4 view() const;
    glm::mat4 projection(float aspect) const;
    // The world-space ray through a window pixel (origin at the camera, unit direction);
    // x, y in pixels from the top-left corner, as GLFW reports the cursor.
    void rayThrough(double x, double y, int width, int height, glm::vec3& origin, glm::vec3& direction) const;

    // Fly from where the camera is now / orbit what is `distance` ahead of it.
    void toFly();
    void toOrbit();
    // Fly: moves the eye by `move` in the view's frame (x right, y up, z forward).
    void fly(glm::vec3 move);
    // Fly at `eye` looking along `forward` (its roll is not kept: +y stays up).
    void lookFrom(glm::vec3 eye, glm::vec3 forward, float fovY);
};

}  // namespace kiln::app
