#include "app/context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>

#include <vector>

#include "kiln/gl.hpp"

namespace kiln::app {

namespace {
std::string glDescription() {
    auto s = [](GLenum e) {
        const GLubyte* v = glGetString(e);
        return v ? std::string(reinterpret_cast<const char*>(v)) : std::string("?");
    };
    return s(GL_VERSION) + " / " + s(GL_RENDERER);
}

// Surfaceless first (Mesa, llvmpipe); on a GPU machine whose EGL lacks it, the
// device platform gives the same offscreen context.
EGLDisplay openDisplay(std::string& tried) {
    auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!getPlatformDisplay) {
        tried = "eglGetPlatformDisplayEXT unavailable";
        return EGL_NO_DISPLAY;
    }
    EGLDisplay dpy = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (dpy != EGL_NO_DISPLAY && eglInitialize(dpy, &major, &minor)) return dpy;
    tried = "surfaceless platform failed";
    auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    if (!queryDevices) return EGL_NO_DISPLAY;
    EGLDeviceEXT devices[8];
    EGLint count = 0;
    if (!queryDevices(8, devices, &count)) return EGL_NO_DISPLAY;
    for (EGLint i = 0; i < count; ++i) {
        dpy = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (dpy != EGL_NO_DISPLAY && eglInitialize(dpy, &major, &minor)) return dpy;
    }
    tried += "; no EGL device platform display either";
    return EGL_NO_DISPLAY;
}
}  // namespace

std::unique_ptr<HeadlessContext> HeadlessContext::create(bool debug, std::string& error) {
    std::string tried;
    EGLDisplay dpy = openDisplay(tried);
    if (dpy == EGL_NO_DISPLAY) {
        error = "EGL: no headless display (" + tried + ")";
        return nullptr;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        error = "EGL: eglBindAPI(EGL_OPENGL_API) failed";
        return nullptr;
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4,
                              EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_CONTEXT_OPENGL_DEBUG, debug ? EGL_TRUE : EGL_FALSE,
                              EGL_NONE};
    // Configless (EGL_KHR_no_config_context): we only ever render into FBOs.
    EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT) {
        error = "EGL: cannot create an OpenGL 4.5 core context (error 0x" + std::to_string(eglGetError()) + ")";
        eglTerminate(dpy);
        return nullptr;
    }
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        error = "EGL: eglMakeCurrent without a surface failed";
        eglDestroyContext(dpy, ctx);
        eglTerminate(dpy);
        return nullptr;
    }
    auto out = std::unique_ptr<HeadlessContext>(new HeadlessContext());
    out->display_ = dpy;
    out->context_ = ctx;
    if (gl::loadGL(reinterpret_cast<GLADloadfunc>(eglGetProcAddress)) < 45) {
        error = "OpenGL 4.5 core is required; the EGL context offers less";
        return nullptr;
    }
    out->description_ = glDescription();
    if (debug) gl::installDebugCallback();
    return out;
}

HeadlessContext::~HeadlessContext() {
    if (display_) {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (context_) eglDestroyContext(display_, context_);
        eglTerminate(display_);
        eglReleaseThread();
    }
}

std::unique_ptr<WindowContext> WindowContext::create(int width, int height, const std::string& title, bool debug,
                                                     std::string& error) {
    glfwSetErrorCallback([](int code, const char* msg) { (void)code; (void)msg; });
    if (!glfwInit()) {
        const char* why = nullptr;
        glfwGetError(&why);
        error = std::string("GLFW: cannot initialise (") + (why ? why : "no display?") + ")";
        return nullptr;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, debug ? GLFW_TRUE : GLFW_FALSE);
    GLFWwindow* w = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!w) {
        const char* why = nullptr;
        glfwGetError(&why);
        error = std::string("GLFW: cannot open a 4.5 core window (") + (why ? why : "?") + ")";
        glfwTerminate();
        return nullptr;
    }
    glfwMakeContextCurrent(w);
    glfwSwapInterval(0);
    auto out = std::unique_ptr<WindowContext>(new WindowContext());
    out->window_ = w;
    if (gl::loadGL(reinterpret_cast<GLADloadfunc>(glfwGetProcAddress)) < 45) {
        error = "OpenGL 4.5 core is required; the window's context offers less";
        return nullptr;
    }
    out->description_ = glDescription();
    if (debug) gl::installDebugCallback();
    return out;
}

WindowContext::~WindowContext() {
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
}

}  // namespace kiln::app
