// The window's input: keys and the wheel act at once; the left button's press is noted
// where it happened (a slow frame may poll it only after the cursor moved on), and
// handleMouse turns it into a drag of the compare line, a tumbler or the camera.
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

#include "app/window_state.hpp"

namespace kiln::app {

void installCallbacks(GLFWwindow* window) {
    glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
        if (ImGui::GetIO().WantCaptureMouse) return;
        auto* s = static_cast<WindowState*>(glfwGetWindowUserPointer(w));
        s->app->camera().distance = std::clamp(s->app->camera().distance * float(std::pow(0.9, dy)), 1.5f, 10.0f);
    });
    glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
        auto* s = static_cast<WindowState*>(glfwGetWindowUserPointer(w));
        s->eventX = x, s->eventY = y;
    });
    glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
        if (button != GLFW_MOUSE_BUTTON_LEFT || action != GLFW_PRESS) return;
        auto* s = static_cast<WindowState*>(glfwGetWindowUserPointer(w));
        s->pressX = s->eventX, s->pressY = s->eventY;
        s->pressPending = true;
    });
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
        if (action != GLFW_PRESS || ImGui::GetIO().WantCaptureKeyboard) return;
        auto* s = static_cast<WindowState*>(glfwGetWindowUserPointer(w));
        if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, 1);
        if (key == GLFW_KEY_F1) s->showDebug = !s->showDebug;
        if (key == GLFW_KEY_SPACE) s->app->paused = !s->app->paused;
        if (key == GLFW_KEY_PERIOD) s->app->singleStep = true;
        if (key == GLFW_KEY_M) s->app->scene().sim().spawnRandom(sim::BallKind::Marble);
        if (key == GLFW_KEY_F) s->app->scene().sim().spawnRandom(sim::BallKind::Fireball);
        if (key == GLFW_KEY_R) s->app->scene().reset();
    });
}

// Left button: on a tumbler it drags it (grabbed below its centre of mass it slides on
// the floor, above it tilts and rolls: the README's keys); on empty space it orbits
// the camera.
void handleMouse(GLFWwindow* window, WindowState& state) {
    App& app = *state.app;
    double x, y;
    glfwGetCursorPos(window, &x, &y);
    const bool down = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    if (down && state.pressPending && !state.dragging && !state.compare.dragging) {
        // Start from where the press happened; this frame's motion follows.
        state.lastX = state.pressX, state.lastY = state.pressY;
        x = state.pressX, y = state.pressY;
    }
    state.pressPending = false;
    const bool inImage = x >= state.image.x && y >= state.image.y && x < state.image.x + state.image.z &&
                         y < state.image.y + state.image.w;
    auto& sim = app.scene().sim();
    // The compare view's line: grabbed within 6 pixels, dragged across the image.
    CompareView& cmp = state.compare;
    const double lineX = state.image.x + cmp.split * state.image.z;
    if (cmp.on && down && (cmp.dragging || (!state.dragging && inImage && std::abs(x - lineX) <= 6 &&
                                            !ImGui::GetIO().WantCaptureMouse))) {
        cmp.dragging = true;
        cmp.split = std::clamp(float((x - state.image.x) / std::max(1, state.image.z)), 0.0f, 1.0f);
        state.lastX = x, state.lastY = y;
        return;
    }
    if (!down) cmp.dragging = false;
    if (down && (state.dragging || (inImage && !ImGui::GetIO().WantCaptureMouse))) {
        glm::vec3 origin, dir;
        app.camera().rayThrough(x - state.image.x, y - state.image.y, state.image.z, state.image.w, origin, dir);
        if (!state.dragging) {
            state.dragging = true;
            state.draggingTumbler = false;
            if (auto hit = sim.raycastTumblers(sim::Vec3(origin), sim::Vec3(dir))) {
                state.dragMode = sim.beginDrag(*hit);
                state.draggingTumbler = true;
            }
        } else if (state.draggingTumbler) {
            if (state.dragMode == sim::DragMode::Translate)
                sim.dragTo(sim::Vec3(origin), sim::Vec3(dir));
            else  // screen drag right tilts about −z (rolls right), drag down tilts about +x
                sim.dragRotate((y - state.lastY) * 0.01, -(x - state.lastX) * 0.01);
        } else {
            app.camera().yaw -= float(x - state.lastX) * 0.005f;
            app.camera().pitch = std::clamp(app.camera().pitch + float(y - state.lastY) * 0.005f, -1.2f, 1.2f);
        }
    } else if (state.dragging && !down) {
        if (state.draggingTumbler) sim.endDrag();
        state.dragging = state.draggingTumbler = false;
    }
    state.lastX = x, state.lastY = y;
}

}  // namespace kiln::app
