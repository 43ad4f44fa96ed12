#include "app/app.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include "kiln/log.hpp"

namespace kiln::app {

bool App::init(const Options& o, std::string& error) {
    options_ = o;
    paused = o.paused;
    viewed = o.view;
    RuntimeOptions ro;
    ro.shaderRoots = {o.shaderRoot};
    // --modules may list several directories, separated by ':'.
    for (size_t start = 0; start <= o.moduleDir.size();) {
        size_t end = o.moduleDir.find(':', start);
        if (end == std::string::npos) end = o.moduleDir.size();
        if (end > start) ro.moduleDirs.emplace_back(o.moduleDir.substr(start, end - start));
        start = end + 1;
    }
    ro.width = o.width;
    ro.height = o.height;
    if (!runtime_.init(ro, error)) return false;
    if (!world_.load(o.scene, o.seed, error)) return false;
    runtime_.scene().init(world_.box(), world_.shape());
    if (!viewed.empty()) runtime_.setRequested({viewed});
    std::string errors;
    if (!runtime_.loadPipeline(o.pipeline, errors)) {
        if (!errors.empty() && errors.back() == '\n') errors.pop_back();
        error = errors;
        return false;
    }
    if (o.live) live_.start(*this);
    if (o.printPlan) std::printf("%s", runtime_.plan()->table().c_str());
    if (!o.dot.empty()) {
        std::FILE* f = std::fopen(o.dot.c_str(), "w");
        if (!f) {
            error = o.dot + ": cannot write";
            return false;
        }
        std::fputs(runtime_.plan()->dot().c_str(), f);
        std::fclose(f);
    }
    return true;
}

void App::resize(int width, int height) {
    if (width < 1 || height < 1 || (width == options_.width && height == options_.height)) return;
    options_.width = width;
    options_.height = height;
    runtime_.resize(width, height);
}

SceneView App::buildView() const {
    SceneView v;
    const int w = options_.width, h = options_.height;
    v.cameraPos = camera_.position();
    const glm::mat4 view = camera_.view();
    const glm::mat4 proj = camera_.projection(float(w) / float(h));
    v.frame.view = view;
    v.frame.proj = proj;
    v.frame.viewProj = proj * view;
    v.frame.invViewProj = glm::inverse(v.frame.viewProj);
    v.frame.cameraPos = glm::vec4(v.cameraPos, 1.0f);
    const BoxLook& box = world_.box();
    v.lightPos = box.lampCentre;
    v.lampRadius = box.lampRadius;
    v.lightColor = box.lampColor * box.lampIntensity;
    v.frame.lightPos = glm::vec4(box.lampCentre, box.lampRadius);
    v.frame.lightColor = glm::vec4(v.lightColor, box.lampIntensity);
    return v;
}

void App::frame() {
    live_.poll(*this);  // edits land at a frame boundary, on this thread
    if (!paused || singleStep) {
        world_.step();
        singleStep = false;
    }
    SceneView view = buildView();
    static_assert(sizeof(view.versions) == 6 * sizeof(uint64_t));
    world_.sync(runtime_.scene(), sceneVersions_, world_.sim().dragged());
    if (view.frame.viewProj != lastViewProj_) {
        lastViewProj_ = view.frame.viewProj;
        ++sceneVersions_[sceneCategoryIndex(kSceneCamera)];
    }
    if (!paused) ++sceneVersions_[sceneCategoryIndex(kSceneTime)];
    std::copy(std::begin(sceneVersions_), std::end(sceneVersions_), view.versions);
    for (uint32_t bit = 0; bit < 6; ++bit) {
        view.counts[bit] = runtime_.scene().count(DrawCategory(1u << bit));
        view.drawVersions[bit] = runtime_.scene().version(DrawCategory(1u << bit));
    }

    FrameInfo info;
    info.index = frameIndex_++;
    info.time = world_.time();
    info.dt = world_.dt();
    runtime_.renderFrame(view, info);
}

const TextureRef* App::displayedTexture() const {
    if (!viewed.empty()) {
        auto dot = viewed.find('.');
        if (dot != std::string::npos)
            if (const TextureRef* t = runtime_.findTexture(viewed.substr(0, dot), viewed.substr(dot + 1))) return t;
    }
    return runtime_.outputTexture();
}

}  // namespace kiln::app
