#include "app/texture_viewer.hpp"

#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "kiln/image_io.hpp"
#include "kiln/log.hpp"

namespace kiln::app {

namespace fs = std::filesystem;

namespace {

constexpr int kLegendPx = 10;  // the colour map's strip under a one-channel texture
using gl::isDepthFormat;
bool isSingleChannel(GLenum f) { return isDepthFormat(f) || gl::isIntegerFormat(f) || f == GL_R16F || f == GL_R32F || f == GL_R8; }

glm::ivec3 levelSize(const TextureRef& t, int mip) {
    return {std::max(1, t.width >> mip), std::max(1, t.height >> mip),
            t.target == GL_TEXTURE_3D ? std::max(1, t.depth >> mip) : 1};
}

int clampedMip(const TextureRef& t, const ViewSettings& s) { return std::clamp(s.mip, 0, std::max(0, t.levels - 1)); }

int clampedSlice(const TextureRef& t, const ViewSettings& s, int mip) {
    const int n = levelSize(t, mip)[std::clamp(s.axis, 0, 2)];
    return s.slice < 0 ? n / 2 : std::min(s.slice, n - 1);
}

// The zoom and centre in effect: "fit" and "middle" resolved against the canvas.
float effectiveZoom(const ViewSettings& s, glm::vec2 canvas, glm::ivec2 plane) {
    return s.zoom > 0.0f ? s.zoom : std::max(1e-3f, std::min(canvas.x / float(plane.x), canvas.y / float(plane.y)));
}
glm::vec2 effectiveCenter(const ViewSettings& s, glm::ivec2 plane) {
    return s.center.x < 0.0f ? glm::vec2(plane) * 0.5f : s.center;
}

// A texel of the displayed plane → the texture's (x, y, z).
glm::ivec3 planeToTexture(glm::ivec2 p, int axis, int slice, bool is3D) {
    if (!is3D) return {p.x, p.y, 0};
    return axis == 0 ? glm::ivec3(slice, p.x, p.y) : axis == 1 ? glm::ivec3(p.x, slice, p.y) : glm::ivec3(p.x, p.y, slice);
}

float linearDepth(float d, float n, float f) { return 2.0f * n * f / (f + n - (d * 2.0f - 1.0f) * (f - n)); }

bool depthPlanesApply(const TextureRef& t, float n, float f, const ViewSettings& s) {
    return isDepthFormat(t.format) && s.linearizeDepth && n > 0.0f && f > n;
}

}  // namespace

std::vector<float> readTexelBox(const TextureRef& t, int level, glm::ivec3 o, glm::ivec3 n) {
    return readTextureBox(t.id, t.format, level, o.x, o.y, o.z, n.x, n.y, n.z);
}

glm::ivec2 planeSize(const TextureRef& t, int mip, int axis) {
    const glm::ivec3 l = levelSize(t, mip);
    if (t.target != GL_TEXTURE_3D) return {l.x, l.y};
    return axis == 0 ? glm::ivec2(l.y, l.z) : axis == 1 ? glm::ivec2(l.x, l.z) : glm::ivec2(l.x, l.y);
}

glm::vec2 TextureViewer::texelAt(glm::vec2 canvasPixel, glm::vec2 canvasSize, const ViewSettings& s, glm::ivec2 plane) {
    return (canvasPixel - canvasSize * 0.5f) / effectiveZoom(s, canvasSize, plane) + effectiveCenter(s, plane);
}

bool TextureViewer::reload(const ShaderLibrary& shaders, std::string& error) {
    ProgramBuild b = buildProgram(shaders, {{"common/fullscreen.vert", "host/display.frag"}, {}, "kiln.display"});
    ProgramBuild plain = buildProgram(
        shaders, {{"common/fullscreen.vert", "host/display.frag"}, {{"KILN_DISPLAY_PLAIN", "1"}}, "kiln.display.plain"});
    if (!b.ok() || !plain.ok()) {
        error = (b.ok() ? plain : b).errorText();
        return false;
    }
    program_ = std::move(b.program);
    plainProgram_ = std::move(plain.program);
    return true;
}

bool TextureViewer::init(const ShaderLibrary& shaders, std::string& error) {
    vao_ = gl::createVertexArray();
    return reload(shaders, error);
}

void TextureViewer::draw(const TextureRef& t, float depthNear, float depthFar, const ViewSettings& s, glm::ivec4 rect,
                         int legendPx) const {
    if (!program_ || !t.id) return;
    const bool is3D = t.target == GL_TEXTURE_3D, isUint = gl::isIntegerFormat(t.format);
    const int mip = clampedMip(t, s);
    const glm::ivec2 plane = planeSize(t, mip, s.axis);
    const glm::vec2 canvas(rect.z, rect.w);
    glViewport(rect.x, rect.y, rect.z, rect.w);
    const bool linear = depthPlanesApply(t, depthNear, depthFar, s);
    const bool plain = !is3D && !isUint && s.channel == 0 && !s.tonemap && !s.checker && legendPx == 0 && !linear &&
                       mip == 0;
    // An 8-bit image shown texel for texel (the window's main image at --size): copied.
    // What the plain shader would write (in [0, 1], no NaN), for half the cost on
    // llvmpipe (a draw 3.1 ms at 720², the blit 1.7).
    const bool unorm8 = t.format == GL_RGBA8 || t.format == GL_SRGB8_ALPHA8;
    if (plain && unorm8 && s.rangeMin == 0.0f && s.rangeMax == 1.0f && plane == glm::ivec2(rect.z, rect.w) &&
        effectiveZoom(s, canvas, plane) == 1.0f && effectiveCenter(s, plane) == glm::vec2(plane) * 0.5f) {
        if (!blitSource_) blitSource_ = gl::createFramebuffer();
        GLint target = 0;  // where draw() would have drawn
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);
        glNamedFramebufferTexture(blitSource_.id(), GL_COLOR_ATTACHMENT0, t.id, 0);
        glBlitNamedFramebuffer(blitSource_.id(), GLuint(target), 0, 0, plane.x, plane.y, rect.x, rect.y, rect.x + rect.z,
                               rect.y + rect.w, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glNamedFramebufferTexture(blitSource_.id(), GL_COLOR_ATTACHMENT0, 0, 0);
        return;
    }
    const GLuint p = plain ? plainProgram_.id() : program_.id();
    glUseProgram(p);
    glBindTextureUnit((isUint ? 2 : 0) + (is3D ? 1 : 0), t.id);
    auto loc = [&](const char* n) { return glGetUniformLocation(p, n); };
    glUniform1i(loc("u_kind"), (isUint ? 2 : 0) + (is3D ? 1 : 0));
    glUniform1i(loc("u_channel"), s.channel);
    glUniform2f(loc("u_range"), s.rangeMin, s.rangeMax);
    glUniform1i(loc("u_falseColor"), s.falseColor);
    glUniform2f(loc("u_depthPlanes"), linear ? depthNear : 0.0f, linear ? depthFar : 0.0f);
    glUniform1i(loc("u_mip"), mip);
    glUniform1i(loc("u_slice"), clampedSlice(t, s, mip));
    glUniform1i(loc("u_axis"), std::clamp(s.axis, 0, 2));
    glUniform1i(loc("u_checker"), s.checker);
    glUniform1i(loc("u_tonemap"), s.tonemap);
    glUniform1f(loc("u_legend"), float(legendPx));
    glUniform2f(loc("u_canvasOrigin"), float(rect.x), float(rect.y));
    glUniform2f(loc("u_canvasSize"), canvas.x, canvas.y);
    const glm::vec2 center = effectiveCenter(s, plane);
    glUniform2f(loc("u_center"), center.x, center.y);
    glUniform1f(loc("u_zoom"), effectiveZoom(s, canvas, plane));
    glBindVertexArray(vao_.id());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindTextureUnit((isUint ? 2 : 0) + (is3D ? 1 : 0), 0);
}

RangeFit TextureViewer::fitRange(const TextureRef& t, float depthNear, float depthFar, ViewSettings& s, glm::vec2 canvas) {
    RangeFit fit;
    const int mip = clampedMip(t, s);
    const glm::ivec2 plane = planeSize(t, mip, s.axis);
    // The texels in view: the canvas corners mapped to the plane, clamped to it.
    const glm::vec2 a = texelAt({0, 0}, canvas, s, plane), b = texelAt(canvas, canvas, s, plane);
    const glm::ivec2 lo = glm::clamp(glm::ivec2(glm::floor(glm::min(a, b))), glm::ivec2(0), plane - 1);
    const glm::ivec2 hi = glm::clamp(glm::ivec2(glm::ceil(glm::max(a, b))) - 1, glm::ivec2(0), plane - 1);
    const glm::ivec2 n = hi - lo + 1;
    const bool is3D = t.target == GL_TEXTURE_3D;
    const int slice = clampedSlice(t, s, mip);
    const glm::ivec3 origin = planeToTexture(lo, s.axis, slice, is3D);
    const glm::ivec3 extent = is3D ? (s.axis == 0 ? glm::ivec3(1, n.x, n.y) : s.axis == 1 ? glm::ivec3(n.x, 1, n.y) : glm::ivec3(n, 1))
                                   : glm::ivec3(n, 1);
    const std::vector<float> texels = readTexelBox(t, mip, origin, extent);
    const bool linear = depthPlanesApply(t, depthNear, depthFar, s);
    std::vector<float> values;
    values.reserve(texels.size());
    for (size_t i = 0; i < texels.size() / 4; ++i)
        for (int c = 0; c < 4; ++c) {
            if (s.channel == 0 ? c == 3 : c != s.channel - 1) continue;
            float v = texels[i * 4 + size_t(c)];
            if (linear) v = linearDepth(v, depthNear, depthFar);
            if (!std::isfinite(v)) {
                ++fit.nonFinite;
                continue;
            }
            values.push_back(v);
        }
    fit.texels = texels.size() / 4;
    if (values.empty()) return fit;
    const auto [mn, mx] = std::minmax_element(values.begin(), values.end());
    fit.min = *mn, fit.max = *mx;
    const float span = std::max(fit.max - fit.min, 1e-20f);
    for (float v : values) fit.histogram[std::min<size_t>(63, size_t((v - fit.min) / span * 64.0f))] += 1.0f;
    s.rangeMin = fit.min;
    s.rangeMax = fit.max > fit.min ? fit.max : fit.min + 1.0f;  // a constant image shows mid-range, not black
    return fit;
}

void TextureViewer::window(const run::NamedTexture& nt, const char* title, bool* open) {
    const TextureRef& t = nt.ref;
    const std::string name = nt.pass + "." + nt.name;
    ViewSettings& s = settings_[name];
    const bool shown = ImGui::Begin(title, open);
    const ImVec2 at = ImGui::GetWindowPos(), extent = ImGui::GetWindowSize();
    windowRect_ = {at.x, at.y, at.x + extent.x, at.y + extent.y};
    if (!shown) {
        ImGui::End();
        return;
    }
    ImGui::PushID(name.c_str());
    const bool fitNow = controls(nt, s);

    // The canvas: what is left of the window but the readout and histogram lines.
    const float footer = ImGui::GetTextLineHeightWithSpacing() * 2.0f + 56.0f;
    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const glm::ivec2 size(std::max(16, int(avail.x)), std::max(16, int(avail.y - footer)));
    ensureCanvas(size);
    if (fitFor_ != name) fit_.reset(), readout_.reset(), fitFor_ = name;
    // Data without a natural 0..1 (depth, counts, one float channel) is fitted when first
    // shown; colour starts at 0..1.
    if (!s.fitted && !isSingleChannel(t.format)) s.fitted = true;
    if (!s.fitted) s.channel = 1;  // one channel: shown in false colour
    if (fitNow || autoFit_ || !s.fitted) fit_ = fitRange(t, nt.depthNear, nt.depthFar, s, glm::vec2(size)), s.fitted = true;
    // One channel (grey or false colour): a legend of the map along the canvas's bottom.
    const int legend = s.channel != 0 ? kLegendPx : 0;
    glBindFramebuffer(GL_FRAMEBUFFER, canvasFbo_.id());
    draw(t, nt.depthNear, nt.depthFar, s, {0, 0, size.x, size.y}, legend);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    const ImVec2 p0 = ImGui::GetCursorScreenPos();
    ImGui::InvisibleButton("canvas", ImVec2(float(size.x), float(size.y)));
    const bool hovered = ImGui::IsItemHovered(), active = ImGui::IsItemActive();
    canvasRect_ = {p0.x, p0.y, p0.x + size.x, p0.y + size.y};
    ImGui::GetWindowDrawList()->AddImage(ImTextureID(intptr_t(canvas_.id())), p0, ImVec2(p0.x + size.x, p0.y + size.y),
                                         ImVec2(0, 1), ImVec2(1, 0));
    if (legend) {  // the range's ends, on the legend's ends
        char lo[32], hi[32];
        std::snprintf(lo, sizeof lo, "%.4g", s.rangeMin);
        std::snprintf(hi, sizeof hi, "%.4g", s.rangeMax);
        ImDrawList* list = ImGui::GetWindowDrawList();
        const float y = p0.y + size.y - kLegendPx - ImGui::GetTextLineHeight();
        list->AddText(ImVec2(p0.x + 2, y), IM_COL32_WHITE, lo);
        list->AddText(ImVec2(p0.x + size.x - ImGui::CalcTextSize(hi).x - 2, y), IM_COL32_WHITE, hi);
    }
    canvasInput(t, s, glm::vec2(p0.x, p0.y), size, hovered, active);
    readoutAndHistogram(nt, name);
    ImGui::PopID();
    ImGui::End();
}

namespace {
// The controls wrap in a narrow window (the inspector column) instead of running off it.
float buttonWidth(const char* label) { return ImGui::CalcTextSize(label).x + ImGui::GetStyle().FramePadding.x * 2; }
float checkboxWidth(const char* label) {
    return ImGui::GetFrameHeight() + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(label).x;
}
void sameLineIfFits(float width) {
    const float right = ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x + width;
    if (right <= ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x) ImGui::SameLine();
}
}  // namespace

bool TextureViewer::controls(const run::NamedTexture& nt, ViewSettings& s) {
    const TextureRef& t = nt.ref;
    const bool is3D = t.target == GL_TEXTURE_3D;
    ImGui::Text("%s.%s  %dx%d%s %s, %d mip%s", nt.pass.c_str(), nt.name.c_str(), t.width, t.height,
                is3D ? ("x" + std::to_string(t.depth)).c_str() : "", gl::formatName(t.format), t.levels, t.levels == 1 ? "" : "s");
    const char* channels[] = {"RGB", "R", "G", "B", "A"};
    ImGui::SetNextItemWidth(70);
    ImGui::Combo("channel", &s.channel, channels, 5);
    sameLineIfFits(buttonWidth("fit range"));
    const bool fitNow = ImGui::Button("fit range");
    sameLineIfFits(checkboxWidth("auto"));
    ImGui::Checkbox("auto", &autoFit_);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("fit the range to what is in view every frame (reads the texture back)");
    sameLineIfFits(buttonWidth("1:1"));
    if (ImGui::Button("1:1")) s.zoom = 1.0f;
    sameLineIfFits(buttonWidth("fit"));
    if (ImGui::Button("fit")) s.zoom = 0.0f, s.center = glm::vec2(-1.0f);
    sameLineIfFits(buttonWidth("save"));
    if (ImGui::Button("save")) save(nt, s);
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    saveButtonRect_ = {lo.x, lo.y, hi.x, hi.y};
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("write it as PNG (and EXR for float data) into %s", saveDir_.c_str());
    ImGui::DragFloatRange2("range", &s.rangeMin, &s.rangeMax, std::max(1e-4f, (s.rangeMax - s.rangeMin) * 0.005f), 0, 0, "%.5g", "%.5g");
    if (s.channel != 0) ImGui::Checkbox("false colour", &s.falseColor), sameLineIfFits(checkboxWidth("alpha checkerboard"));
    ImGui::Checkbox("alpha checkerboard", &s.checker);
    if (s.channel == 0) sameLineIfFits(checkboxWidth("tonemap")), ImGui::Checkbox("tonemap", &s.tonemap);
    if (isDepthFormat(t.format) && nt.depthNear > 0.0f) {
        sameLineIfFits(checkboxWidth("depth in metres"));
        ImGui::Checkbox("depth in metres", &s.linearizeDepth);
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("linearised with the producing camera's planes %.3g .. %.3g", nt.depthNear, nt.depthFar);
    }
    if (!lastSaved_.empty()) ImGui::TextDisabled("saved: %s", lastSaved_.c_str());
    if (t.levels > 1) ImGui::SliderInt("mip", &s.mip, 0, t.levels - 1);
    if (is3D) {
        const char* axes[] = {"x", "y", "z"};
        ImGui::SetNextItemWidth(60);
        ImGui::Combo("axis", &s.axis, axes, 3);
        ImGui::SameLine();
        const int mip = clampedMip(t, s);
        int slice = clampedSlice(t, s, mip);
        if (ImGui::SliderInt("slice", &slice, 0, levelSize(t, mip)[s.axis] - 1)) s.slice = slice;
    }
    return fitNow;
}

void TextureViewer::save(const run::NamedTexture& nt, const ViewSettings& s) {
    const TextureRef& t = nt.ref;
    const int mip = clampedMip(t, s);
    const bool is3D = t.target == GL_TEXTURE_3D;
    const int slice = is3D ? (s.axis == 2 ? clampedSlice(t, s, mip) : levelSize(t, mip).z / 2) : -1;
    const FloatImage img = readTexture(t.id, t.target, t.format, std::max(1, t.width >> mip),
                                       std::max(1, t.height >> mip), mip, slice);
    std::string name = nt.pass + "." + nt.name;
    if (mip > 0) name += ".mip" + std::to_string(mip);
    if (is3D) name += ".z" + std::to_string(slice);
    std::error_code ec;
    fs::create_directories(saveDir_, ec);
    const std::string base = (saveDir_ / name).string();
    std::string error;
    bool withExr = false;
    if (ec) lastSaved_ = saveDir_.string() + ": cannot create: " + ec.message();
    else if (!run::writeTextureImage(img, t.format, base, withExr, error)) lastSaved_ = error;
    else lastSaved_ = base + (withExr ? ".png and .exr" : ".png");
    log::info("texture window: ", lastSaved_);
}

void TextureViewer::ensureCanvas(glm::ivec2 size) {
    if (canvas_.width() == size.x && canvas_.height() == size.y) return;
    canvas_ = gl::Texture::create(GL_TEXTURE_2D, GL_RGBA8, size.x, size.y, 1, 1, "kiln.texture_viewer");
    canvasFbo_ = gl::createFramebuffer();
    glNamedFramebufferTexture(canvasFbo_.id(), GL_COLOR_ATTACHMENT0, canvas_.id(), 0);
}

void TextureViewer::canvasInput(const TextureRef& t, ViewSettings& s, glm::vec2 p0, glm::ivec2 size, bool hovered,
                                bool active) {
    const ImGuiIO& io = ImGui::GetIO();
    const int mip = clampedMip(t, s);
    const glm::ivec2 plane = planeSize(t, mip, s.axis);
    const glm::vec2 canvas(size);
    // Canvas pixel of the cursor, origin bottom-left like the shader's.
    const glm::vec2 cursor(io.MousePos.x - p0.x, float(size.y) - (io.MousePos.y - p0.y));
    if (active && ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f)) {
        const float zoom = effectiveZoom(s, canvas, plane);
        s.center = effectiveCenter(s, plane) + glm::vec2(-io.MouseDelta.x, io.MouseDelta.y) / zoom;
        s.zoom = zoom;
    }
    if (hovered && io.MouseWheel != 0.0f) {
        const glm::vec2 under = texelAt(cursor, canvas, s, plane);
        const float zoom = std::clamp(effectiveZoom(s, canvas, plane) * std::pow(1.25f, io.MouseWheel), 1.0f / 64.0f, 256.0f);
        s.zoom = zoom;
        s.center = under - (cursor - canvas * 0.5f) / zoom;  // the texel under the cursor stays put
    }
    if (!hovered) return;
    const glm::ivec2 p(glm::floor(texelAt(cursor, canvas, s, plane)));
    if (p.x < 0 || p.y < 0 || p.x >= plane.x || p.y >= plane.y) return;
    TexelReadout r;
    r.texel = planeToTexture(p, s.axis, clampedSlice(t, s, mip), t.target == GL_TEXTURE_3D);
    r.mip = mip;
    const std::vector<float> v = readTexelBox(t, mip, r.texel, {1, 1, 1});
    r.value = {v[0], v[1], v[2], v[3]};
    r.isInteger = gl::isIntegerFormat(t.format);
    r.isDepth = isDepthFormat(t.format);
    readout_ = r;
}

void TextureViewer::readoutAndHistogram(const run::NamedTexture& nt, const std::string& name) {
    if (readout_) {
        const TexelReadout& r = *readout_;
        const bool is3D = nt.ref.target == GL_TEXTURE_3D;
        ImGui::Text("texel %d, %d%s  mip %d", r.texel.x, r.texel.y, is3D ? (", " + std::to_string(r.texel.z)).c_str() : "", r.mip);
        if (r.isInteger) ImGui::Text("value %u", unsigned(r.value.r));
        else if (r.isDepth && nt.depthNear > 0.0f)
            // The pass that wrote it rendered from its own eye (shadow: the lamp's).
            ImGui::Text("depth %.7g  (%.5g m from %s's eye)", r.value.r, linearDepth(r.value.r, nt.depthNear, nt.depthFar),
                        nt.pass.c_str());
        else if (r.isDepth) ImGui::Text("depth %.7g", r.value.r);
        else ImGui::Text("%.6g  %.6g  %.6g  %.6g", r.value.r, r.value.g, r.value.b, r.value.a);
    } else {
        ImGui::TextDisabled("hover the image for the value under the cursor");
        ImGui::TextDisabled("wheel: zoom   drag: pan");
    }
    if (fit_ && fitFor_ == name) {
        char overlay[96];
        std::snprintf(overlay, sizeof overlay, "%.4g .. %.4g  (%zu texels%s; log counts)", fit_->min, fit_->max,
                      fit_->texels, fit_->nonFinite ? ", some NaN/Inf" : "");
        // Log heights: one bin (empty voxels, the background) often holds most texels.
        std::array<float, 64> heights;
        for (size_t i = 0; i < heights.size(); ++i) heights[i] = std::log1p(fit_->histogram[i]);
        // The width in pixels: ImGui 1.86's plots take a negative size literally (a
        // 1-pixel histogram), unlike its other widgets.
        ImGui::PlotHistogram("##histogram", heights.data(), 64, 0, overlay, 0.0f, FLT_MAX,
                             ImVec2(ImGui::GetContentRegionAvail().x, 48));
        const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
        histogramRect_ = {lo.x, lo.y, hi.x, hi.y};
    } else {
        histogramRect_ = glm::vec4(0.0f);
    }
}

}  // namespace kiln::app
