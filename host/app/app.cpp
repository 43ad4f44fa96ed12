#include "app/app.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "kiln/data_root.hpp"
#include "kiln/log.hpp"
#include "ray/volume_faces.hpp"
#include "scene/punctual.hpp"
#include "scene/redraw_region.hpp"

namespace kiln::app {

namespace {

// glibc returns the top of the heap to the system whenever more than M_TRIM_THRESHOLD
// (128 KiB until a large block is freed) lies free there. llvmpipe allocates and frees
// its per-frame command and vertex memory every frame, so the heap was trimmed and
// regrown, page fault by page fault, every frame: 720² default pipeline, 147 ms a
// frame against 104 ms with trimming held off (gbuffer's CPU time 25 ms → 2 ms). The
// first App in a process paid it all; later ones were fast only because freeing the
// first one's large blocks raised glibc's dynamic threshold. Kiln keeps its freed heap
// instead: the peak it reached, no more.
void keepFreedHeap() {
    static const bool done = mallopt(M_TRIM_THRESHOLD, 1 << 30) == 1;
    (void)done;
}

}  // namespace

bool App::init(const Options& o, std::string& error) {
    keepFreedHeap();
    options_ = o;
    paused = o.paused;
    redrawParts = !o.fullRedraw;
    viewed = o.view;
    run::RuntimeOptions ro;
    // --shaders and --modules may list several directories, separated by ':'; the first
    // that has a file wins.
    for (const std::string& dir : pathList(o.shaderRoot)) ro.shaderRoots.emplace_back(dir);
    for (const std::string& dir : pathList(o.moduleDir)) ro.moduleDirs.emplace_back(dir);
    ro.pipelineSearchDirs = {(shippedFiles().data / "pipelines").string()};
    ro.width = o.width;
    ro.height = o.height;
    if (!runtime_.init(ro, error)) return false;
    runtime_.readEverything = o.headless && !o.dump.empty();  // --dump writes every texture
    if (!scene_.load(o.scene, seedOverride(), error)) return false;
    // A glTF file given as the scene is seen through its first camera, if it has one; a
    // scene without the box from the box's side and 20° above, framing the scene's bounds.
    glm::vec3 eye, forward;
    float fovY = 0.0f;
    if (scene_.modelCamera(eye, forward, fovY)) {
        camera_.lookFrom(eye, forward, fovY);
    } else if (!scene_.look().walls) {
        const glm::vec3 lo = scene_.boundsMin(), hi = scene_.boundsMax();
        camera_.target = 0.5f * (lo + hi);
        camera_.pitch = 0.35f;
        const float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
        camera_.distance = radius / std::sin(0.5f * camera_.fovY) * 1.05f;
    }
    requested_ = requestedTextures();
    runtime_.setRequested(requested_);
    std::vector<Runtime::ParamOverride> overrides;
    for (const std::string& set : o.sets)
        if (auto parsed = graph::parseParamOverride(set)) overrides.push_back(std::move(*parsed));  // checked when parsed
    runtime_.setOverrides(std::move(overrides));
    std::string errors;
    if (!runtime_.loadPipeline(o.pipeline, errors)) {
        if (!errors.empty() && errors.back() == '\n') errors.pop_back();
        error = errors;
        return false;
    }
    // A --view the pipeline has no texture for is an error, not a warning and the graph's
    // output instead.
    if (const auto& shown = runtime_.plan()->requested; !o.view.empty() && std::find(shown.begin(), shown.end(), o.view) == shown.end()) {
        error = "--view " + o.view + ": not a texture of the running pipeline";
        const std::string named = "viewed texture \"" + o.view + "\": ";
        for (const auto& w : runtime_.plan()->warnings)
            if (w.message.rfind(named, 0) == 0) error = "--view " + o.view + ": " + w.message.substr(named.size());
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
    if (width == refusedWidth_ && height == refusedHeight_) return;  // said once already
    std::string error;
    if (!runtime_.resize(width, height, error)) {
        refusedWidth_ = width, refusedHeight_ = height;
        if (!error.empty() && error.back() == '\n') error.pop_back();
        log::error(error);
        runtime_.setExternalError("resize", error + " (rendering stays at " + std::to_string(options_.width) + "x" +
                                                std::to_string(options_.height) + ")");
        return;
    }
    runtime_.setExternalError("resize", "");
    options_.width = width;
    options_.height = height;
}

std::optional<uint64_t> App::seedOverride() const {
    return options_.seed == kSceneSeed ? std::nullopt : std::optional<uint64_t>(options_.seed);
}

uint32_t App::meshClosedFaces(const glm::vec4& volume, glm::vec3 extent) {
    const uint64_t meshes = renderer_.version(kSceneMeshes);
    if (meshes != closedFacesMeshes_ || volume != closedFacesVolume_ || extent != closedFacesExtent_) {
        closedFacesMeshes_ = meshes, closedFacesVolume_ = volume, closedFacesExtent_ = extent;
        // Within two cells of the coarsest grid voxelize offers (32 along the longest side)
        // of the face: walls drawn to overlap at the corners put the bounds past them, and
        // a wall that far in is still in the outermost texel of every coarse level that a
        // lookup past the face clamps to (an empty border there faded it: a closed room
        // lost a third of its second bounce, tests/gi/test_bounces.cpp).
        const glm::vec3 half = volume.w * extent;
        const glm::vec3 cell = 2.0f * half / glm::vec3(glm::ivec3(32) >> voxelGridShift(extent));
        closedFaces_ = ray::closedVolumeFaces(renderer_.rayMeshData(), glm::vec3(volume), half, scene_.boundsMin(),
                                              scene_.boundsMax(), 2.0f * cell);
    }
    return closedFaces_;
}

SceneView App::buildView() {
    {
        // The whole scene in view from where the camera is, with room to back off; the
        // box's planes (kCameraFar) for anything smaller, so its depth is unchanged.
        const glm::vec3 lo = scene_.boundsMin(), hi = scene_.boundsMax();
        const float reach = glm::distance(camera_.position(), 0.5f * (lo + hi)) + 0.5f * glm::length(hi - lo);
        camera_.farPlane = std::max(kCameraFar, 2.0f * reach);
    }
    const glm::mat4 view = camera_.view();
    const glm::mat4 proj = camera_.projection(float(options_.width) / float(options_.height));
    scene_.writeTo(renderer_, scene_.sim().dragged());
    // The view's forward axis in the world: minus the view matrix's third row.
    const glm::vec3 forward = -glm::vec3(view[0][2], view[1][2], view[2][2]);
    renderer_.setViewer(camera_.position(), forward, proj[1][1] * 0.5f * float(options_.height));
    renderer_.upload();

    SceneView v;
    v.frame.view = view;
    v.frame.proj = proj;
    v.frame.viewProj = proj * view;
    v.frame.invViewProj = glm::inverse(v.frame.viewProj);
    v.frame.cameraPos = glm::vec4(camera_.position(), 1.0f);
    const scene::SceneLook& look = scene_.look();
    v.frame.lightPos = glm::vec4(look.lampCentre, look.lampRadius);
    v.frame.lightColor = glm::vec4(look.lampColor * look.lampIntensity, look.lampIntensity);
    v.frame.ringsLight = glm::vec4(look.ringsLight, look.woodRingFrequency);
    v.frame.ringsDark = glm::vec4(look.ringsDark, 0.0f);
    v.frame.roundCone = glm::vec4(look.tumblerB, look.tumblerT, look.tumblerAlpha,
                                     (look.tumblerB - look.tumblerT) / std::sin(look.tumblerAlpha));
    v.frame.voxelVolume = voxelVolumeAround(scene_.boundsMin(), scene_.boundsMax());
    const glm::vec3 extent = voxelExtentAround(scene_.boundsMin(), scene_.boundsMax());
    v.frame.voxelExtent = glm::vec4(extent, 0.0f);
    {
        // The voxel grids follow the volume's shape (they only ever shrink from the cube,
        // so the limits that admitted the pipeline admit them).
        const glm::ivec3 shift = voxelGridShift(extent);
        std::string error;
        if (!runtime_.setGridShape({{shift.x, shift.y, shift.z}}, error)) log::error(error);
    }
    // The box's walls close the volume's faces only where the volume is the box (a model
    // reaching out of it widens the volume past the walls). Without the box, the faces
    // its meshes close: a room's walls in the outermost voxels.
    const bool volumeIsBox = v.frame.voxelVolume == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f) && extent == glm::vec3(1.0f);
    uint32_t closed = 0;
    if (look.walls) closed = volumeIsBox ? closedFaceBits(look.closed) : 0u;
    else closed = meshClosedFaces(v.frame.voxelVolume, extent);
    v.frame.closedFaces = glm::uvec4(closed, 0u, 0u, 0u);
    v.frame.sceneMin = glm::vec4(scene_.boundsMin(), 0.0f);
    v.frame.sceneMax = glm::vec4(scene_.boundsMax(), 0.0f);
    scene::packPunctualLights(scene_.lights(), scene_.boundsMin(), scene_.boundsMax(), v.frame);
    v.materialTextures[0] = renderer_.materialTexture(0);
    v.materialTextures[1] = renderer_.materialTexture(1);
    v.rayMeshes = renderer_.rayMeshes();

    if (v.frame.viewProj != lastViewProj_) lastViewProj_ = v.frame.viewProj, ++cameraVersion_;
    lastVoxelVolume_ = v.frame.voxelVolume;
    lastVoxelExtent_ = extent;
    for (int i = 0; i < kSceneGeometryCount; ++i) {
        const auto c = SceneCategory(1u << i);
        v.versions[i] = renderer_.version(c);
        v.counts[i] = renderer_.count(c);
    }
    v.versions[sceneCategoryIndex(kSceneLights)] = scene_.lightsVersion();
    v.versions[sceneCategoryIndex(kSceneCamera)] = cameraVersion_;
    v.versions[sceneCategoryIndex(kSceneTime)] = timeVersion_;
    return v;
}

// A frame in which nothing but tumblers and marbles changed redraws where they were
// and are, their shadows and the light near them (scene/redraw_region.hpp), and one
// band of rows (kiln/pass.hpp, REDRAWING PART OF THE PICTURE); any other change, or a
// footprint over half the picture, redraws it all.
void App::chooseRedraw(const SceneView& view, FrameInfo& info) {
    const std::optional<std::vector<glm::vec4>> moved = renderer_.takeMovedBodies();
    bool onlyBodies = true;
    for (int i = 0; i < kSceneCategoryCount; ++i) {
        const uint32_t c = 1u << i;
        // Time moves on with the bodies; a pass that reads it redraws all (the runtime).
        if (c != kSceneRoundCones && c != kSceneSpheres && c != kSceneTime && view.versions[i] != lastVersions_[i])
            onlyBodies = false;
        lastVersions_[i] = view.versions[i];
    }
    if (!redrawParts || !onlyBodies || !moved || moved->empty()) return;
    scene::RedrawView where;
    where.viewProj = view.frame.viewProj;
    where.width = options_.width, where.height = options_.height;
    where.lampCentre = glm::vec3(view.frame.lightPos);
    where.lampRadius = view.frame.lightPos.w;
    const std::optional<PixelRect> changed = scene::changedPixels(*moved, where);
    if (!changed || 2.0 * changed->width * changed->height > double(options_.width) * options_.height) return;
    info.redraw[info.redrawCount++] = scene::redrawBand(redrawBand_++, options_.width, options_.height);
    if (!changed->empty()) info.redraw[info.redrawCount++] = *changed;
}

// Fixed steps for `wallSeconds` of wall clock × timeScale, while stepping fits in the
// budget; what it cannot step in time is dropped and counted.
int App::stepRealTime(double wallSeconds, std::chrono::steady_clock::time_point start) {
    const double dt = scene_.dt();
    accumulator_ += std::max(0.0, wallSeconds) * std::max(0.0, timeScale);
    int steps = 0;
    while (accumulator_ >= dt) {
        if (steps > 0 && std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() >
                             stepBudgetMs) {
            const double behind = std::floor(accumulator_ / dt) * dt;
            droppedSeconds += behind;
            accumulator_ -= behind;
            break;
        }
        scene_.step();
        accumulator_ -= dt;
        ++steps;
    }
    return steps;
}

int App::settle(int maxFrames) {
    const bool wasPaused = paused;
    paused = true;
    int frames = 0;
    for (; frames < maxFrames && runtime_.settling(); ++frames) frame();
    paused = wasPaused;
    return frames;
}

std::vector<std::string> App::requestedTextures() const {
    std::vector<std::string> out;
    if (!viewed.empty()) out.push_back(viewed);
    for (const std::string& t : alsoRead)
        if (!t.empty() && std::find(out.begin(), out.end(), t) == out.end()) out.push_back(t);
    return out;
}

void App::frame(double wallSeconds) {
    live_.poll(*this);  // edits land at a frame boundary, on this thread
    if (std::vector<std::string> requested = requestedTextures(); requested != requested_) {
        requested_ = requested;
        runtime_.setRequested(std::move(requested));
    }
    if (scene_.time() < lastSimTime_) droppedSeconds = 0.0;  // reset (R) or a reloaded scene
    const auto stepStart = std::chrono::steady_clock::now();
    int steps = 0;
    if (singleStep || (!paused && wallSeconds < 0.0)) {
        scene_.step();
        steps = 1;
    } else if (!paused) {
        steps = stepRealTime(wallSeconds, stepStart);
    }
    if (paused) accumulator_ = 0.0;
    singleStep = false;
    if (steps > 0) ++timeVersion_;
    lastSteps = steps;
    lastStepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - stepStart).count();
    lastSimTime_ = scene_.time();
    const SceneView view = buildView();
    FrameInfo info;
    info.index = frameIndex_++;
    info.time = scene_.time();
    info.dt = scene_.dt();
    info.outputWidth = options_.width, info.outputHeight = options_.height;
    chooseRedraw(view, info);
    lastFrame_ = info;
    runtime_.renderFrame(view, renderer_, info);
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
