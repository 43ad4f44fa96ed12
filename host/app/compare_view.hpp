// app/compare_view.hpp — the window's compare view: two textures of the running graph
// (by default composite.hdr against the path-traced reference.radiance, as
// pipelines/compare.json runs them) in one image, A left and B right of a line the user
// drags, with the error of A against B (host/metrics: RMSE, relative MSE, PSNR, SSIM)
// refreshed every second while the reference converges.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "app/texture_viewer.hpp"
#include "metrics.hpp"

namespace kiln::app {

class App;

class CompareView {
public:
    bool on = false;
    std::string a = "composite.hdr", b = "reference.radiance";
    float split = 0.5f;              // where the line is, 0..1 across the image
    bool tonemap = true;             // both through ACES + gamma, as composite shows radiance
    bool dragging = false;

    // Measures A against B, at most once a second (while the view is on, whether or not
    // its panel is shown).
    void update(const App&, double now);
    // The sidebar's "Compare" tab: what to compare, the figures; `probe` records a widget
    // for --ui-probe.
    void panel(App&, const std::function<void(const std::string&)>& probe);
    // A in the whole image rectangle (GL pixels, origin bottom-left), B right of the line.
    void draw(const TextureViewer&, const App&, glm::ivec4 rect) const;
    const std::optional<metrics::Errors>& errors() const { return errors_; }
    int referenceSamples() const { return samples_; }

private:
    void measure(const App&);
    std::optional<metrics::Errors> errors_;
    std::string problem_;            // why there are no figures (a texture missing, sizes differ)
    int samples_ = 0;                // B's alpha when it is a progressive reference (paths per pixel)
    double lastMeasure_ = -1.0;
};

}  // namespace kiln::app
