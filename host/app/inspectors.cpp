// What the debug view shows about the image beside the sidebar: the graph view, the
// pixel trace and its mark, the error pass's legend labels, and the one split the compare
// line and the error pass share. Immediate mode, as debug_panels.cpp: each reads the
// host's state every frame.
#include <algorithm>
#include <cstdio>
#include <map>

#include "app/window_state.hpp"

namespace kiln::app {

namespace {

// Where each pass sits in the graph view: columns by dependency depth (file order is
// execution order, so producers come first), rows in file order within a column.
struct GraphLayout {
    std::vector<int> column, row;
    int columns = 1;
};

GraphLayout layOut(const graph::Plan& plan) {
    const size_t n = plan.passes.size();
    GraphLayout l{std::vector<int>(n, 0), std::vector<int>(n, 0), 1};
    for (size_t i = 0; i < n; ++i)
        for (const graph::Binding& b : plan.passes[i].bindings)
            if (b.bound()) l.column[i] = std::max(l.column[i], l.column[size_t(b.producer)] + 1);
    std::map<int, int> rowsInColumn;
    for (size_t i = 0; i < n; ++i) l.row[i] = rowsInColumn[l.column[i]]++;
    if (n) l.columns = *std::max_element(l.column.begin(), l.column.end()) + 1;
    return l;
}

// One pass's node: its state's colour, its id and module; a click selects it.
void drawNode(WindowState& state, const graph::PlannedPass& p, const std::string& runState, ImVec2 a, ImVec2 size, int i) {
    ImDrawList* draw = ImGui::GetWindowDrawList();
    const ImVec2 b(a.x + size.x, a.y + size.y);
    // ran this frame: green; skipped (nothing it reads changed): blue; culled: grey;
    // disabled: dark red; failed or faulted this frame: orange.
    const ImU32 fill = p.state == graph::PassState::Disabled ? IM_COL32(110, 40, 40, 255)
                       : p.state == graph::PassState::Culled ? IM_COL32(70, 70, 70, 255)
                       : runState == "error"                 ? IM_COL32(170, 90, 20, 255)
                       : runState == "ran" || runState == "nothing to do" ? IM_COL32(40, 110, 60, 255)
                                                             : IM_COL32(40, 70, 120, 255);
    draw->AddRectFilled(a, b, fill, 4.0f);
    if (p.id == state.editor.selected) draw->AddRect(a, b, IM_COL32(255, 220, 80, 255), 4.0f, 0, 2.0f);
    draw->PushClipRect(a, b, true);  // a narrow node cuts its labels, not its neighbours
    draw->AddText(ImVec2(a.x + 6, a.y + 4), IM_COL32_WHITE, p.id.c_str());
    const std::string sub = p.module + " - " + (runState == "error" ? std::string("error") : toString(p.state));
    draw->AddText(ImVec2(a.x + 6, a.y + 24), IM_COL32(210, 210, 210, 255), sub.c_str());
    draw->PopClipRect();
    ImGui::SetCursorScreenPos(a);
    ImGui::PushID(i);
    if (ImGui::InvisibleButton("node", size)) state.editor.selected = p.id;
    if (ImGui::IsItemHovered() && !p.reason.empty()) ImGui::SetTooltip("%s", p.reason.c_str());
    state.probe.item("graph-node:" + p.id);
    ImGui::PopID();
}

}  // namespace

// Passes as nodes in columns by dependency depth, bindings as edges.
void panelGraph(WindowState& state, bool* open) {
    App& app = *state.app;
    const graph::Plan* plan = app.runtime().plan();
    // Along the bottom, as wide as the window allows: the whole graph fits (nodes narrow to
    // fit their columns), none is clipped off the window's edge, and the Passes panel's
    // "graph" button that closes it stays uncovered.
    const ImGuiIO& io = ImGui::GetIO();
    const ImVec2 size(std::min(900.0f, io.DisplaySize.x - 16), std::min(260.0f, io.DisplaySize.y * 0.5f));
    ImGui::SetNextWindowPos(ImVec2(8, io.DisplaySize.y - size.y - 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(size, ImGuiCond_FirstUseEver);
    placeInspector(state, kGraphWindow);
    if (!ImGui::Begin(kGraphWindow, open, ImGuiWindowFlags_HorizontalScrollbar) || !plan) {
        ImGui::End();
        return;
    }
    const GraphLayout layout = layOut(*plan);
    std::map<std::string, std::string> runState;
    for (auto& r : app.runtime().stats()) runState[r.id] = r.state;

    ImGui::TextWrapped("green ran, blue skipped (nothing it reads changed), grey culled, red disabled, orange failed; "
                       "click to select");
    const float perColumn = (ImGui::GetContentRegionAvail().x - 16) / float(layout.columns);
    const float nodeWidth = std::clamp(perColumn * 0.78f, 90.0f, 150.0f);
    const ImVec2 nodeSize(nodeWidth, 46), gap(std::max(16.0f, std::min(60.0f, perColumn - nodeWidth)), 18);
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    auto nodePos = [&](size_t i) {
        return ImVec2(origin.x + 8 + layout.column[i] * (nodeSize.x + gap.x),
                      origin.y + 8 + layout.row[i] * (nodeSize.y + gap.y));
    };
    ImDrawList* draw = ImGui::GetWindowDrawList();
    for (size_t i = 0; i < plan->passes.size(); ++i)
        for (const graph::Binding& b : plan->passes[i].bindings) {
            if (!b.bound()) continue;
            const ImVec2 a = nodePos(size_t(b.producer)), c = nodePos(i);
            const ImVec2 from(a.x + nodeSize.x, a.y + nodeSize.y * 0.5f), to(c.x, c.y + nodeSize.y * 0.5f);
            draw->AddBezierCubic(from, ImVec2(from.x + 30, from.y), ImVec2(to.x - 30, to.y), to, IM_COL32(180, 180, 190, 200), 1.5f);
        }
    for (size_t i = 0; i < plan->passes.size(); ++i)
        drawNode(state, plan->passes[i], runState[plan->passes[i].id], nodePos(i), nodeSize, int(i));
    // The graph's extent as the window's content, so it scrolls when it does not fit.
    int rows = 1;
    for (int r : layout.row) rows = std::max(rows, r + 1);
    ImGui::SetCursorScreenPos(origin);
    ImGui::Dummy(ImVec2(16 + layout.columns * (nodeSize.x + gap.x), 16 + rows * (nodeSize.y + gap.y)));
    ImGui::End();
}

// One split: the compare line and every error pass's "split" parameter are the same value.
// Whichever moved since the last frame (the line, the Compare tab's slider, or the
// parameter edited in its tab) sets the other.
void shareSplit(WindowState& state) {
    App& app = *state.app;
    const graph::Plan* plan = app.runtime().plan();
    if (!plan) return;
    std::vector<std::string> errorPasses;
    float parameter = state.sharedSplit;
    for (const graph::PlannedPass& p : plan->passes)
        if (p.module == "error")
            if (const ParamValue* v = p.params.find("split"); v && std::holds_alternative<float>(*v)) {
                errorPasses.push_back(p.id);
                if (std::get<float>(*v) != state.sharedSplit) parameter = std::get<float>(*v);
            }
    if (state.compare.split != state.sharedSplit) {
        for (const std::string& id : errorPasses) state.editor.setParam(app, id, "split", state.compare.split);
    } else if (parameter != state.sharedSplit) {
        state.compare.split = parameter;
    }
    state.sharedSplit = state.compare.split;
}

// The error pass draws its colour map along the image's bottom (passes/error); the window
// labels its ends and ticks when the image shows that pass's output.
void legendLabels(WindowState& state) {
    const App& app = *state.app;
    const graph::Plan* plan = app.runtime().plan();
    if (!plan || !plan->output.valid() || state.compare.on || state.mainShowsSelection) return;
    const graph::PlannedPass& p = plan->passes[size_t(plan->output.pass)];
    const ParamValue *legend = p.params.find("legend"), *mode = p.params.find("mode"), *scale = p.params.find("scale");
    if (p.module != "error" || !legend || !std::get<bool>(*legend) || !mode || std::get<std::string>(*mode) == "split") return;
    std::vector<std::string> labels = {"1e-4", "1e-3", "0.01", "0.1", ">=1"};
    if (std::get<std::string>(*mode) == "signed") {
        char v[32];
        std::snprintf(v, sizeof v, "%.3g", scale ? std::get<float>(*scale) : 1.0f);
        labels = {std::string("-") + v + " (too dark)", "0", std::string("+") + v + " (too bright)"};
    }
    ImDrawList* fg = ImGui::GetForegroundDrawList();
    const float bottom = float(state.image.y + state.image.w) - 2.0f, height = ImGui::GetTextLineHeight();
    for (size_t i = 0; i < labels.size(); ++i) {
        const float t = float(i) / float(labels.size() - 1), w = ImGui::CalcTextSize(labels[i].c_str()).x;
        const float x = std::clamp(float(state.image.x) + t * float(state.image.z) - w * t, float(state.image.x) + 2.0f,
                                   float(state.image.x + state.image.z) - w - 2.0f);
        fg->AddRectFilled(ImVec2(x - 2, bottom - height - 1), ImVec2(x + w + 2, bottom + 1), IM_COL32(0, 0, 0, 170), 2.0f);
        fg->AddText(ImVec2(x, bottom - height), IM_COL32_WHITE, labels[i].c_str());
    }
}

// The pixel trace's window: one row per texture (per tile of a tiled 3D atlas), passes in
// the order they ran; a texture's name selects it in the texture window. A cross marks
// the pixel on the image.
void panelTrace(WindowState& state) {
    App& app = *state.app;
    if (!state.showTrace || !state.traceUv) return;
    state.trace = tracePixel(app.runtime(), glm::inverse(app.viewProj()), app.voxelVolume(), app.voxelExtent(), *state.traceUv);
    const PixelTrace& t = state.trace;
    const float cx = float(state.image.x) + t.uv.x * float(state.image.z), cy = float(state.image.y) + (1.0f - t.uv.y) * float(state.image.w);
    ImDrawList* fg = ImGui::GetForegroundDrawList();
    fg->AddLine(ImVec2(cx - 8, cy), ImVec2(cx + 8, cy), IM_COL32(255, 80, 200, 255), 1.5f);
    fg->AddLine(ImVec2(cx, cy - 8), ImVec2(cx, cy + 8), IM_COL32(255, 80, 200, 255), 1.5f);
    ImGui::SetNextWindowPos(ImVec2(float(state.image.x + state.image.z) - 470, float(state.image.y + state.image.w) - 330), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(460, 320), ImGuiCond_FirstUseEver);
    placeInspector(state, kTraceWindow);
    if (ImGui::Begin(kTraceWindow, &state.showTrace)) {
        const TextureRef* out = app.runtime().outputTexture();
        ImGui::Text("pixel (%d, %d) of the output", out ? int(t.uv.x * float(out->width)) : 0, out ? int(t.uv.y * float(out->height)) : 0);
        if (t.world) ImGui::Text("world (%.3f, %.3f, %.3f) from %s", t.world->x, t.world->y, t.world->z, t.depthTexture.c_str());
        else ImGui::TextDisabled("%s", t.depthTexture.empty() ? "no camera depth in this graph: 3D textures unread" : "the pixel sees no surface");
        const ImGuiTableFlags flags = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_ScrollY | ImGuiTableFlags_Resizable;
        if (ImGui::BeginTable("trace", 4, flags)) {
            ImGui::TableSetupScrollFreeze(0, 1);
            for (const char* column : {"pass", "texture", "texel", "value"}) ImGui::TableSetupColumn(column);
            ImGui::TableHeadersRow();
            std::string lastPass;
            for (const TraceRow& r : t.rows) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                if (r.pass != lastPass) ImGui::TextUnformatted(r.pass.c_str());
                lastPass = r.pass;
                ImGui::TableNextColumn();
                const std::string name = r.pass + "." + r.name;
                const std::string label = r.name + (r.tile >= 0 ? "[" + std::to_string(r.tile) + "]" : "") + "##" + name + std::to_string(r.tile);
                if (ImGui::Selectable(label.c_str(), app.viewed == name)) app.viewed = name, state.showTexture = true;
                ImGui::TableNextColumn();
                if (r.volume) ImGui::Text("%d,%d,%d", r.texel.x, r.texel.y, r.texel.z);
                else ImGui::Text("%d,%d", r.texel.x, r.texel.y);
                ImGui::TableNextColumn();
                if (r.read) ImGui::Text("%.4g %.4g %.4g %.4g", r.value.r, r.value.g, r.value.b, r.value.a);
                else ImGui::TextDisabled("-");
            }
            ImGui::EndTable();
        }
        if (state.probe.on()) {
            const ImVec2 p = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
            state.probe.widgets["trace-window"] = {p.x, p.y, p.x + size.x, p.y + size.y};
        }
    }
    ImGui::End();
}

}  // namespace kiln::app
