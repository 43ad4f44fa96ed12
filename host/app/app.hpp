// app/app.hpp — one running Kiln: the scene (simulation + look), its renderer, the
// camera and the runtime, stepped a frame at a time. Shared by the window and the
// headless front ends. Data flows one way each frame: the live scene steps and writes
// what changed into the scene renderer; buildView() makes the whole SceneView from the
// renderer, the camera and the scene's look; the runtime runs the graph over it.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "app/camera.hpp"
#include "app/cli.hpp"
#include "app/live.hpp"
#include "run/runtime.hpp"
#include "scene/live_scene.hpp"
#include "scene/scene_renderer.hpp"

namespace kiln::app {

using run::Runtime;

class App {
public:
    bool init(const Options&, std::string& error);
    // Steps the simulation (unless paused), builds the scene view, runs the graph.
    // Headless (wallSeconds < 0): one fixed step per frame, so frame N is the same
    // everywhere. Window: simulated time follows the wall clock × timeScale in fixed
    // steps (an accumulator), real time at any frame rate as long as stepping fits in
    // stepBudgetMs a frame (a step of the shipped scene costs ~15 µs: 17 steps keep real
    // time at 14 fps in a quarter of a millisecond); beyond it the backlog is dropped,
    // so a slow frame never stalls on steps it cannot catch up with.
    void frame(double wallSeconds = -1.0);
    // Frames with the simulation held until no pass is settling (feedback converging
    // over frames, kiln/pass.hpp keepRunning), at most maxFrames; the frames it ran.
    // For an output written from one moment (--out, a test's read-back).
    int settle(int maxFrames = 64);
    double stepBudgetMs = 10.0;
    double timeScale = 1.0;
    int lastSteps = 0;          // steps taken in the last frame
    double lastStepMs = 0;      // what they cost, in all
    double droppedSeconds = 0;  // simulated time given up to the budget since the last reset or reload
    // The camera's view-projection of the last frame built (what its textures hold).
    const glm::mat4& viewProj() const { return lastViewProj_; }
    // The voxel volume of the last frame built (GpuFrame::voxelVolume).
    const glm::vec4& voxelVolume() const { return lastVoxelVolume_; }
    glm::vec3 voxelExtent() const { return lastVoxelExtent_; }
    // The graph output, or the texture chosen with --view / in the debug view.
    const TextureRef* displayedTexture() const;

    // The window's framebuffer changed size: reallocate size-relative textures.
    void resize(int width, int height);
    Runtime& runtime() { return runtime_; }
    const Runtime& runtime() const { return runtime_; }
    scene::LiveScene& scene() { return scene_; }
    const scene::LiveScene& scene() const { return scene_; }
    // The scene's geometry as last uploaded (its CPU side: ray hierarchies, material names).
    const scene::SceneRenderer& renderer() const { return renderer_; }
    Camera& camera() { return camera_; }
    const Camera& camera() const { return camera_; }
    LiveReload& live() { return live_; }
    // The seed given on the command line, if any (a scene reload keeps it).
    std::optional<uint64_t> seedOverride() const;
    bool paused = false;
    bool singleStep = false;
    // "pass.output" or empty for the graph output. Viewing a texture un-culls its
    // producer (from the next frame on), as --view does.
    std::string viewed;
    // More textures something outside the graph reads (the compare view's two): asked
    // for, so their producers run and write them (PassContext::isRead).
    std::vector<std::string> alsoRead;

    // Frames in which only bodies moved redraw part of the picture (--full-redraw: off).
    bool redrawParts = true;
    // What the last frame was asked to redraw (FrameInfo::redraw; count 0: all of it).
    const FrameInfo& lastFrame() const { return lastFrame_; }

private:
    SceneView buildView();
    // GpuFrame::closedFaces for a scene without the box: the faces of `volume` its meshes
    // close (ray::closedVolumeFaces), found again when the meshes or the volume change.
    uint32_t meshClosedFaces(const glm::vec4& volume, glm::vec3 extent);
    std::vector<std::string> requestedTextures() const;  // viewed, then alsoRead
    void chooseRedraw(const SceneView&, FrameInfo&);

    int stepRealTime(double wallSeconds, std::chrono::steady_clock::time_point start);

    Options options_;
    Runtime runtime_;
    scene::LiveScene scene_;
    scene::SceneRenderer renderer_;
    Camera camera_;
    LiveReload live_;
    uint64_t frameIndex_ = 0;
    glm::mat4 lastViewProj_{0.0f};
    glm::vec4 lastVoxelVolume_{0.0f, 0.0f, 0.0f, 1.0f};
    glm::vec3 lastVoxelExtent_{1.0f};
    uint64_t closedFacesMeshes_ = ~uint64_t(0);
    glm::vec4 closedFacesVolume_{0.0f};
    glm::vec3 closedFacesExtent_{0.0f};
    uint32_t closedFaces_ = 0;
    uint64_t cameraVersion_ = 0, timeVersion_ = 0;
    uint64_t lastVersions_[kSceneCategoryCount] = {};  // the last frame's, for chooseRedraw
    int redrawBand_ = 0;
    FrameInfo lastFrame_;
    double accumulator_ = 0.0;
    double lastSimTime_ = 0.0;   // the scene's time after the last frame (a smaller one: reset or reload)
    std::vector<std::string> requested_;  // what the runtime was last asked to keep un-culled and written
    int refusedWidth_ = 0, refusedHeight_ = 0;  // a size the runtime refused
};

int runWindow(const Options&);

}  // namespace kiln::app
