#include "app/compare_view.hpp"

#include <imgui.h>

#include <cmath>

#include "app/app.hpp"
#include "kiln/image_io.hpp"

namespace kiln::app {

void CompareView::measure(const App& app) {
    const auto ta = app.runtime().namedTexture(a), tb = app.runtime().namedTexture(b);
    errors_.reset();
    if (!ta || !tb) {
        problem_ = std::string("no texture ") + (!ta ? a : b) + " in the running pipeline (pipelines/compare.json has both)";
        return;
    }
    if (ta->ref.target != GL_TEXTURE_2D || tb->ref.target != GL_TEXTURE_2D || ta->ref.width != tb->ref.width ||
        ta->ref.height != tb->ref.height) {
        problem_ = "the two textures differ in size or kind";
        return;
    }
    const FloatImage ia = readTexture(ta->ref.id, ta->ref.target, ta->ref.format, ta->ref.width, ta->ref.height);
    const FloatImage ib = readTexture(tb->ref.id, tb->ref.target, tb->ref.format, tb->ref.width, tb->ref.height);
    samples_ = int(ib.pixels.size() >= 4 ? ib.pixels[3] : 0.0f);
    errors_ = metrics::compare(ia, ib);
    problem_.clear();
}

void CompareView::update(const App& app, double now) {
    if (now - lastMeasure_ >= 1.0) measure(app), lastMeasure_ = now;
}

void CompareView::panel(App& app, const std::function<void(const std::string&)>& probe) {
    auto pick = [&](const char* label, std::string& name) {
        if (ImGui::BeginCombo(label, name.c_str())) {
            for (auto& t : app.runtime().textures()) {
                if (t.ref.target != GL_TEXTURE_2D) continue;
                const std::string n = t.pass + "." + t.name;
                if (ImGui::Selectable(n.c_str(), n == name)) name = n, lastMeasure_ = -1.0;
            }
            ImGui::EndCombo();
        }
    };
    pick("A (left)", a);
    pick("B (right)", b);
    ImGui::SliderFloat("split", &split, 0.0f, 1.0f, "%.2f");
    ImGui::Checkbox("tonemap both", &tonemap);
    probe("compare-tonemap");
    if (errors_) {
        ImGui::Text("A against B, %d pixels%s", errors_->pixels,
                    samples_ > 0 ? (", B at " + std::to_string(samples_) + " paths").c_str() : "");
        ImGui::Text("RMSE %.4g   relMSE %.4g", errors_->rmse, errors_->relMse);
        ImGui::Text("PSNR %.2f dB   SSIM %.4f", errors_->psnr, errors_->ssim);
        ImGui::TextDisabled("radiance metrics on linear RGB; SSIM on display luminance");
    } else {
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextColored(ImVec4(1, 0.6f, 0.4f, 1), "%s", problem_.c_str());
        ImGui::PopTextWrapPos();
    }
    ImGui::TextDisabled("drag the line in the image to move it");
}

void CompareView::draw(const TextureViewer& viewer, const App& app, glm::ivec4 rect) const {
    ViewSettings s;
    s.tonemap = tonemap;
    if (const auto ta = app.runtime().namedTexture(a)) viewer.draw(ta->ref, 0, 0, s, rect);
    if (const auto tb = app.runtime().namedTexture(b)) {
        const int x = rect.x + int(std::lround(split * float(rect.z)));
        glEnable(GL_SCISSOR_TEST);
        glScissor(x, rect.y, rect.x + rect.z - x, rect.w);
        viewer.draw(tb->ref, 0, 0, s, rect);
        glDisable(GL_SCISSOR_TEST);
    }
}

}  // namespace kiln::app
