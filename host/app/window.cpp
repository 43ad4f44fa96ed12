// The window front end: GLFW + Dear ImGui. The debug view is one function per panel,
// each reading the host's state every frame (immediate mode, nothing to keep in sync).
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "graph/pipeline.hpp"

#include "app/app.hpp"
#include "app/context.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace {

// How the selected texture is drawn to the screen (shaders/host/display.frag).
struct DisplaySettings {
    int channel = 0;        // 0 RGB, 1 R, 2 G, 3 B, 4 A
    float rangeMin = 0.0f, rangeMax = 1.0f;
    float exposure = 1.0f;
    bool linearizeDepth = false;
    int mip = 0;
    float slice = 0.5f;     // 3D: normalised position along the axis
    int axis = 2;           // 3D: 0 x, 1 y, 2 z
};


// Applies an edit of the running pipeline (a toggle, a parameter) by recompiling
// the edited description; the pipeline file itself changes only on "write back".
struct PipelineEditor {
    std::string error;
    std::string selected;  // pass id whose parameters are shown

    bool apply(App& app, const std::function<void(graph::PipelineDesc&)>& edit) {
        Runtime& rt = app.runtime();
        auto desc = graph::parsePipeline(rt.pipelineText(), rt.pipelineFile());
        if (!desc) {
            error = desc.errorText();
            return false;
        }
        edit(*desc);
        std::string errors;
        if (!rt.loadPipelineText(graph::writePipeline(*desc), rt.pipelineFile(), errors)) {
            error = errors;  // the running plan stays
            return false;
        }
        error.clear();
        return true;
    }
};

void setParam(graph::PassDesc& pass, const std::string& name, const ParamValue& value) {
    auto literal = graph::ParamLiteral::of(value);
    for (auto& [k, v] : pass.params)
        if (k == name) {
            v = literal;
            return;
        }
    pass.params.emplace_back(name, literal);
}

void panelParams(App& app, PipelineEditor& editor) {
    const graph::Plan* plan = app.runtime().plan();
    if (!plan) return;
    int index = plan->find(editor.selected);
    if (index < 0) return;
    // A copy: an edit below swaps the running plan, and with it this pass's entry.
    const graph::PlannedPass pass = plan->passes[static_cast<size_t>(index)];
    // Widget ids are scoped to the pass, so "exposure" here is not the texture
    // panel's display "exposure".
    ImGui::PushID("params");
    ImGui::PushID(pass.id.c_str());
    ImGui::Separator();
    ImGui::Text("%s parameters", pass.id.c_str());
    for (auto& decl : pass.decl.params) {
        const ParamValue* current = pass.params.find(decl.name);
        if (!current) continue;
        ParamValue edited = *current;
        bool changed = false;
        const char* label = decl.name.c_str();
        const bool bounded = decl.max > decl.min;
        switch (decl.type) {
            case ParamType::Bool: changed = ImGui::Checkbox(label, &std::get<bool>(edited)); break;
            case ParamType::Int:
                if (!decl.intChoices.empty()) {
                    int& v = std::get<int>(edited);
                    if (ImGui::BeginCombo(label, std::to_string(v).c_str())) {
                        for (int c : decl.intChoices)
                            if (ImGui::Selectable(std::to_string(c).c_str(), c == v)) v = c, changed = true;
                        ImGui::EndCombo();
                    }
                } else if (bounded) {
                    changed = ImGui::SliderInt(label, &std::get<int>(edited), int(decl.min), int(decl.max));
                } else {
                    changed = ImGui::InputInt(label, &std::get<int>(edited));
                }
                break;
            case ParamType::Float:
                changed = bounded ? ImGui::SliderFloat(label, &std::get<float>(edited), float(decl.min), float(decl.max))
                                  : ImGui::DragFloat(label, &std::get<float>(edited), 0.01f);
                break;
            case ParamType::Enum: {
                std::string& v = std::get<std::string>(edited);
                if (ImGui::BeginCombo(label, v.c_str())) {
                    for (auto& c : decl.choices)
                        if (ImGui::Selectable(c.c_str(), c == v)) v = c, changed = true;
                    ImGui::EndCombo();
                }
                break;
            }
            case ParamType::Color: changed = ImGui::ColorEdit3(label, std::get<Color3>(edited).data()); break;
        }
        if (!decl.doc.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", decl.doc.c_str());
        if (changed) {
            editor.apply(app, [&](graph::PipelineDesc& d) { setParam(d.passes[size_t(d.find(pass.id))], decl.name, edited); });
            break;  // the next frame draws the widgets of the new plan
        }
    }
    if (ImGui::Button("write back to the pipeline file")) {
        std::FILE* f = std::fopen(app.runtime().pipelineFile().c_str(), "w");
        if (!f) {
            editor.error = app.runtime().pipelineFile() + ": cannot write";
        } else {
            std::fputs(app.runtime().pipelineText().c_str(), f);
            std::fclose(f);
        }
    }
    ImGui::PopID();
    ImGui::PopID();
}

void panelPasses(App& app, PipelineEditor& editor) {
    if (!ImGui::CollapsingHeader("Passes", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (!ImGui::BeginTable("passes", 5, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) return;
    ImGui::TableSetupColumn("pass");
    ImGui::TableSetupColumn("module");
    ImGui::TableSetupColumn("state");
    ImGui::TableSetupColumn("GPU ms");
    ImGui::TableSetupColumn("CPU ms");
    ImGui::TableHeadersRow();
    double gpuTotal = 0, cpuTotal = 0;
    const graph::Plan* plan = app.runtime().plan();
    for (auto& r : app.runtime().stats()) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        int index = plan ? plan->find(r.id) : -1;
        bool enabled = index >= 0 && plan->passes[size_t(index)].state != graph::PassState::Disabled;
        ImGui::PushID(r.id.c_str());
        if (ImGui::Checkbox("##on", &enabled))
            editor.apply(app, [&](graph::PipelineDesc& d) {
                if (int i = d.find(r.id); i >= 0) d.passes[size_t(i)].enabled = enabled;
            });
        ImGui::SameLine();
        if (ImGui::Selectable(r.id.c_str(), editor.selected == r.id)) editor.selected = r.id;
        ImGui::PopID();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(r.module.c_str());
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(r.state.c_str());
        if (!r.why.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", r.why.c_str());
        // What ran this frame costs its rolling average; a skipped, culled or disabled
        // pass costs nothing and shows a dash, never its last figure.
        ImGui::TableNextColumn();
        if (r.ranThisFrame && r.gpuMs >= 0) ImGui::Text("%.3f", r.gpuMs), gpuTotal += r.gpuMs;
        else ImGui::TextDisabled("-");
        ImGui::TableNextColumn();
        if (r.ranThisFrame) ImGui::Text("%.3f", r.cpuMs), cpuTotal += r.cpuMs;
        else ImGui::TextDisabled("-");
    }
    ImGui::EndTable();
    ImGui::Text("this frame: GPU %.2f ms, CPU %.2f ms (rolling averages of what ran)", gpuTotal, cpuTotal);
    if (!editor.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", editor.error.c_str());
    panelParams(app, editor);
}

void panelTextures(App& app, DisplaySettings& d) {
    if (!ImGui::CollapsingHeader("Textures", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const bool showingOutput = app.viewed.empty();
    if (ImGui::RadioButton("graph output", showingOutput)) app.viewed.clear();
    for (auto& t : app.runtime().textures()) {
        std::string name = t.pass + "." + t.name;
        std::string label = name + (t.internal ? " (internal)" : "") + "  " + std::to_string(t.ref.width) + "x" +
                            std::to_string(t.ref.height) + (t.ref.target == GL_TEXTURE_3D ? "x" + std::to_string(t.ref.depth) : "") +
                            " " + gl::formatName(t.ref.format);
        if (ImGui::RadioButton(label.c_str(), app.viewed == name)) app.viewed = name;
    }
    ImGui::PushID("display");
    const char* channels[] = {"RGB", "R", "G", "B", "A"};
    ImGui::Combo("channel", &d.channel, channels, 5);
    ImGui::DragFloatRange2("range", &d.rangeMin, &d.rangeMax, 0.01f, -100.0f, 100.0f);
    ImGui::SliderFloat("exposure", &d.exposure, 0.01f, 16.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
    ImGui::Checkbox("linearize depth", &d.linearizeDepth);
    ImGui::SliderInt("mip", &d.mip, 0, 10);
    const char* axes[] = {"x", "y", "z"};
    ImGui::Combo("3D axis", &d.axis, axes, 3);
    ImGui::SliderFloat("3D slice", &d.slice, 0.0f, 1.0f);
    ImGui::PopID();
}

void panelErrors(App& app) {
    auto errors = app.runtime().activeErrors();
    if (errors.empty()) return;
    ImGui::SetNextWindowPos(ImVec2(10, ImGui::GetIO().DisplaySize.y - 10), ImGuiCond_Always, ImVec2(0, 1));
    ImGui::SetNextWindowBgAlpha(0.85f);
    ImGui::Begin("errors", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize);
    for (auto& e : errors) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", e.c_str());
    ImGui::End();
}

void panelScene(App& app) {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    auto& sim = app.scene().sim();
    ImGui::Checkbox("paused (Space)", &app.paused);
    ImGui::SameLine();
    if (ImGui::Button("step (.)")) app.singleStep = true;
    ImGui::SameLine();
    if (ImGui::Button("reset (R)")) app.scene().reset();
    if (ImGui::Button("spawn marble (M)")) sim.spawnRandom(sim::BallKind::Marble);
    ImGui::SameLine();
    if (ImGui::Button("spawn fireball (F)")) sim.spawnRandom(sim::BallKind::Fireball);
    ImGui::Text("t = %.2f s, %zu balls, %zu particles", app.scene().time(), sim.balls().size(), sim.particles().size());
    ImGui::TextUnformatted("drag a tumbler: low to move it, high to tilt it");
}

struct WindowState {
    App* app = nullptr;
    bool showDebug = true;
    bool dragging = false;
    bool draggingTumbler = false;
    sim::DragMode dragMode = sim::DragMode::Translate;
    double lastX = 0, lastY = 0;
    DisplaySettings display;
    PipelineEditor editor;
};

GLuint buildDisplayProgram(const ShaderLibrary& shaders) {
    ProgramBuild b = buildProgram(shaders, {{"common/fullscreen.vert", "host/display.frag"}, {}, "kiln.display"});
    if (!b.ok()) {
        log::error(b.errorText());
        return 0;
    }
    return b.program.release();
}

void drawToScreen(GLuint program, const TextureRef& t, const DisplaySettings& d, int fbW, int fbH, GLuint vao) {
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbW, fbH);
    glClearColor(0.1f, 0.1f, 0.1f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    if (!program) return;
    glUseProgram(program);
    const bool is3d = t.target == GL_TEXTURE_3D;
    glBindTextureUnit(is3d ? 1 : 0, t.id);
    auto loc = [&](const char* n) { return glGetUniformLocation(program, n); };
    glUniform1i(loc("u_is3d"), is3d);
    glUniform1i(loc("u_channel"), d.channel);
    glUniform2f(loc("u_range"), d.rangeMin, d.rangeMax);
    glUniform1f(loc("u_exposure"), d.exposure);
    const bool isDepth = t.format == GL_DEPTH_COMPONENT32F || t.format == GL_DEPTH_COMPONENT24;
    glUniform1i(loc("u_linearizeDepth"), isDepth && d.linearizeDepth);
    glUniform1f(loc("u_mip"), float(std::min(d.mip, t.levels - 1)));
    glUniform1f(loc("u_slice"), d.slice);
    glUniform1i(loc("u_axis"), d.axis);
    glUniform1i(loc("u_isInteger"), t.format == GL_R32UI);
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
}

void installCallbacks(GLFWwindow* window) {
    glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
        if (ImGui::GetIO().WantCaptureMouse) return;
        auto* s = static_cast<WindowState*>(glfwGetWindowUserPointer(w));
        s->app->camera().distance = std::clamp(s->app->camera().distance * float(std::pow(0.9, dy)), 1.5f, 10.0f);
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
    int winW, winH;
    glfwGetWindowSize(window, &winW, &winH);
    const bool down = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    auto& sim = app.scene().sim();
    if (down && !ImGui::GetIO().WantCaptureMouse) {
        glm::vec3 origin, dir;
        app.camera().rayThrough(x, y, winW, winH, origin, dir);
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
    } else if (state.dragging) {
        if (state.draggingTumbler) sim.endDrag();
        state.dragging = state.draggingTumbler = false;
    }
    state.lastX = x, state.lastY = y;
}

void drawDebugView(WindowState& state) {
    App& app = *state.app;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (state.showDebug) {
        ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(420, 520), ImGuiCond_FirstUseEver);
        ImGui::Begin("Kiln (F1)");
        ImGui::Text("%s", app.runtime().pipelineFile().c_str());
        panelPasses(app, state.editor);
        panelTextures(app, state.display);
        panelScene(app);
        ImGui::End();
    }
    panelErrors(app);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
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
    auto context = WindowContext::create(o.width, o.height, "Kiln", true, error);
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
    GLFWwindow* window = context->window();
    glfwSetWindowUserPointer(window, &state);
    installCallbacks(window);
    // Ours first: ImGui's GLFW backend chains to the callbacks it finds installed.
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 450 core");

    GLuint displayProgram = buildDisplayProgram(app.runtime().shaders());
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    for (int frames = 1; !glfwWindowShouldClose(window); ++frames) {
        glfwPollEvents();
        handleMouse(window, state);
        int fbW, fbH;
        glfwGetFramebufferSize(window, &fbW, &fbH);
        app.resize(fbW, fbH);
        app.frame();
        if (const TextureRef* t = app.displayedTexture()) drawToScreen(displayProgram, *t, state.display, fbW, fbH, vao);
        drawDebugView(state);
        if (!o.screenshot.empty() && frames == o.frames) {
            saveScreenshot(o.screenshot, fbW, fbH);
            glfwSetWindowShouldClose(window, 1);
        }
        glfwSwapBuffers(window);
    }
    glDeleteVertexArrays(1, &vao);
    if (displayProgram) glDeleteProgram(displayProgram);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    return 0;
}

}  // namespace kiln::app
