// app/window_state.hpp — what the window keeps between frames, shared by its parts:
// the debug view's panels (debug_panels.cpp), mouse and keys (window_input.cpp), the
// script interface (ui_probe.cpp) and the main loop with its resolution budget
// (window.cpp).
#pragma once

#include <imgui.h>
#include <nlohmann/json.hpp>

#include <cfloat>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/app.hpp"
#include "app/compare_view.hpp"
#include "app/pixel_trace.hpp"
#include "app/texture_viewer.hpp"
#include "graph/pipeline.hpp"

struct GLFWwindow;

namespace kiln::app {

inline constexpr int kSidebarWidth = 380;  // the panels' column, left of the image
// The inspector windows' titles (ImGui identifies a window by it), in column order.
inline constexpr const char* kTextureWindow = "Texture";
inline constexpr const char* kTraceWindow = "Pixel trace (right-click the image)";
inline constexpr const char* kGraphWindow = "Graph";

// Where each widget a script may want to click is, and what the texture readout says,
// written to --ui-probe FILE every frame (tests drive the window with xdotool).
struct UiProbe {
    std::string path;
    nlohmann::json widgets = nlohmann::json::object();

    bool on() const { return !path.empty(); }
    void item(const std::string& id) {
        if (!on() || !ImGui::IsItemVisible()) return;  // scrolled away or clipped: not clickable
        const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
        widgets[id] = {a.x, a.y, b.x, b.y};
    }
    // Writes `state` with the widgets seen since the last write, atomically.
    void write(nlohmann::json state);
};

// Edits of the running pipeline: toggles recompile an edited description, parameter
// values go through Runtime::setParam (no recompile). The file changes only on "write back".
struct PipelineEditor {
    std::string error;
    std::string selected;  // pass id whose parameters are shown

    bool apply(App& app, const std::function<void(graph::PipelineDesc&)>& edit);
    void setParam(App& app, const std::string& pass, const std::string& name, const ParamValue& v);
    // Only the edited values change in the file (key order, layout and notes stay).
    void writeBack(App& app);
};

// What ImGui is fed, in the order GLFW reported it. ImGui 1.86 predates the input queue
// of 1.87: its backend writes key states as they come and polls the cursor and buttons
// when a frame starts, so between two slow frames a key pressed and released is lost and
// a click lands where the cursor went next. The queue replays one transition of each key
// or button per frame, each at the cursor position it happened at.
struct UiInput {
    enum class Kind : uint8_t { Move, Button, Key, Char, Scroll };
    struct Event {
        Kind kind;
        double x = 0, y = 0;  // Move: the position; Scroll: the offsets
        int code = 0;         // the button or key
        bool down = false;
        unsigned ch = 0;
    };
    std::deque<Event> events;
    // What ImGui has been told so far.
    double x = -FLT_MAX, y = -FLT_MAX;
    bool buttons[ImGuiMouseButton_COUNT] = {};
    std::map<int, bool> keys;
    // Feeds ImGui the events of one frame (call between the backend's NewFrame and
    // ImGui::NewFrame, which it overrides).
    void feed(ImGuiIO& io);
};

struct WindowState {
    App* app = nullptr;
    bool showDebug = true;
    bool showTexture = false, showGraph = false;
    bool mainShowsSelection = false;  // the image shows the selected texture, not the output
    bool dragging = false;
    bool draggingTumbler = false;
    sim::DragMode dragMode = sim::DragMode::Translate;
    double lastX = 0, lastY = 0;
    // Where the left button went down (the callback sees it when it happens): a slow
    // frame may poll the button only after the cursor has moved on, and what the press
    // grabs (the compare line, a tumbler) is decided where it was pressed.
    bool pressPending = false;
    double pressX = 0, pressY = 0;
    double eventX = 0, eventY = 0;  // the cursor as of the last motion event handled
                                    // (glfwGetCursorPos is the pointer now, later events included)
    // The layout (window.cpp layOut): the sidebar on the left, the image at the aspect it
    // was started with, fitted and centred in what is left, and a column on the right for
    // the inspector windows (texture, trace, graph) while one is open and not moved by the
    // user, so none covers the image unless the user puts it there.
    int sidebarWidth = 0;
    double imageAspect = 1.0;         // width / height, from --size
    glm::ivec4 image{0};              // where the image is, window pixels from the top left
    glm::ivec4 inspector{0};          // the inspector column (width 0: none, they float)
    std::set<std::string> movedWindows;  // inspector windows the user dragged out of the column
    std::string wantTab;              // the sidebar tab to bring forward next frame
    std::string lastSelectedPass;
    bool lastCompareOn = false;
    float sharedSplit = 0.5f;         // the compare line and error passes' "split" (shareSplit)
    // The pixel trace: a right click on the image picks the pixel (traced every frame
    // while its window is open, so the values follow the scene).
    bool tracePending = false;
    double traceX = 0, traceY = 0;    // where the right button went down
    std::optional<glm::vec2> traceUv;
    bool showTrace = false;
    bool showRedraw = false;          // outline the part of the picture the last frame redrew
    PixelTrace trace;
    TextureViewer viewer;
    CompareView compare;
    PipelineEditor editor;
    // Int parameter values being dragged (applied on release), by "pass.param".
    std::map<std::string, ParamValue> pendingInts;
    UiProbe probe;
    UiInput uiInput;
    ImGuiTextFilter textureFilter;  // the Textures panel's filter
    // The resolution budget: render at renderScale × the image area; with autoScale
    // the scale follows the frame time toward budgetMs.
    float renderScale = 1.0f;
    bool autoScale = true;
    float budgetMs = 100.0f;
    double frameMs = 0.0;             // smoothed wall time per frame
    double lastScaleChange = 0.0;
    double msBeforeDecrease = 0.0;    // frame time before the last step down (0: none pending)
    // The budget never takes the image below half size on its own (a busy machine would
    // otherwise leave a pixelated first image); the slider, with the budget off, goes to 1/8.
    static constexpr float kAutoScaleFloor = 0.5f;
    float scaleFloor = kAutoScaleFloor;  // raised where fewer pixels stopped buying time
    std::vector<std::string> pipelines;  // *.json beside the running pipeline
};

// window.cpp: where the sidebar, the image and the inspector column go for a window
// of fbW × fbH pixels (sets sidebarWidth, image, inspector).
void layOut(WindowState&, int fbW, int fbH);
// Inspector windows in the column, in this order: the first gets 60 % of its height when
// others share it, the rest split what is left. Each call places `name` (before its Begin)
// unless the user has dragged it out, or the window has no column: then it floats.
bool inspectorDocked(const WindowState&, const std::string& name);
void placeInspector(WindowState&, const std::string& name);

// window.cpp: moves renderScale toward the budget after a frame ending at `now` seconds
// (frameMs already updated); never below scaleFloor on its own.
void followBudget(WindowState&, double now);

// debug_panels.cpp: the sidebar's panels, the error overlay, the image.
void drawSidebar(WindowState&);
void panelErrors(const App&, WindowState&);
void drawImage(WindowState&, int framebufferWidth, int framebufferHeight);
// inspectors.cpp: the graph view, the pixel trace, the error legend's labels, the split
// the compare line and the error pass share.
void panelGraph(WindowState&, bool* open);
void panelTrace(WindowState&);
void shareSplit(WindowState&);
void legendLabels(WindowState&);

// window_input.cpp: keys, wheel and button events, and the left button's drags.
void installCallbacks(GLFWwindow*);
void handleMouse(GLFWwindow*, WindowState&);
void flyFromKeys(GLFWwindow*, WindowState&, double seconds);

// ui_probe.cpp: what --ui-probe writes each frame, and --screenshot.
nlohmann::json probeState(const WindowState&, uint64_t frame);
void saveScreenshot(const std::string& path, int width, int height);

}  // namespace kiln::app
