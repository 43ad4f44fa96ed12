// The debug view's sidebar (the pipeline row, the frame line, the passes and the
// Parameters/Textures/Scene/Compare tabs), the error overlay, the texture window's place
// and the image, reading the host's state every frame (immediate mode, nothing to keep in
// sync). The windows about the image are inspectors.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string_view>

#include <imgui_internal.h>  // the windows drawn last frame: windowOverlapsColumn

#include "app/window_state.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace fs = std::filesystem;

bool PipelineEditor::apply(App& app, const std::function<void(graph::PipelineDesc&)>& edit) {
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
void PipelineEditor::setParam(App& app, const std::string& pass, const std::string& name, const ParamValue& v) {
    std::string e;
    if (app.runtime().setParam(pass, name, v, e)) error.clear();
    else error = e;
}
void PipelineEditor::writeBack(App& app) {
    Runtime& rt = app.runtime();
    if (!rt.pipelineDesc()) return;
    if (rt.pipelineChain().size() > 1) {  // its passes are partly another file's
        error = rt.pipelineFile() + ": not written back: it extends " + rt.pipelineChain()[1].string() +
                "; set the value in it by hand";
        return;
    }
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

namespace {

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

void pipelineSwitcher(WindowState& state, float width) {
    App& app = *state.app;
    const std::string current = fs::path(app.runtime().pipelineFile()).filename().string();
    ImGui::SetNextItemWidth(width);
    // As tall as the list (up to the window): a ninth file fell below the default eight rows.
    if (ImGui::BeginCombo("##pipeline", current.c_str(), ImGuiComboFlags_HeightLargest)) {
        if (ImGui::IsWindowAppearing()) listPipelines(state);
        for (const std::string& p : state.pipelines) {
            const std::string name = fs::path(p).filename().string();
            if (ImGui::Selectable(name.c_str(), name == current)) {
                std::string errors;
                if (app.runtime().loadPipeline(p, errors)) {
                    state.editor.error.clear();  // live reload follows runtime().pipelineFile()
                    // The compare view follows the pipeline: on for compare.json, off when
                    // leaving it (it would compare textures the new graph does not have).
                    state.compare.on = name == "compare.json";
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

GLuint imageTextureFor(const App& app, const WindowState& state, run::NamedTexture& named);

// The next item beside the last when it fits whole in the column, else on the next line
// (a long frame-time line cut "save image" to "save i").
void sameLineIfFits(float width) {
    const ImGuiStyle& style = ImGui::GetStyle();
    const float right = ImGui::GetItemRectMax().x + style.ItemSpacing.x + width;
    if (right <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) ImGui::SameLine();
}

float buttonWidth(const char* label) {
    return ImGui::CalcTextSize(label).x + ImGui::GetStyle().FramePadding.x * 2;
}

// The pipeline switcher and the graph and compare toggles on one line, the switcher taking
// what the buttons leave (it was given a fixed share, and cut the last button off).
void headerRow(WindowState& state) {
    const ImGuiStyle& style = ImGui::GetStyle();
    const float buttons = buttonWidth("graph") + buttonWidth("compare") + style.ItemSpacing.x * 2;
    pipelineSwitcher(state, std::max(80.0f, ImGui::GetContentRegionAvail().x - buttons));
    ImGui::SameLine();
    if (ImGui::SmallButton("graph")) state.showGraph = !state.showGraph;
    state.probe.item("show-graph");
    ImGui::SameLine();
    if (ImGui::SmallButton("compare")) state.compare.on = !state.compare.on;
    state.probe.item("show-compare");
}

// What the frame costs and at what size: at the top, where a 720-px window shows it.
void frameLine(WindowState& state) {
    App& app = *state.app;
    ImGui::Text("%.1f ms a frame (%.1f fps), rendering %dx%d", state.frameMs, state.frameMs > 0 ? 1000.0 / state.frameMs : 0.0,
                app.runtime().outputTexture() ? app.runtime().outputTexture()->width : 0,
                app.runtime().outputTexture() ? app.runtime().outputTexture()->height : 0);
    state.probe.item("frame-line");
    // What the image shows, as its texture holds it: no error overlay, no panels.
    sameLineIfFits(buttonWidth("save image"));
    if (ImGui::SmallButton("save image")) {
        run::NamedTexture shown;
        if (imageTextureFor(app, state, shown)) {
            state.viewer.save(shown, state.mainShowsSelection ? state.viewer.settingsFor(app.viewed) : ViewSettings{});
        }
    }
    state.probe.item("save-image");
    if (state.renderScale < 1.0f) {
        char scale[32];
        std::snprintf(scale, sizeof scale, "(scale %.2f)", state.renderScale);
        sameLineIfFits(ImGui::CalcTextSize(scale).x);
        ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "%s", scale);
    }
}

void panelPasses(WindowState& state) {
    App& app = *state.app;
    PipelineEditor& editor = state.editor;
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
    ImGuiTextFilter& filter = state.textureFilter;
    filter.Draw("filter", 160);
    state.probe.item("texture-filter");
    if (!app.viewed.empty()) {
        ImGui::SameLine();
        if (ImGui::SmallButton("clear")) app.viewed.clear();
    }
    ImGui::BeginChild("texture list");
    for (auto& t : app.runtime().textures()) {
        const std::string name = t.pass + "." + t.name;
        if (!filter.PassFilter(name.c_str())) continue;
        const std::string label = name + (t.internal ? " (internal)" : "") +
                                  (t.stale ? " (unread: written once shown)" : t.read ? "" : " (unread)") + "  " +
                                  std::to_string(t.ref.width) + "x" +
                                  std::to_string(t.ref.height) +
                                  (t.ref.target == GL_TEXTURE_3D ? "x" + std::to_string(t.ref.depth) : "") + " " +
                                  gl::formatName(t.ref.format);
        // Selecting a texture un-culls its producer (from the next frame on), as --view does.
        if (ImGui::Selectable(label.c_str(), app.viewed == name)) app.viewed = name, state.showTexture = true;
        state.probe.item("texture:" + name);
    }
    ImGui::EndChild();
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
    ImGui::Checkbox("redraw only what moved", &app.redrawParts);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("where only tumblers and marbles moved, redraw what they can change and one band of rows");
    state.probe.item("redraw-parts");
    ImGui::SameLine();
    ImGui::Checkbox("outline it", &state.showRedraw);
    state.probe.item("redraw-outline");
    ImGui::Text("t = %.2f s, %d steps this frame, %zu balls, %zu particles", app.scene().time(), app.lastSteps,
                sim.balls().size(), sim.particles().size());
    // Real time unless stepping outgrew its budget: then say how far behind it fell.
    if (app.droppedSeconds > 0)
        ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "behind real time: %.1f s dropped (stepping over %.0f ms a frame)",
                           app.droppedSeconds, app.stepBudgetMs);
    else if (!app.paused)
        ImGui::TextDisabled("real time: stepping %.2f ms this frame", app.lastStepMs);
    // The camera, and the placed models with what of them is not drawn.
    Camera& camera = app.camera();
    bool fly = camera.mode == Camera::Mode::Fly;
    if (ImGui::Checkbox("fly camera (C)", &fly)) fly ? camera.toFly() : camera.toOrbit();
    state.probe.item("camera-fly");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("W/S A/D Q/E move it (Shift: 4x), dragging turns it, the wheel moves it forward");
    for (const scene::PlacedModel& placed : app.scene().models()) {
        const model::Model& m = *placed.model;
        const std::string name = m.files.empty() ? std::string("model") : std::filesystem::path(m.files[0]).filename().string();
        const bool open = ImGui::TreeNode(name.c_str(), "%s%s", name.c_str(), m.warnings.empty() ? "" : " (warnings)");
        state.probe.item("model:" + name);
        if (!open) continue;
        ImGui::Text("%llu triangles drawn, %zu meshes", static_cast<unsigned long long>(m.triangles()), m.meshes.size());
        ImGui::Text("%zu materials, %zu images, %zu lights, %zu cameras", m.materials.size(), m.images.size(),
                    m.lights.size(), m.cameras.size());
        for (const std::string& file : m.files) {
            ImGui::TextDisabled("%s", std::filesystem::path(file).filename().c_str());
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", file.c_str());
        }
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.75f, 0.3f, 1.0f));
        for (const std::string& w : m.warnings) ImGui::TextWrapped("%s", w.c_str());
        ImGui::PopStyleColor();
        ImGui::TreePop();
    }
    ImGui::Separator();
    ImGui::Checkbox("resolution follows the budget", &state.autoScale);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("lowers the render resolution while frames take longer than the budget");
    ImGui::SetNextItemWidth(120);
    if (ImGui::SliderFloat("budget ms", &state.budgetMs, 16.0f, 500.0f, "%.0f")) state.scaleFloor = WindowState::kAutoScaleFloor;
    if (!state.autoScale) ImGui::SliderFloat("resolution scale", &state.renderScale, 0.125f, 1.0f, "%.3f");
    else ImGui::Text("resolution scale %.3f", state.renderScale);
    ImGui::TextDisabled("drag a tumbler: low to move it, high to tilt it");
}

}  // namespace

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

namespace {

// One tab at a time in all the height the passes leave: a 720-px window shows ~17 rows
// of any of them, and a tab scrolls rather than cuts its widgets off.
void sidebarTabs(WindowState& state) {
    App& app = *state.app;
    // Selecting a pass brings its parameters forward; turning the compare view on, its figures.
    if (state.editor.selected != state.lastSelectedPass && !state.editor.selected.empty()) state.wantTab = "Parameters";
    if (state.compare.on && !state.lastCompareOn) state.wantTab = "Compare";
    state.lastSelectedPass = state.editor.selected, state.lastCompareOn = state.compare.on;
    if (!ImGui::BeginTabBar("panels")) return;
    auto tab = [&](const char* name, bool* open, const std::function<void()>& contents) {
        const ImGuiTabItemFlags flags = state.wantTab == name ? ImGuiTabItemFlags_SetSelected : 0;
        const bool shown = ImGui::BeginTabItem(name, open, flags);
        state.probe.item(std::string("tab:") + name);
        if (!shown) return;
        ImGui::BeginChild(name);
        contents();
        ImGui::EndChild();
        ImGui::EndTabItem();
    };
    tab("Parameters", nullptr, [&] { panelParams(state); });
    tab("Textures", nullptr, [&] { panelTextures(state); });
    tab("Scene", nullptr, [&] { panelScene(state); });
    if (state.compare.on)
        tab("Compare", &state.compare.on, [&] { state.compare.panel(app, [&](const std::string& id) { state.probe.item(id); }); });
    ImGui::EndTabBar();
    state.wantTab.clear();
}

}  // namespace

// The rectangles the last frame redrew, over the image (output pixels, y up); nothing
// when it redrew all of it.
static void outlineRedraw(const WindowState& state) {
    const FrameInfo& f = state.app->lastFrame();
    if (f.outputWidth <= 0 || f.outputHeight <= 0) return;
    ImDrawList* fg = ImGui::GetForegroundDrawList();
    const float sx = float(state.image.z) / float(f.outputWidth), sy = float(state.image.w) / float(f.outputHeight);
    const float left = float(state.image.x), bottom = float(state.image.y + state.image.w);
    for (int i = 0; i < f.redrawCount; ++i) {
        const PixelRect& r = f.redraw[i];
        fg->AddRect(ImVec2(left + float(r.x) * sx, bottom - float(r.y + r.height) * sy),
                    ImVec2(left + float(r.x + r.width) * sx, bottom - float(r.y) * sy), IM_COL32(120, 255, 120, 230), 0.0f, 0,
                    1.5f);
    }
}

namespace {

constexpr const char* kSidebarTitle = "Kiln (F1 hides the panels)";

// Whether another window (an inspector, the graph, a popup) drew over the sidebar's column
// in the last frame. Where none did, the sidebar needs no background of its own: the
// window's clear shows through (drawImage), and a 360 × 720 blended rectangle cost the
// debug view 0.7 of its 1.9 ms a frame on llvmpipe.
bool windowOverlapsColumn(float columnWidth) {
    const ImGuiContext& g = *ImGui::GetCurrentContext();
    for (const ImGuiWindow* w : g.Windows)
        if (w->WasActive && !(w->Flags & ImGuiWindowFlags_ChildWindow) && w->Pos.x < columnWidth &&
            std::string_view(w->Name) != kSidebarTitle)
            return true;
    return false;
}

}  // namespace

void drawSidebar(WindowState& state) {
    App& app = *state.app;
    const ImGuiIO& io = ImGui::GetIO();
    // Pinned to the left edge, the whole height (a floating window over it goes behind it
    // when the sidebar is clicked, as any window does).
    ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(float(state.sidebarWidth), io.DisplaySize.y), ImGuiCond_Always);
    if (!windowOverlapsColumn(float(state.sidebarWidth))) ImGui::SetNextWindowBgAlpha(0.0f);
    const ImGuiWindowFlags pinned =
        ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;
    if (ImGui::Begin(kSidebarTitle, nullptr, pinned)) {
        headerRow(state);
        frameLine(state);
        panelPasses(state);
        sidebarTabs(state);
    }
    ImGui::End();
    shareSplit(state);
    if (state.compare.on) {
        state.compare.update(app, ImGui::GetTime());
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
            // Floating (no room in a column, or dragged out): first shown at the top right.
            ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 8, 8), ImGuiCond_FirstUseEver, ImVec2(1, 0));
            ImGui::SetNextWindowSize(ImVec2(440, std::min(560.0f, io.DisplaySize.y - 16)), ImGuiCond_FirstUseEver);
            placeInspector(state, kTextureWindow);
            state.viewer.window(*t, kTextureWindow, &state.showTexture);
            const glm::vec4 c = state.viewer.canvasRect(), r = state.viewer.windowRect();
            if (state.probe.on()) state.probe.widgets["texture-canvas"] = {c.x, c.y, c.z, c.w};
            if (state.probe.on()) state.probe.widgets["texture-window"] = {r.x, r.y, r.z, r.w};
            if (const glm::vec4 h = state.viewer.histogramRect(); state.probe.on() && h.z > h.x)
                state.probe.widgets["texture-histogram"] = {h.x, h.y, h.z, h.w};
            if (const glm::vec4 b = state.viewer.saveButtonRect(); state.probe.on() && b.z > b.x)
                state.probe.widgets["texture-save"] = {b.x, b.y, b.z, b.w};
        }
    panelTrace(state);
    if (state.showGraph) panelGraph(state, &state.showGraph);
    if (state.showRedraw) outlineRedraw(state);
}

namespace {
GLuint imageTextureFor(const App& app, const WindowState& state, run::NamedTexture& named) {
    const TextureRef* t = state.mainShowsSelection ? app.displayedTexture() : app.runtime().outputTexture();
    if (!t) return 0;
    named = {};
    named.ref = *t;
    std::string name = app.viewed;
    if (const graph::Plan* plan = app.runtime().plan(); !state.mainShowsSelection && plan && plan->output.valid())
        name = plan->passes[size_t(plan->output.pass)].id + "." + plan->output.name;
    if (const auto n = app.runtime().namedTexture(name)) named = *n;
    return t->id;
}

}  // namespace

void drawImage(WindowState& state, int fbW, int fbH) {
    App& app = *state.app;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbW, fbH);
    // The sidebar's background where it draws none (drawSidebar): ImGui's, opaque. One
    // clear of the whole window: a scissored one round the image cost llvmpipe more.
    const ImVec4 backdrop = ImGui::GetStyle().Colors[ImGuiCol_WindowBg];
    glClearColor(backdrop.x, backdrop.y, backdrop.z, 1.0f);
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

}  // namespace kiln::app
