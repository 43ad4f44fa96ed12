// app/context.hpp — the two ways Kiln gets an OpenGL 4.5 core context:
// headless through EGL (surfaceless platform; the device platform on a GPU machine)
// and a GLFW window. Both load the one glad loader in libkiln_core.
#pragma once

#include <memory>
#include <string>

struct GLFWwindow;

namespace kiln::app {

class HeadlessContext {
public:
    // Creates and makes current a 4.5 core context; null with `error` on failure.
    static std::unique_ptr<HeadlessContext> create(bool debug, std::string& error);
    ~HeadlessContext();
    const std::string& description() const { return description_; }

private:
    HeadlessContext() = default;
    void* display_ = nullptr;
    void* context_ = nullptr;
    std::string description_;
};

class WindowContext {
public:
    static std::unique_ptr<WindowContext> create(int width, int height, const std::string& title, bool debug,
                                                 std::string& error);
    ~WindowContext();
    GLFWwindow* window() const { return window_; }
    const std::string& description() const { return description_; }

private:
    WindowContext() = default;
    GLFWwindow* window_ = nullptr;
    std::string description_;
};

}  // namespace kiln::app
