// app/texture_viewer.hpp — the debug view's texture window (RenderDoc's texture viewer
// is the model): any texture of the running graph at 1:1, zoom and pan, nearest-
// neighbour texels, the raw value under the cursor, a range fitted to what is in view
// with its histogram, false colour for one channel, depth in metres, mips and 3D
// slices. Display settings are kept per texture.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "kiln/gl.hpp"
#include "kiln/pass.hpp"
#include "kiln/shader.hpp"
#include "run/texture_pool.hpp"

namespace kiln::app {

struct ViewSettings {
    int channel = 0;              // 0 RGB, 1 R, 2 G, 3 B, 4 A
    float rangeMin = 0.0f, rangeMax = 1.0f;
    bool falseColor = true;       // one channel through a colour map
    bool linearizeDepth = true;   // depth with declared planes: metres
    bool checker = false;         // blend over a checkerboard by alpha
    bool tonemap = false;         // RGB radiance through ACES + gamma, as composite shows it
    int mip = 0;
    int axis = 2;                 // 3D: 0 x, 1 y, 2 z
    int slice = -1;               // 3D: texel along the axis; -1 = the middle
    float zoom = 0.0f;            // screen pixels per texel; 0 = fit to the canvas
    glm::vec2 center{-1.0f};      // texel-space point at the canvas centre; < 0 = middle
    bool fitted = false;          // the range was fitted once (on first view)
};

// What the cursor is over: texel coordinates in the displayed plane and the raw value.
struct TexelReadout {
    glm::ivec3 texel{0};          // x, y, z in the texture (z: the slice, 0 for 2D)
    int mip = 0;
    glm::vec4 value{0.0f};        // as stored: floats, uint counts as floats, depth in r
    bool isInteger = false, isDepth = false;
};

// A range and a 64-bin histogram of the channel(s) shown, over the texels in view.
struct RangeFit {
    float min = 0.0f, max = 0.0f;
    std::array<float, 64> histogram{};
    size_t texels = 0, nonFinite = 0;
};

// readTextureBox (kiln/image_io.hpp) of a TextureRef.
std::vector<float> readTexelBox(const TextureRef&, int level, glm::ivec3 origin, glm::ivec3 size);

// The displayed plane (a 2D level, or one slice of a 3D one along `axis`) in texels.
glm::ivec2 planeSize(const TextureRef&, int mip, int axis);

class TextureViewer {
public:
    bool init(const ShaderLibrary&, std::string& error);
    // Rebuild the display program after a shader edit; keeps the old one on error.
    bool reload(const ShaderLibrary&, std::string& error);

    // Draws `t` into the current framebuffer's rectangle (x, y, w, h in GL pixels,
    // origin bottom-left) with `s`.
    // `legendPx` > 0: a strip that tall along the bottom shows the colour map over the range.
    void draw(const TextureRef& t, float depthNear, float depthFar, const ViewSettings& s, glm::ivec4 rect,
              int legendPx = 0) const;
    // The "Texture" ImGui window for `t`: toolbar, canvas, readout, histogram.
    void window(const run::NamedTexture& t, const char* title, bool* open);
    // Screen rectangle of the canvas in the last window() (x0, y0, x1, y1), for --ui-probe.
    glm::vec4 canvasRect() const { return canvasRect_; }
    glm::vec4 histogramRect() const { return histogramRect_; }  // zero when none is drawn
    glm::vec4 saveButtonRect() const { return saveButtonRect_; }
    glm::vec4 windowRect() const { return windowRect_; }
    // Where "save" writes the texture shown (PNG, and OpenEXR with the raw values for
    // float and depth formats): --dump's directory, else ./kiln-saves.
    void setSaveDirectory(std::filesystem::path dir) { saveDir_ = std::move(dir); }
    // Writes the level (and, for 3D seen along z, the slice) on view; says so in lastSaved().
    void save(const run::NamedTexture& nt, const ViewSettings& s);
    const std::string& lastSaved() const { return lastSaved_; }  // the file written, or why not

    ViewSettings& settingsFor(const std::string& name) { return settings_[name]; }
    const std::optional<TexelReadout>& lastReadout() const { return readout_; }
    const std::optional<RangeFit>& lastFit() const { return fit_; }
    // Canvas pixel (origin bottom-left) → texel of the displayed plane; the same
    // mapping as shaders/host/display.frag.
    static glm::vec2 texelAt(glm::vec2 canvasPixel, glm::vec2 canvasSize, const ViewSettings&, glm::ivec2 plane);
    // Fits s.rangeMin/Max to the texels of the plane inside the canvas.
    static RangeFit fitRange(const TextureRef&, float depthNear, float depthFar, ViewSettings& s, glm::vec2 canvasSize);

private:
    // The parts of window(): the controls above the image (true: "fit range" pressed),
    // the canvas texture at `size`, the mouse over it (pan, zoom, the texel under the
    // cursor), the readout and histogram below it.
    bool controls(const run::NamedTexture& nt, ViewSettings& s);
    void ensureCanvas(glm::ivec2 size);
    void canvasInput(const TextureRef& t, ViewSettings& s, glm::vec2 canvasTopLeft, glm::ivec2 size, bool hovered,
                     bool active);
    void readoutAndHistogram(const run::NamedTexture& nt, const std::string& name);

    gl::ProgramHandle program_;
    gl::ProgramHandle plainProgram_;  // KILN_DISPLAY_PLAIN: a float 2D texture as it is
    gl::VertexArrayHandle vao_;
    mutable gl::FramebufferHandle blitSource_;  // the shown texture, attached while it is copied
    gl::Texture canvas_;           // the ImGui window's image, redrawn every frame
    gl::FramebufferHandle canvasFbo_;
    std::map<std::string, ViewSettings> settings_;
    std::optional<TexelReadout> readout_;
    std::optional<RangeFit> fit_;
    std::string fitFor_;           // which texture fit_ describes
    bool autoFit_ = false;
    glm::vec4 canvasRect_{0.0f}, histogramRect_{0.0f}, saveButtonRect_{0.0f}, windowRect_{0.0f};
    std::filesystem::path saveDir_ = "kiln-saves";
    std::string lastSaved_;
};

}  // namespace kiln::app
