// The window front end: GLFW + Dear ImGui. The main loop, and the resolution budget
// that paces it. The debug view's panels sit in a sidebar left of the image, so the
// image is never under them by default (debug_panels.cpp); input is window_input.cpp,
// the script interface (--ui-probe, --screenshot) ui_probe.cpp.
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_internal.h>  // FindWindowByName, MovingWindow: a docked inspector the user drags out
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string_view>

#include "app/context.hpp"
#include "app/stop_signal.hpp"
#include "app/window_state.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace fs = std::filesystem;

// The resolution budget: steps of 0.8 / 1.25, at most one a second (and six frames), so
// a single slow frame (a shader rebuild) does not halve the resolution.
void followBudget(WindowState& state, double now) {
    // The first seconds build every program: not what the scene costs.
    // Six frames between changes, so the smoothed frame time has followed the last one.
    if (!state.autoScale || now < 3.0 || now - state.lastScaleChange < std::max(1.0, 6e-3 * state.frameMs)) return;
    // A step down that did not save 5 % of the frame: what is left is resolution-independent
    // work (shadow map, voxels); go back up a step and stay there.
    if (state.msBeforeDecrease > 0.0) {
        const bool helped = state.frameMs < state.msBeforeDecrease * 0.95;
        state.msBeforeDecrease = 0.0;
        // (Only at half resolution and below: above, a noisy frame time is no reason to stop.)
        if (!helped && state.renderScale <= 0.5f) {
            state.renderScale = std::min(1.0f, state.renderScale * 1.25f);
            state.scaleFloor = state.renderScale;
            state.lastScaleChange = now;
            return;
        }
    }
    if (state.frameMs > state.budgetMs * 1.2 && state.renderScale > state.scaleFloor) {
        state.msBeforeDecrease = state.frameMs;
        state.renderScale = std::max(state.scaleFloor, state.renderScale * 0.8f);
        state.lastScaleChange = now;
    } else if (state.frameMs < state.budgetMs * 0.5 && state.renderScale < 1.0f) {
        state.renderScale = std::min(1.0f, state.renderScale * 1.25f);
        state.lastScaleChange = now;
    }
}

namespace {

// The inspector windows open now, in column order.
std::vector<std::string> openInspectors(const WindowState& state) {
    std::vector<std::string> open;
    if (state.showTexture) open.push_back(kTextureWindow);
    if (state.showTrace && state.traceUv) open.push_back(kTraceWindow);
    if (state.showGraph) open.push_back(kGraphWindow);
    return open;
}

// Those of them in the column: the user has not dragged them out.
std::vector<std::string> dockedInspectors(const WindowState& state) {
    std::vector<std::string> docked;
    for (const std::string& name : openInspectors(state))
        if (!state.movedWindows.count(name)) docked.push_back(name);
    return docked;
}

}  // namespace

bool inspectorDocked(const WindowState& state, const std::string& name) {
    return state.inspector.z > 0 && !state.movedWindows.count(name);
}

void layOut(WindowState& state, int fbW, int fbH) {
    state.sidebarWidth = state.showDebug ? std::min(kSidebarWidth, fbW * 2 / 3) : 0;
    const int area = std::max(1, fbW - state.sidebarWidth);
    int column = state.showDebug && !dockedInspectors(state).empty() ? std::clamp(fbW * 3 / 10, 300, 460) : 0;
    if (area - column < std::max(240, area * 2 / 5)) column = 0;  // no room beside the image: they float
    state.inspector = {fbW - column, 0, column, fbH};
    const int w = std::max(1, area - column), h = std::max(1, fbH);
    int iw = w, ih = int(std::lround(w / state.imageAspect));
    if (ih > h) ih = h, iw = int(std::lround(h * state.imageAspect));
    iw = std::clamp(iw, 1, w), ih = std::clamp(ih, 1, h);
    state.image = {state.sidebarWidth + (w - iw) / 2, (h - ih) / 2, iw, ih};
}

void placeInspector(WindowState& state, const std::string& name) {
    if (!inspectorDocked(state, name)) return;
    const std::vector<std::string> docked = dockedInspectors(state);
    const auto at = std::find(docked.begin(), docked.end(), name);
    if (at == docked.end()) return;
    const float x = float(state.inspector.x), width = float(state.inspector.z), height = float(state.inspector.w);
    const size_t index = size_t(at - docked.begin()), n = docked.size();
    const float first = n == 1 ? height : height * 0.6f, rest = n == 1 ? 0.0f : (height - first) / float(n - 1);
    const float y = index == 0 ? 0.0f : first + rest * float(index - 1), h = index == 0 ? first : rest;
    // Dragged away from its slot (ImGui moved it this frame, before we place it): it floats
    // from now on, where the user puts it. A click that moves nothing keeps it docked.
    if (ImGuiWindow* w = ImGui::FindWindowByName(name.c_str());
        w && GImGui->MovingWindow && GImGui->MovingWindow->RootWindow == w &&
        std::max(std::abs(w->Pos.x - x), std::abs(w->Pos.y - y)) > 2.0f) {
        state.movedWindows.insert(name);
        ImGui::MarkIniSettingsDirty();
        return;
    }
    ImGui::SetNextWindowPos(ImVec2(x, y), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(width, h), ImGuiCond_Always);
}

namespace {

// $XDG_CONFIG_HOME/kiln/imgui.ini (else ~/.config/kiln/imgui.ini); "" when there is
// no such directory and it cannot be made (then nothing persists).
std::string imguiIniPath() {
    const char* xdg = std::getenv("XDG_CONFIG_HOME");
    const char* home = std::getenv("HOME");
    const fs::path dir = xdg && *xdg ? fs::path(xdg) / "kiln" : home && *home ? fs::path(home) / ".config/kiln" : fs::path();
    std::error_code ec;
    if (dir.empty() || (fs::create_directories(dir, ec), ec)) return "";
    return (dir / "imgui.ini").string();
}

// Which inspector windows the user dragged out of the column, kept in the ini file beside
// ImGui's own window places (a "[Kiln][Floating]" entry, one title a line), so a window
// put somewhere stays there in the next run.
void keepFloatingWindows(WindowState& state) {
    ImGuiSettingsHandler handler;
    handler.TypeName = "Kiln";
    handler.TypeHash = ImHashStr("Kiln");
    handler.UserData = &state;
    handler.ReadOpenFn = [](ImGuiContext*, ImGuiSettingsHandler*, const char* name) -> void* {
        return std::string_view(name) == "Floating" ? reinterpret_cast<void*>(1) : nullptr;
    };
    handler.ReadLineFn = [](ImGuiContext*, ImGuiSettingsHandler* h, void*, const char* line) {
        if (*line) static_cast<WindowState*>(h->UserData)->movedWindows.insert(line);
    };
    handler.WriteAllFn = [](ImGuiContext*, ImGuiSettingsHandler* h, ImGuiTextBuffer* out) {
        out->append("[Kiln][Floating]\n");
        for (const std::string& name : static_cast<WindowState*>(h->UserData)->movedWindows) out->appendf("%s\n", name.c_str());
        out->append("\n");
    };
    ImGui::GetCurrentContext()->SettingsHandlers.push_back(handler);
}

// Panel positions and sizes persist between runs in `ini` ("" : nowhere).
void startImGui(GLFWwindow* window, const std::string& ini, WindowState& state) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = ini.empty() ? nullptr : ini.c_str();
    keepFloatingWindows(state);  // before the first frame, which reads the file
    // No backend callbacks: ours queue GLFW's events and UiInput feeds them (window_state.hpp).
    ImGui_ImplGlfw_InitForOpenGL(window, false);
    ImGui_ImplOpenGL3_Init("#version 450 core");
}

// What the command line asks of the window at start.
void startState(WindowState& state, const Options& o, App& app) {
    state.app = &app;
    state.probe.path = o.uiProbe;
    state.mainShowsSelection = !o.view.empty();
    state.imageAspect = double(o.width) / double(o.height);
    state.showTexture = !o.view.empty();
    state.compare.on = fs::path(o.pipeline).filename() == "compare.json";
    state.autoScale = o.budgetMs > 0;
    state.budgetMs = o.budgetMs > 0 ? float(o.budgetMs) : state.budgetMs;
    std::string error;
    if (!state.viewer.init(app.runtime().shaders(), error)) log::error(error);
    if (!o.dump.empty()) state.viewer.setSaveDirectory(o.dump);
}

// The debug view over the image: the sidebar's panels and the error overlay.
void drawUi(WindowState& state, int fbW, int fbH) {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    state.uiInput.feed(ImGui::GetIO());
    ImGui::NewFrame();
    if (state.showDebug) drawSidebar(state);
    legendLabels(state);
    panelErrors(*state.app, state);
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbW, fbH);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace

int runWindow(const Options& o) {
    std::string error;
    // By default the panels get a column of their own beside an image of --size; the
    // image then takes the room the window leaves it, at --size's aspect.
    const int windowWidth = o.windowWidth ? o.windowWidth : o.width + kSidebarWidth;
    const int windowHeight = o.windowHeight ? o.windowHeight : o.height;
    auto context = WindowContext::create(windowWidth, windowHeight, "Kiln", true, error);
    if (!context) {
        std::fprintf(stderr, "kiln: error: %s; without a display use --headless (or run under xvfb-run)\n", error.c_str());
        return 1;
    }
    log::info("window: ", context->description());
    App app;
    if (!app.init(o, error)) {
        std::fprintf(stderr, "kiln: error: %s\n", error.c_str());
        return 1;
    }
    WindowState state;
    startState(state, o, app);
    GLFWwindow* window = context->window();
    glfwSetWindowUserPointer(window, &state);
    installCallbacks(window);  // ours first: ImGui's GLFW backend chains to the callbacks it finds
    const std::string ini = imguiIniPath();  // outlives ImGui, which keeps a pointer to it
    startImGui(window, ini, state);

    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    Clock::time_point last = start;
    catchStopSignals();  // Ctrl+C in the terminal closes the window as Esc does: the layout is saved
    for (int frames = 1; !glfwWindowShouldClose(window) && !stopSignalled; ++frames) {
        glfwPollEvents();
        int fbW, fbH;
        glfwGetFramebufferSize(window, &fbW, &fbH);
        layOut(state, fbW, fbH);
        handleMouse(window, state);
        const Clock::time_point now = Clock::now();
        const double wall = std::chrono::duration<double>(now - last).count();
        last = now;
        flyFromKeys(window, state, wall);
        state.frameMs = frames == 1 ? wall * 1e3 : state.frameMs * 0.8 + wall * 1e3 * 0.2;
        followBudget(state, std::chrono::duration<double>(now - start).count());
        app.resize(std::max(1, int(std::lround(state.image.z * state.renderScale))),
                   std::max(1, int(std::lround(state.image.w * state.renderScale))));
        // What the compare view reads is asked for, so it is written.
        app.alsoRead = state.compare.on ? std::vector<std::string>{state.compare.a, state.compare.b}
                                        : std::vector<std::string>{};
        // The first frame steps once, as headless does; then the wall clock leads.
        app.frame(frames == 1 ? -1.0 : wall);
        drawImage(state, fbW, fbH);

        drawUi(state, fbW, fbH);
        state.probe.write(probeState(state, uint64_t(frames)));
        if (!o.screenshot.empty() && frames == o.frames) {
            saveScreenshot(o.screenshot, fbW, fbH);
            glfwSetWindowShouldClose(window, 1);
        }
        glfwSwapBuffers(window);
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    return stopSignalled ? exitStatusAfterStop() : 0;
}

}  // namespace kiln::app
