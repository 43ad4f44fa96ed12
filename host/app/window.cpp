// The window front end: GLFW + Dear ImGui. The debug view is one ImGui window per panel
// (passes, textures, scene, graph, errors, and the texture viewer), each reading the
// host's state every frame (immediate mode, nothing to keep in sync). The panels sit
// in a sidebar left of the image, so the image is never under them by default; the
// graph is rendered at the size of what is left (times the resolution scale).
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "graph/pipeline.hpp"

#include "app/app.hpp"
#include "app/compare_view.hpp"
#include "app/context.hpp"
#include "app/texture_viewer.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace {

namespace fs = std::filesystem;

constexpr int kSidebarWidth = 380;  // the panels' column, left of the image

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
    void write(nlohmann::json state) {
        if (!on()) return;
        state["widgets"] = std::move(widgets);
        widgets = nlohmann::json::object();
        const std::string tmp = path + ".tmp";
        std::ofstream(tmp) << state.dump(1);
        std::error_code ec;
        fs::rename(tmp, path, ec);  // readers never see half a file
    }
};

// Edits of the running pipeline: toggles recompile an edited description, parameter
// values go through Runtime::setParam (no recompile). The file changes only on "write back".
struct PipelineEditor {
    std::string error;
    std::string selected;  // pass id whose parameters are shown

    bool apply(App& app, const std::function<void(graph::PipelineDesc&)>& edit) {
        Runtime& rt = app.runtime();
        if (!rt.pipelineDesc()) return false;
        graph::PipelineDesc desc = *rt.pipelineDesc();
        edit(desc);
        std::string errors;
        if (!rt.loadPipelineDesc(std::move(desc), errors)) {
            error = errors;  // the running plan stays
            return false;
        }
        error.clear();
        return true;
    }
    void setParam(App& app, const std::string& pass, const std::string& name, const ParamValue& v) {
        std::string e;
        if (app.runtime().setParam(pass, name, v, e)) error.clear();
        else error = e;
    }
    // Only the edited values change in the file (key order, layout and notes stay).
    void writeBack(App& app) {
        Runtime& rt = app.runtime();
        if (!rt.pipelineDesc()) return;
        std::string why;
        std::optional<std::string> text = graph::patchPipelineText(rt.pipelineText(), *rt.pipelineDesc(), why);
        if (!text) {
            error = rt.pipelineFile() + ": not written back: " + why;
            return;
        }
        std::ofstream out(rt.pipelineFile(), std::ios::binary | std::ios::trunc);
        if (!out || !(out << *text)) error = rt.pipelineFile() + ": cannot write";
        else error.clear(), log::info("wrote ", rt.pipelineFile());
    }
};

// Ints apply when the slider is released: passes bake some into #defines, and a
// program per intermediate value is a stall per frame of the drag. Floats apply live.
bool paramWidget(const ParamDecl& decl, ParamValue& edited) {
    const char* label = decl.name.c_str();
    const bool bounded = decl.max > decl.min;
    switch (decl.type) {
        case ParamType::Bool: return ImGui::Checkbox(label, &std::get<bool>(edited));
        case ParamType::Int: {
            int& v = std::get<int>(edited);
            if (!decl.intChoices.empty()) {
                bool changed = false;
                if (ImGui::BeginCombo(label, std::to_string(v).c_str())) {
                    for (int c : decl.intChoices)
                        if (ImGui::Selectable(std::to_string(c).c_str(), c == v)) v = c, changed = true;
                    ImGui::EndCombo();
                }
                return changed;
            }
            if (bounded) ImGui::SliderInt(label, &v, int(decl.min), int(decl.max));
            else ImGui::InputInt(label, &v);
            return ImGui::IsItemDeactivatedAfterEdit();
        }
        case ParamType::Float:
            return bounded ? ImGui::SliderFloat(label, &std::get<float>(edited), float(decl.min), float(decl.max), "%.4g")
                           : ImGui::DragFloat(label, &std::get<float>(edited), 0.01f);
        case ParamType::Enum: {
            std::string& v = std::get<std::string>(edited);
            bool changed = false;
            if (ImGui::BeginCombo(label, v.c_str())) {
                for (auto& c : decl.choices)
                    if (ImGui::Selectable(c.c_str(), c == v)) v = c, changed = true;
                ImGui::EndCombo();
            }
            return changed;
        }
        case ParamType::Color: return ImGui::ColorEdit3(label, std::get<Color3>(edited).data());
    }
    return false;
}

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
    glm::ivec4 image{0};              // where the image is, window pixels from the top left
    TextureViewer viewer;
    CompareView compare;
    PipelineEditor editor;
    // Int parameter values being dragged (applied on release), by "pass.param".
    std::map<std::string, ParamValue> pendingInts;
    UiProbe probe;
    // The resolution budget: render at renderScale × the image area; with autoScale
    // the scale follows the frame time toward budgetMs.
    float renderScale = 1.0f;
    bool autoScale = true;
    float budgetMs = 100.0f;
    double frameMs = 0.0;             // smoothed wall time per frame
    double lastScaleChange = 0.0;
    double msBeforeDecrease = 0.0;    // frame time before the last step down (0: none pending)
    float scaleFloor = 0.125f;        // below this, fewer pixels stopped buying time
    std::vector<std::string> pipelines;  // *.json beside the running pipeline
};

void panelParams(WindowState& state) {
    App& app = *state.app;
    PipelineEditor& editor = state.editor;
    const graph::Plan* plan = app.runtime().plan();
    const int index = plan ? plan->find(editor.selected) : -1;
    if (index < 0) {
        ImGui::TextDisabled("select a pass for its parameters");
        return;
    }
    // A copy: a toggle below may swap the running plan, and with it this entry.
    const graph::PlannedPass pass = plan->passes[size_t(index)];
    ImGui::PushID("params");
    ImGui::PushID(pass.id.c_str());
    ImGui::Text("%s (%s)", pass.id.c_str(), pass.module.c_str());
    ImGui::SameLine();
    if (ImGui::SmallButton("write back")) editor.writeBack(app);
    state.probe.item("write-back");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("writes the edited values (only those) into %s", app.runtime().pipelineFile().c_str());
    for (const ParamDecl& decl : pass.decl.params) {
        const ParamValue* current = pass.params.find(decl.name);
        if (!current) continue;
        const std::string key = pass.id + "." + decl.name;
        auto pending = state.pendingInts.find(key);
        ParamValue edited = pending != state.pendingInts.end() ? pending->second : *current;
        const bool changed = paramWidget(decl, edited);
        state.probe.item("param:" + key);
        if (decl.type == ParamType::Int && ImGui::IsItemActive()) state.pendingInts[key] = edited;
        else if (pending != state.pendingInts.end() && !changed) state.pendingInts.erase(pending);
        if (!decl.doc.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", decl.doc.c_str());
        if (changed) {
            state.pendingInts.erase(key);
            editor.setParam(app, pass.id, decl.name, edited);
        }
    }
    ImGui::PopID();
    ImGui::PopID();
}

void listPipelines(WindowState& state) {
    state.pipelines.clear();
    std::error_code ec;
    const fs::path dir = fs::path(state.app->runtime().pipelineFile()).parent_path();
    for (auto& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, ec))
        if (e.path().extension() == ".json" && e.path().filename() != "pipeline.schema.json")
            state.pipelines.push_back(e.path().string());
    std::sort(state.pipelines.begin(), state.pipelines.end());
}

void pipelineSwitcher(WindowState& state) {
    App& app = *state.app;
    const std::string current = fs::path(app.runtime().pipelineFile()).filename().string();
    ImGui::SetNextItemWidth(-60);
    if (ImGui::BeginCombo("##pipeline", current.c_str())) {
        if (ImGui::IsWindowAppearing()) listPipelines(state);
        for (const std::string& p : state.pipelines) {
            const std::string name = fs::path(p).filename().string();
            if (ImGui::Selectable(name.c_str(), name == current)) {
                std::string errors;
                if (app.runtime().loadPipeline(p, errors)) {
                    state.editor.error.clear();  // live reload follows runtime().pipelineFile()
                    if (name == "compare.json") state.compare.on = true;
                } else {
                    state.editor.error = errors;  // the running pipeline stays
                }
            }
            state.probe.item("pipeline:" + name);
        }
        ImGui::EndCombo();
    }
    state.probe.item("pipeline-switcher");
}

void panelPasses(WindowState& state) {
    App& app = *state.app;
    PipelineEditor& editor = state.editor;
    pipelineSwitcher(state);
    ImGui::SameLine();
    if (ImGui::SmallButton("graph")) state.showGraph = !state.showGraph;
    state.probe.item("show-graph");
    ImGui::SameLine();
    if (ImGui::SmallButton("compare")) state.compare.on = !state.compare.on;
    state.probe.item("show-compare");
    if (ImGui::BeginTable("passes", 4, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit)) {
        ImGui::TableSetupColumn("pass", ImGuiTableColumnFlags_WidthStretch);
        ImGui::TableSetupColumn("state");
        ImGui::TableSetupColumn("GPU ms");
        ImGui::TableSetupColumn("CPU ms");
        ImGui::TableHeadersRow();
        double gpuTotal = 0, cpuTotal = 0;
        const graph::Plan* plan = app.runtime().plan();
        for (auto& r : app.runtime().stats()) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            const int index = plan ? plan->find(r.id) : -1;
            bool enabled = index >= 0 && plan->passes[size_t(index)].state != graph::PassState::Disabled;
            ImGui::PushID(r.id.c_str());
            if (ImGui::Checkbox("##on", &enabled))
                editor.apply(app, [&](graph::PipelineDesc& d) {
                    if (int i = d.find(r.id); i >= 0) d.passes[size_t(i)].enabled = enabled;
                });
            state.probe.item("pass-enabled:" + r.id);
            ImGui::SameLine();
            if (ImGui::Selectable(r.id.c_str(), editor.selected == r.id)) editor.selected = r.id;
            state.probe.item("pass:" + r.id);
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("module %s", r.module.c_str());
            ImGui::PopID();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(r.state.c_str());
            if (!r.why.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", r.why.c_str());
            // What ran this frame costs its rolling average; a skipped, culled or disabled
            // pass costs nothing and shows a dash, never its last figure.
            ImGui::TableNextColumn();
            if (r.ranThisFrame && r.gpuMs >= 0) ImGui::Text("%.2f", r.gpuMs), gpuTotal += r.gpuMs;
            else ImGui::TextDisabled("-");
            ImGui::TableNextColumn();
            if (r.ranThisFrame) ImGui::Text("%.2f", r.cpuMs), cpuTotal += r.cpuMs;
            else ImGui::TextDisabled("-");
        }
        ImGui::EndTable();
        ImGui::Text("this frame: GPU %.2f ms, CPU %.2f ms", gpuTotal, cpuTotal);
    }
    if (!editor.error.empty()) {
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", editor.error.c_str());
        ImGui::PopTextWrapPos();
    }
}

void panelTextures(WindowState& state) {
    App& app = *state.app;
    if (ImGui::RadioButton("image: graph output", !state.mainShowsSelection)) state.mainShowsSelection = false;
    ImGui::SameLine();
    if (ImGui::RadioButton("selected texture", state.mainShowsSelection)) state.mainShowsSelection = true;
    static ImGuiTextFilter filter;
    filter.Draw("filter", 160);
    state.probe.item("texture-filter");
    for (auto& t : app.runtime().textures()) {
        const std::string name = t.pass + "." + t.name;
        if (!filter.PassFilter(name.c_str())) continue;
        const std::string label = name + (t.internal ? " (internal)" : "") + "  " + std::to_string(t.ref.width) + "x" +
                                  std::to_string(t.ref.height) +
                                  (t.ref.target == GL_TEXTURE_3D ? "x" + std::to_string(t.ref.depth) : "") + " " +
                                  gl::formatName(t.ref.format);
        // Selecting a texture un-culls its producer (from the next frame on), as --view does.
        if (ImGui::Selectable(label.c_str(), app.viewed == name)) app.viewed = name, state.showTexture = true;
        state.probe.item("texture:" + name);
    }
    if (!app.viewed.empty() && ImGui::SmallButton("clear selection")) app.viewed.clear();
}

void panelScene(WindowState& state) {
    App& app = *state.app;
    auto& sim = app.scene().sim();
    ImGui::Checkbox("paused (Space)", &app.paused);
    state.probe.item("paused");
    ImGui::SameLine();
    if (ImGui::Button("step (.)")) app.singleStep = true;
    ImGui::SameLine();
    if (ImGui::Button("reset (R)")) app.scene().reset();
    if (ImGui::Button("marble (M)")) sim.spawnRandom(sim::BallKind::Marble);
    ImGui::SameLine();
    if (ImGui::Button("fireball (F)")) sim.spawnRandom(sim::BallKind::Fireball);
    float scale = float(app.timeScale);
    if (ImGui::SliderFloat("time scale", &scale, 0.05f, 4.0f, "%.2fx", ImGuiSliderFlags_Logarithmic)) app.timeScale = scale;
    ImGui::Text("t = %.2f s, %d steps this frame, %zu balls, %zu particles", app.scene().time(), app.lastSteps,
                sim.balls().size(), sim.particles().size());
    if (app.droppedSeconds > 0)
        ImGui::TextDisabled("%.1f s of simulated time dropped (frames slower than %d steps)", app.droppedSeconds,
                            App::kMaxStepsPerFrame);
    ImGui::Separator();
    ImGui::Text("%.1f ms per frame (%.1f fps), rendering %dx%d", state.frameMs, state.frameMs > 0 ? 1000.0 / state.frameMs : 0.0,
                int(state.image.z * state.renderScale), int(state.image.w * state.renderScale));
    ImGui::Checkbox("resolution follows the budget", &state.autoScale);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("lowers the render resolution while frames take longer than the budget");
    ImGui::SetNextItemWidth(120);
    if (ImGui::SliderFloat("budget ms", &state.budgetMs, 16.0f, 500.0f, "%.0f")) state.scaleFloor = 0.125f;
    if (!state.autoScale) ImGui::SliderFloat("resolution scale", &state.renderScale, 0.125f, 1.0f, "%.3f");
    else ImGui::Text("resolution scale %.3f", state.renderScale);
    ImGui::TextDisabled("drag a tumbler: low to move it, high to tilt it");
}

// Passes as nodes in columns by dependency depth, bindings as edges.
void panelGraph(WindowState& state, bool* open) {
    App& app = *state.app;
    const graph::Plan* plan = app.runtime().plan();
    ImGui::SetNextWindowPos(ImVec2(float(state.image.x) + 8, float(state.image.y) + 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(640, 320), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Graph", open) || !plan) {
        ImGui::End();
        return;
    }
    const size_t n = plan->passes.size();
    std::vector<int> column(n, 0), row(n, 0);
    for (size_t i = 0; i < n; ++i)  // file order is execution order: producers come first
        for (const graph::Binding& b : plan->passes[i].bindings)
            if (b.bound()) column[i] = std::max(column[i], column[size_t(b.producer)] + 1);
    std::map<int, int> rowsInColumn;
    for (size_t i = 0; i < n; ++i) row[i] = rowsInColumn[column[i]]++;
    std::map<std::string, bool> ran;
    for (auto& r : app.runtime().stats()) ran[r.id] = r.ranThisFrame;

    ImGui::TextDisabled("green ran, blue skipped (nothing it reads changed), grey culled, red disabled; click to select");
    const ImVec2 nodeSize(150, 46), gap(60, 18);
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    auto nodePos = [&](size_t i) {
        return ImVec2(origin.x + 8 + column[i] * (nodeSize.x + gap.x), origin.y + 8 + row[i] * (nodeSize.y + gap.y));
    };
    ImDrawList* draw = ImGui::GetWindowDrawList();
    for (size_t i = 0; i < n; ++i)
        for (const graph::Binding& b : plan->passes[i].bindings) {
            if (!b.bound()) continue;
            const ImVec2 a = nodePos(size_t(b.producer)), c = nodePos(i);
            const ImVec2 from(a.x + nodeSize.x, a.y + nodeSize.y * 0.5f), to(c.x, c.y + nodeSize.y * 0.5f);
            draw->AddBezierCubic(from, ImVec2(from.x + 30, from.y), ImVec2(to.x - 30, to.y), to, IM_COL32(180, 180, 190, 200), 1.5f);
        }
    for (size_t i = 0; i < n; ++i) {
        const graph::PlannedPass& p = plan->passes[i];
        const ImVec2 a = nodePos(i), b(a.x + nodeSize.x, a.y + nodeSize.y);
        // run this frame: green; skipped (nothing it reads changed): blue; culled: grey; disabled: red.
        ImU32 fill = p.state == graph::PassState::Disabled ? IM_COL32(110, 40, 40, 255)
                     : p.state == graph::PassState::Culled ? IM_COL32(70, 70, 70, 255)
                     : ran[p.id]                           ? IM_COL32(40, 110, 60, 255)
                                                           : IM_COL32(40, 70, 120, 255);
        draw->AddRectFilled(a, b, fill, 4.0f);
        if (p.id == state.editor.selected) draw->AddRect(a, b, IM_COL32(255, 220, 80, 255), 4.0f, 0, 2.0f);
        draw->AddText(ImVec2(a.x + 6, a.y + 4), IM_COL32_WHITE, p.id.c_str());
        const std::string sub = p.module + " - " + toString(p.state);
        draw->AddText(ImVec2(a.x + 6, a.y + 24), IM_COL32(210, 210, 210, 255), sub.c_str());
        ImGui::SetCursorScreenPos(a);
        ImGui::PushID(int(i));
        if (ImGui::InvisibleButton("node", nodeSize)) state.editor.selected = p.id;
        if (ImGui::IsItemHovered() && !p.reason.empty()) ImGui::SetTooltip("%s", p.reason.c_str());
        state.probe.item("graph-node:" + p.id);
        ImGui::PopID();
    }
    ImGui::End();
}

void panelErrors(const App& app, WindowState& state) {
    auto errors = app.runtime().activeErrors();
    if (errors.empty()) return;
    const ImGuiIO& io = ImGui::GetIO();
    const float x = float(state.image.x) + 8, width = std::max(200.0f, float(state.image.z) - 16);
    ImGui::SetNextWindowPos(ImVec2(x, io.DisplaySize.y - 8), ImGuiCond_Always, ImVec2(0, 1));
    ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0), ImVec2(width, io.DisplaySize.y * 0.5f));
    ImGui::SetNextWindowBgAlpha(0.88f);
    ImGui::Begin("errors", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::PushTextWrapPos(0.0f);  // long lines wrap at the window's edge
    for (auto& e : errors) ImGui::TextColored(ImVec4(1, 0.45f, 0.45f, 1), "%s", e.c_str());
    ImGui::PopTextWrapPos();
    ImGui::End();
}

void drawSidebar(WindowState& state) {
    App& app = *state.app;
    const ImGuiIO& io = ImGui::GetIO();
    const float h = io.DisplaySize.y;
    auto place = [&](float y, float height) {
        ImGui::SetNextWindowPos(ImVec2(0, y), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(float(kSidebarWidth), height), ImGuiCond_FirstUseEver);
    };
    place(0, h * 0.36f);
    if (ImGui::Begin("Passes (F1 hides the panels)")) panelPasses(state);
    ImGui::End();
    place(h * 0.36f, h * 0.24f);
    if (ImGui::Begin("Parameters")) panelParams(state);
    ImGui::End();
    place(h * 0.6f, h * 0.22f);
    if (ImGui::Begin("Textures")) panelTextures(state);
    ImGui::End();
    place(h * 0.82f, h * 0.18f);
    if (ImGui::Begin("Scene")) panelScene(state);
    ImGui::End();
    if (state.showGraph) panelGraph(state, &state.showGraph);
    if (state.compare.on) {
        state.compare.panel(app, ImGui::GetTime(), {state.image.x + 8, state.image.y + 8}, [&](const std::string& id) { state.probe.item(id); });
        // The line, over the image; drag it (handleMouse).
        const float x = float(state.image.x) + state.compare.split * float(state.image.z);
        ImDrawList* fg = ImGui::GetForegroundDrawList();
        fg->AddLine(ImVec2(x, float(state.image.y)), ImVec2(x, float(state.image.y + state.image.w)), IM_COL32(255, 255, 255, 220), 2.0f);
        fg->AddText(ImVec2(x - 16, float(state.image.y) + 4), IM_COL32_WHITE, "A");
        fg->AddText(ImVec2(x + 8, float(state.image.y) + 4), IM_COL32_WHITE, "B");
        if (state.probe.on()) state.probe.widgets["compare-line"] = {x - 2, state.image.y, x + 2, state.image.y + state.image.w};
    }
    if (state.showTexture)
        if (const auto t = app.runtime().namedTexture(app.viewed)) {
            state.viewer.window(*t, &state.showTexture);
            const glm::vec4 c = state.viewer.canvasRect();
            if (state.probe.on()) state.probe.widgets["texture-canvas"] = {c.x, c.y, c.z, c.w};
        }
}

GLuint imageTextureFor(const App& app, const WindowState& state, run::NamedTexture& named) {
    const TextureRef* t = state.mainShowsSelection ? app.displayedTexture() : app.runtime().outputTexture();
    if (!t) return 0;
    named = {};
    named.ref = *t;
    if (state.mainShowsSelection)
        if (const auto n = app.runtime().namedTexture(app.viewed)) named = *n;
    return t->id;
}

void drawImage(WindowState& state, int fbW, int fbH) {
    App& app = *state.app;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbW, fbH);
    glClearColor(0.1f, 0.1f, 0.11f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    run::NamedTexture named;
    if (!imageTextureFor(app, state, named)) return;
    // The graph output as it is; a selected texture with its viewer settings, fitted.
    ViewSettings s;
    if (state.mainShowsSelection) {
        s = state.viewer.settingsFor(app.viewed);
        s.zoom = 0.0f, s.center = glm::vec2(-1.0f);
    }
    const glm::ivec4 rect(state.image.x, fbH - state.image.y - state.image.w, state.image.z, state.image.w);
    if (state.compare.on) state.compare.draw(state.viewer, app, rect);
    else state.viewer.draw(named.ref, named.depthNear, named.depthFar, s, rect);
}

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

// Left button: on a tumbler it drags it (SPEC §4.4: below the centre of mass
// translates, above rotates); on empty space it orbits the camera.
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

nlohmann::json probeState(const WindowState& state, uint64_t frame) {
    const App& app = *state.app;
    nlohmann::json j;
    j["frame"] = frame;
    j["pipeline"] = app.runtime().pipelineFile();
    j["viewed"] = app.viewed;
    j["image"] = {state.image.x, state.image.y, state.image.z, state.image.w};
    j["frame_ms"] = state.frameMs;
    j["render_scale"] = state.renderScale;
    j["errors"] = app.runtime().activeErrors();
    j["editor_error"] = state.editor.error;
    if (const auto& r = state.viewer.lastReadout()) {
        j["readout"] = {{"texel", {r->texel.x, r->texel.y, r->texel.z}},
                        {"mip", r->mip},
                        {"value", {r->value.r, r->value.g, r->value.b, r->value.a}}};
    }
    if (const auto& f = state.viewer.lastFit()) j["fit"] = {f->min, f->max};
    j["compare"] = {{"on", state.compare.on}, {"split", state.compare.split}};
    if (const auto& e = state.compare.errors())
        j["compare"]["errors"] = {{"rmse", e->rmse}, {"rel_mse", e->relMse}, {"psnr", e->psnr}, {"ssim", e->ssim},
                                  {"reference_paths", state.compare.referenceSamples()}};
    if (const graph::Plan* plan = app.runtime().plan()) {
        nlohmann::json passes = nlohmann::json::object();
        for (auto& p : plan->passes) {
            nlohmann::json params = nlohmann::json::object();
            for (auto& v : p.params.values) params[v.name] = graph::formatParamValue(v.value);
            passes[p.id] = {{"state", toString(p.state)}, {"params", params}};
        }
        j["passes"] = passes;
    }
    return j;
}

// The whole window, debug view included (README screenshots under xvfb-run).
void saveScreenshot(const std::string& path, int width, int height) {
    FloatImage img;
    img.width = width, img.height = height;
    img.pixels.resize(size_t(width) * height * 4);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, img.pixels.data());
    std::string error;
    if (!writePng(path, img, 3, error)) log::error(error);
    else log::info("wrote ", path);
}

}  // namespace

int runWindow(const Options& o) {
    std::string error;
    // The panels get a column of their own beside an image of --size.
    auto context = WindowContext::create(o.width + kSidebarWidth, o.height, "Kiln", true, error);
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
    state.app = &app;
    state.probe.path = o.uiProbe;
    state.mainShowsSelection = !o.view.empty();
    state.showTexture = !o.view.empty();
    state.compare.on = fs::path(o.pipeline).filename() == "compare.json";
    state.autoScale = o.budgetMs > 0;
    state.budgetMs = o.budgetMs > 0 ? float(o.budgetMs) : state.budgetMs;
    if (!state.viewer.init(app.runtime().shaders(), error)) log::error(error);
    GLFWwindow* window = context->window();
    glfwSetWindowUserPointer(window, &state);
    installCallbacks(window);
    // Ours first: ImGui's GLFW backend chains to the callbacks it finds installed.
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 450 core");

    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    Clock::time_point last = start;
    for (int frames = 1; !glfwWindowShouldClose(window); ++frames) {
        glfwPollEvents();
        int fbW, fbH;
        glfwGetFramebufferSize(window, &fbW, &fbH);
        const int sidebar = state.showDebug ? std::min(kSidebarWidth, fbW * 2 / 3) : 0;
        state.image = {sidebar, 0, std::max(1, fbW - sidebar), std::max(1, fbH)};
        handleMouse(window, state);
        const Clock::time_point now = Clock::now();
        const double wall = std::chrono::duration<double>(now - last).count();
        last = now;
        state.frameMs = frames == 1 ? wall * 1e3 : state.frameMs * 0.8 + wall * 1e3 * 0.2;
        followBudget(state, std::chrono::duration<double>(now - start).count());
        app.resize(std::max(1, int(std::lround(state.image.z * state.renderScale))),
                   std::max(1, int(std::lround(state.image.w * state.renderScale))));
        // The first frame steps once, as headless does; then the wall clock leads.
        app.frame(frames == 1 ? -1.0 : wall);
        drawImage(state, fbW, fbH);

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        if (state.showDebug) drawSidebar(state);
        panelErrors(app, state);
        ImGui::Render();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, fbW, fbH);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
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
    return 0;
}

}  // namespace kiln::app
