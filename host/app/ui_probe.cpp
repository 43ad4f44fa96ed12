// The window's script interface: --ui-probe FILE (where each widget is, what the readout
// and the compare view say, the passes and their parameters), rewritten every frame so
// tests can drive the window with xdotool; and --screenshot.
#include <filesystem>
#include <fstream>

#include "app/window_state.hpp"
#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace fs = std::filesystem;

void UiProbe::write(nlohmann::json state) {
    if (!on()) return;
    state["widgets"] = std::move(widgets);
    widgets = nlohmann::json::object();
    const std::string tmp = path + ".tmp";
    std::ofstream(tmp) << state.dump(1);
    std::error_code ec;
    fs::rename(tmp, path, ec);  // readers never see half a file
}

nlohmann::json probeState(const WindowState& state, uint64_t frame) {
    const App& app = *state.app;
    nlohmann::json j;
    j["frame"] = frame;
    j["pipeline"] = app.runtime().pipelineFile();
    j["viewed"] = app.viewed;
    j["image"] = {state.image.x, state.image.y, state.image.z, state.image.w};
    j["frame_ms"] = state.frameMs;
    j["sim_time"] = app.scene().time();           // seconds simulated
    j["sim_dropped_s"] = app.droppedSeconds;      // simulated seconds given up to the step budget
    j["render_scale"] = state.renderScale;
    j["settling"] = app.runtime().settling();     // a pass's output still converging (keepRunning)
    j["errors"] = app.runtime().activeErrors();
    j["editor_error"] = state.editor.error;
    j["texture_filter"] = std::string(state.textureFilter.InputBuf);
    if (const auto& r = state.viewer.lastReadout()) {
        j["readout"] = {{"texel", {r->texel.x, r->texel.y, r->texel.z}},
                        {"mip", r->mip},
                        {"value", {r->value.r, r->value.g, r->value.b, r->value.a}}};
    }
    if (const auto& f = state.viewer.lastFit()) j["fit"] = {f->min, f->max};
    if (!state.viewer.lastSaved().empty()) j["saved"] = state.viewer.lastSaved();
    if (state.showTrace && state.traceUv) {
        const PixelTrace& t = state.trace;
        nlohmann::json rows = nlohmann::json::array();
        for (const TraceRow& r : t.rows)
            rows.push_back({{"texture", r.pass + "." + r.name}, {"tile", r.tile}, {"texel", {r.texel.x, r.texel.y, r.texel.z}},
                            {"read", r.read}, {"value", {r.value.r, r.value.g, r.value.b, r.value.a}}});
        j["trace"] = {{"uv", {t.uv.x, t.uv.y}}, {"depth", t.depthTexture}, {"rows", rows}};
        if (t.world) j["trace"]["world"] = {t.world->x, t.world->y, t.world->z};
    }
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

}  // namespace kiln::app
