// The window's input: keys and the wheel act at once; the left button's press is noted
// where it happened (a slow frame may poll it only after the cursor moved on), and
// handleMouse turns it into a drag of the compare line, a tumbler or the camera.
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

#include <imgui_internal.h>

#include "app/window_state.hpp"

namespace kiln::app {

namespace {
// Whether a panel (an ImGui window drawn last frame) covers window pixel (x, y). Asked by
// position, not through io.WantCaptureMouse: ImGui learns of the cursor through the
// queue, a frame or more after the press handleMouse is deciding about.
bool overPanel(double x, double y) {
    const ImGuiContext& g = *ImGui::GetCurrentContext();
    const ImVec2 p{float(x), float(y)};
    for (const ImGuiWindow* w : g.Windows)
        if (w->Active && !w->Hidden && !(w->Flags & ImGuiWindowFlags_ChildWindow) && w->Rect().Contains(p)) return true;
    return false;
}

WindowState& stateOf(GLFWwindow* w) { return *static_cast<WindowState*>(glfwGetWindowUserPointer(w)); }
bool isModifier(int key) {
    return key == GLFW_KEY_LEFT_CONTROL || key == GLFW_KEY_RIGHT_CONTROL || key == GLFW_KEY_LEFT_SHIFT ||
           key == GLFW_KEY_RIGHT_SHIFT || key == GLFW_KEY_LEFT_ALT || key == GLFW_KEY_RIGHT_ALT ||
           key == GLFW_KEY_LEFT_SUPER || key == GLFW_KEY_RIGHT_SUPER;
}
}  // namespace

void UiInput::feed(ImGuiIO& io) {
    std::map<int, bool> changedKeys;
    bool keyChanged = false;  // a key other than a modifier went down or up this frame
    bool changedButtons[ImGuiMouseButton_COUNT] = {};
    while (!events.empty()) {
        const Event& e = events.front();
        if (e.kind == Kind::Move) {
            // After a press or release this frame, the cursor stays where it happened.
            if (std::any_of(std::begin(changedButtons), std::end(changedButtons), [](bool b) { return b; })) break;
            x = e.x, y = e.y;
        } else if (e.kind == Kind::Button) {
            if (e.code < 0 || e.code >= ImGuiMouseButton_COUNT) { events.pop_front(); continue; }
            if (changedButtons[e.code]) break;  // its second transition: next frame
            buttons[e.code] = e.down, changedButtons[e.code] = true;
        } else if (e.kind == Kind::Key) {
            // A key's second transition waits; so does a modifier changing after a key
            // went down or up this frame (Ctrl released right after A would hide the Ctrl).
            if (changedKeys[e.code] || (isModifier(e.code) && keyChanged)) break;
            keys[e.code] = e.down, changedKeys[e.code] = true;
            keyChanged |= !isModifier(e.code);
        } else if (e.kind == Kind::Char) {
            io.AddInputCharacter(e.ch);
        } else {
            io.MouseWheelH += float(e.x), io.MouseWheel += float(e.y);
        }
        events.pop_front();
    }
    io.MousePos = ImVec2(float(x), float(y));
    for (int b = 0; b < ImGuiMouseButton_COUNT; ++b) io.MouseDown[b] = buttons[b];
    for (auto& [key, down] : keys)
        if (key >= 0 && key < int(IM_ARRAYSIZE(io.KeysDown))) io.KeysDown[key] = down;
    auto held = [&](int a, int b) { return keys[a] || keys[b]; };
    io.KeyCtrl = held(GLFW_KEY_LEFT_CONTROL, GLFW_KEY_RIGHT_CONTROL);
    io.KeyShift = held(GLFW_KEY_LEFT_SHIFT, GLFW_KEY_RIGHT_SHIFT);
    io.KeyAlt = held(GLFW_KEY_LEFT_ALT, GLFW_KEY_RIGHT_ALT);
    io.KeySuper = held(GLFW_KEY_LEFT_SUPER, GLFW_KEY_RIGHT_SUPER);
}

void installCallbacks(GLFWwindow* window) {
    glfwSetScrollCallback(window, [](GLFWwindow* w, double dx, double dy) {
        WindowState& s = stateOf(w);
        s.uiInput.events.push_back({UiInput::Kind::Scroll, dx, dy});
        if (ImGui::GetIO().WantCaptureMouse) return;
        Camera& camera = s.app->camera();
        if (camera.mode == Camera::Mode::Fly) {  // a notch: 5 % of the scene's diagonal ahead
            const auto& scene = s.app->scene();
            camera.fly(glm::vec3(0.0f, 0.0f, float(dy) * 0.05f * glm::length(scene.boundsMax() - scene.boundsMin())));
            return;
        }
        camera.distance = std::clamp(camera.distance * float(std::pow(0.9, dy)), 1.5f, 10.0f);
    });
    glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
        WindowState& s = stateOf(w);
        s.uiInput.events.push_back({UiInput::Kind::Move, x, y});
        s.eventX = x, s.eventY = y;
    });
    glfwSetCharCallback(window, [](GLFWwindow* w, unsigned ch) {
        stateOf(w).uiInput.events.push_back({UiInput::Kind::Char, 0, 0, 0, false, ch});
    });
    glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
        WindowState& s = stateOf(w);
        s.uiInput.events.push_back({UiInput::Kind::Button, 0, 0, button, action == GLFW_PRESS});
        if (button == GLFW_MOUSE_BUTTON_RIGHT && action == GLFW_PRESS) {
            s.traceX = s.eventX, s.traceY = s.eventY;
            s.tracePending = true;
        }
        if (button != GLFW_MOUSE_BUTTON_LEFT || action != GLFW_PRESS) return;
        s.pressX = s.eventX, s.pressY = s.eventY;
        s.pressPending = true;
    });
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
        if (action != GLFW_REPEAT) stateOf(w).uiInput.events.push_back({UiInput::Kind::Key, 0, 0, key, action == GLFW_PRESS});
        if (action != GLFW_PRESS || ImGui::GetIO().WantCaptureKeyboard) return;
        auto* s = &stateOf(w);
        if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, 1);
        if (key == GLFW_KEY_F1) s->showDebug = !s->showDebug;
        if (key == GLFW_KEY_SPACE) s->app->paused = !s->app->paused;
        if (key == GLFW_KEY_PERIOD) s->app->singleStep = true;
        if (key == GLFW_KEY_M) s->app->scene().sim().spawnRandom(sim::BallKind::Marble);
        if (key == GLFW_KEY_F) s->app->scene().sim().spawnRandom(sim::BallKind::Fireball);
        if (key == GLFW_KEY_R) s->app->scene().reset();
        if (key == GLFW_KEY_C) {  // orbit ↔ fly
            Camera& c = s->app->camera();
            if (c.mode == Camera::Mode::Orbit) c.toFly();
            else c.toOrbit();
        }
    });
}

// W/S forward and back, A/D left and right, Q/E down and up (Shift: 4× as fast) at a
// quarter of the scene's diagonal a second: the camera flies from where it is.
void flyFromKeys(GLFWwindow* window, WindowState& state, double seconds) {
    if (ImGui::GetIO().WantCaptureKeyboard) return;
    auto down = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS ? 1.0f : 0.0f; };
    const glm::vec3 move(down(GLFW_KEY_D) - down(GLFW_KEY_A), down(GLFW_KEY_E) - down(GLFW_KEY_Q),
                         down(GLFW_KEY_W) - down(GLFW_KEY_S));
    if (move == glm::vec3(0.0f)) return;
    const auto& scene = state.app->scene();
    const float speed = 0.25f * glm::length(scene.boundsMax() - scene.boundsMin()) *
                        (down(GLFW_KEY_LEFT_SHIFT) + down(GLFW_KEY_RIGHT_SHIFT) > 0.0f ? 4.0f : 1.0f);
    state.app->camera().fly(move * (speed * float(std::min(seconds, 0.1))));
}

// Right button on the image: trace that pixel through the graph (panelTrace).
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
    auto inImageAt = [&](double px, double py) {
        return px >= state.image.x && py >= state.image.y && px < state.image.x + state.image.z &&
               py < state.image.y + state.image.w && !overPanel(px, py);
    };
    if (state.tracePending && inImageAt(state.traceX, state.traceY)) {
        // The centre of the window pixel under the cursor, y up.
        state.traceUv = glm::vec2((state.traceX - state.image.x + 0.5) / state.image.z,
                                  1.0 - (state.traceY - state.image.y + 0.5) / state.image.w);
        state.showTrace = true;
    }
    state.tracePending = false;
    const bool inImage = x >= state.image.x && y >= state.image.y && x < state.image.x + state.image.z &&
                         y < state.image.y + state.image.w;
    auto& sim = app.scene().sim();
    // The compare view's line: grabbed within 6 pixels, dragged across the image.
    CompareView& cmp = state.compare;
    const double lineX = state.image.x + cmp.split * state.image.z;
    if (cmp.on && down && (cmp.dragging || (!state.dragging && inImage && std::abs(x - lineX) <= 6 &&
                                            !overPanel(x, y)))) {
        cmp.dragging = true;
        cmp.split = std::clamp(float((x - state.image.x) / std::max(1, state.image.z)), 0.0f, 1.0f);
        state.lastX = x, state.lastY = y;
        return;
    }
    if (!down) cmp.dragging = false;
    if (down && (state.dragging || (inImage && !overPanel(x, y)))) {
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
