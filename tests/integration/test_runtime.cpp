// The runtime's resource pool and skipping, on the real modules.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "app/app.hpp"
#include "app/pixel_trace.hpp"
#include "app/window_state.hpp"
#include "kiln/image_io.hpp"
#include "support/headless.hpp"

using namespace kiln;

namespace {

struct Fixture {
    app::App app;
    Fixture(int size = 48) {
        REQUIRE(test::ensureHeadlessContext());
        std::string error;
        REQUIRE(app.init(test::pausedHeadlessOptions(size), error));
    }
    GLuint texture(const char* pass, const char* name) {
        const TextureRef* t = app.runtime().findTexture(pass, name);
        return t ? t->id : 0;
    }
};

// A minimal two-pass pipeline whose composite exposure is `exposure`.
std::string pipelineWithExposure(double exposure) {
    std::ostringstream s;
    s << R"({"output": "composite.color", "passes": [
          {"id": "gbuffer", "module": "gbuffer"},
          {"id": "composite", "module": "composite", "params": {"exposure": )"
      << exposure << R"(},
           "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}}]})";
    return s.str();
}

}  // namespace

TEST_CASE("recompiling keeps textures, and a pass whose parameters changed runs again", "[runtime][gl]") {
    Fixture f;
    std::string errors;
    REQUIRE(f.app.runtime().loadPipelineText(pipelineWithExposure(1.0), "a.json", errors));
    f.app.frame();
    const GLuint albedo = f.texture("gbuffer", "albedo"), color = f.texture("composite", "color");
    REQUIRE(albedo != 0);
    REQUIRE(color != 0);
    auto ran = [&](const std::string& id) {
        for (auto& r : f.app.runtime().stats())
            if (r.id == id) return r.ranFrames;
        return -1;
    };
    const int gbufferRuns = ran("gbuffer"), compositeRuns = ran("composite");
    REQUIRE(f.app.runtime().loadPipelineText(pipelineWithExposure(2.0), "a.json", errors));
    CHECK(f.texture("gbuffer", "albedo") == albedo);  // same module, params, inputs
    CHECK(f.texture("composite", "color") == color);  // new params, same shape: same texture
    f.app.frame();
    CHECK(ran("gbuffer") == gbufferRuns);          // nothing it reads changed: skipped
    CHECK(ran("composite") == compositeRuns + 1);  // its parameters changed: ran again
}

TEST_CASE("an invalid pipeline keeps the running plan", "[runtime][gl]") {
    Fixture f;
    std::string errors;
    REQUIRE(f.app.runtime().loadPipelineText(pipelineWithExposure(1.0), "a.json", errors));
    const GLuint color = f.texture("composite", "color");
    CHECK_FALSE(f.app.runtime().loadPipelineText(pipelineWithExposure(99.0), "a.json", errors));
    CHECK_THAT(errors, Catch::Contains("passes[1].params.exposure"));
    CHECK(f.texture("composite", "color") == color);
    REQUIRE(f.app.runtime().plan());
    CHECK(f.app.runtime().plan()->passes.size() == 2);
}

TEST_CASE("resizing reallocates output-relative textures at the new size", "[runtime][gl]") {
    Fixture f(40);
    f.app.frame();
    REQUIRE(f.app.runtime().findTexture("gbuffer", "depth")->width == 40);
    f.app.resize(64, 32);
    f.app.frame();
    const TextureRef* depth = f.app.runtime().findTexture("gbuffer", "depth");
    CHECK(depth->width == 64);
    CHECK(depth->height == 32);
    const TextureRef* out = f.app.displayedTexture();
    FloatImage img = readTexture(out->id, out->target, out->format, out->width, out->height);
    CHECK(img.width == 64);
}

TEST_CASE("a pass whose inputs, parameters and scene did not change is skipped", "[runtime][gl]") {
    Fixture f;
    f.app.frame();
    // The default's voxel_mip feeds its bounces back: it asks for 16 more frames
    // (keepRunning), and what reads it runs with it; then the paused frame is still.
    CHECK(f.app.runtime().settling());
    CHECK(f.app.settle() == 16);
    CHECK_FALSE(f.app.runtime().settling());
    f.app.runtime().resetTimings();
    f.app.frame();
    for (auto& row : f.app.runtime().stats()) {
        INFO(row.id);
        CHECK(row.ranFrames == 0);
        CHECK(row.skippedFrames == 1);
        CHECK(row.state == "skipped");
    }
    // Moving the camera re-runs the gbuffer and what reads it; the shadow map and the
    // voxels do not depend on the camera and stay as they are.
    f.app.camera().yaw += 0.1f;
    f.app.frame();
    const std::set<std::string> cameraFree = {"shadow", "lights", "voxelize", "voxel_mip"};
    for (auto& row : f.app.runtime().stats()) {
        INFO(row.id);
        CHECK(row.ranFrames == (cameraFree.count(row.id) ? 0 : 1));
    }
}

TEST_CASE("a texture's setup stays while only instances move, and changes with anything else that made it",
          "[runtime][gl]") {
    // TextureRef::setup (kiln/pass.hpp, REUSING WHAT DID NOT CHANGE): what a pass may
    // compare to reuse what it computed from an input where no instance moved.
    Fixture f;
    f.app.frame();
    f.app.settle();
    auto setup = [&](const char* pass, const char* name) {
        const TextureRef* t = f.app.runtime().findTexture(pass, name);
        REQUIRE(t);
        return t->setup;
    };
    const uint64_t gbuffer = setup("gbuffer", "albedo"), shadow = setup("shadow", "depth");
    const uint64_t mips = setup("voxel_mip", "iso");
    CHECK(gbuffer != 0);
    CHECK(shadow != 0);
    // The scene running: the bodies move, time passes.
    f.app.paused = false;
    for (int i = 0; i < 3; ++i) f.app.frame();
    CHECK(setup("gbuffer", "albedo") == gbuffer);
    CHECK(setup("shadow", "depth") == shadow);
    // voxel_mip feeds its bounces back (keepRunning): its volumes change with nothing
    // moving too.
    CHECK(setup("voxel_mip", "iso") != mips);
    f.app.paused = true;
    // A parameter: its pass and those after it, not the others.
    std::string error;
    REQUIRE(f.app.runtime().setParam("gbuffer", "particles", false, error));
    f.app.frame();
    const uint64_t gbuffer2 = setup("gbuffer", "albedo");
    CHECK(gbuffer2 != gbuffer);
    CHECK(setup("composite", "color") != 0);
    CHECK(setup("shadow", "depth") == shadow);
    // The camera: what reads it.
    f.app.camera().yaw += 0.1f;
    f.app.frame();
    CHECK(setup("gbuffer", "albedo") != gbuffer2);
    CHECK(setup("shadow", "depth") == shadow);
    // The shadow map's parameter, with nothing moving: its depths change in place.
    REQUIRE(f.app.runtime().setParam("shadow", "slope_bias", 8.0f, error));
    f.app.frame();
    CHECK(setup("shadow", "depth") != shadow);
}

TEST_CASE("a pass that asks to keep running gets its frames after each change, not more, and then skips",
          "[runtime][gl]") {
    // The default's voxel_mip feeds its bounces back and asks for 16 frames after each
    // run that a change caused (PassContext::keepRunning). Its settling frames do not
    // extend themselves; a change part way through starts the count again; a paused
    // frame after them skips it.
    Fixture f;
    auto voxelMip = [&] {
        for (const auto& row : f.app.runtime().stats())
            if (row.id == "voxel_mip") return row;
        FAIL("no voxel_mip row");
        return run::PassRow{};
    };
    f.app.frame();
    for (int i = 0; i < 5; ++i) f.app.frame();
    CHECK(voxelMip().ranFrames == 6);
    CHECK(voxelMip().why.find("settling (voxel bounces fed back): 11 more frames") != std::string::npos);
    std::string error;
    REQUIRE(f.app.runtime().setParam("voxel_mip", "gather_diameter_offset", ParamValue(1.25f), error));
    f.app.frame();  // the change: a run of its own, and 16 frames again from here
    CHECK(f.app.settle() == 16);
    CHECK(voxelMip().ranFrames == 6 + 1 + 16);
    f.app.frame();
    CHECK(voxelMip().state == "skipped");
    CHECK(voxelMip().ranFrames == 23);
}

TEST_CASE("viewing a culled pass's texture un-culls it without renewing other textures", "[runtime][gl]") {
    Fixture f;
    std::string errors;
    // A second gbuffer nobody reads: culled.
    std::string text = R"({"output": "composite.color", "passes": [
          {"id": "gbuffer", "module": "gbuffer"},
          {"id": "spare", "module": "gbuffer"},
          {"id": "composite", "module": "composite",
           "inputs": {"albedo": "gbuffer.albedo", "normal": "gbuffer.normal", "depth": "gbuffer.depth"}}]})";
    REQUIRE(f.app.runtime().loadPipelineText(text, "c.json", errors));
    f.app.frame();
    auto stateOf = [&](const std::string& id) {
        for (auto& r : f.app.runtime().stats())
            if (r.id == id) return r.state;
        return std::string("?");
    };
    CHECK(stateOf("spare") == "culled");
    const GLuint color = f.texture("composite", "color");
    // Selecting the texture in the window (App::viewed) is enough, as --view is.
    f.app.viewed = "spare.normal";
    f.app.frame();
    CHECK(stateOf("spare") == "ran");
    CHECK(f.texture("composite", "color") == color);
    f.app.viewed.clear();
    f.app.frame();
    CHECK(stateOf("spare") == "culled");
}

TEST_CASE("a pass that did not run this frame reports no cost this frame", "[runtime][gl]") {
    Fixture f;
    f.app.frame();
    for (auto& r : f.app.runtime().stats()) {
        INFO(r.id);
        CHECK(r.ranThisFrame);
    }
    f.app.settle();  // voxel_mip's feedback converges
    f.app.runtime().resetTimings();
    f.app.frame();  // paused: everything skips
    for (auto& r : f.app.runtime().stats()) {
        INFO(r.id << " " << r.state);
        CHECK(r.state == "skipped");
        CHECK_FALSE(r.ranThisFrame);
        CHECK(r.skippedFrames == 1);
    }
    // No execute() ran, so nothing was spent inside the passes; the frame's own CPU cost
    // is the graph's bookkeeping only.
    CHECK(f.app.runtime().lastFrameCost().passesMs == 0.0);
}

TEST_CASE("textures beyond the budget or the GL limits are a named error and the running plan stays",
          "[runtime][gl][robust]") {
    REQUIRE(test::ensureHeadlessContext());
    app::Options o = test::pausedHeadlessOptions(64);
    run::RuntimeOptions ro;
    ro.shaderRoots = {o.shaderRoot};
    ro.moduleDirs = {o.moduleDir};
    ro.width = ro.height = 64;
    // The course pipeline at 64² needs 68 MiB (a 2048² depth map is 16 MiB; voxelize's
    // 64³ sums and the lamp dome's copy of them 14 MiB each; the 64³ volumes, their mips
    // and voxel_mip's scratch volumes, which the host allocates whether or not a pass's
    // settings use them, most of the rest); an 80 MiB budget holds it, but not its
    // variant with a 4096² shadow map (+ 48 MiB) nor the same plan at 4096² (a 4096²
    // RGBA16F is 128 MiB).
    ro.textureBudgetBytes = 80ull << 20;
    run::Runtime rt;
    std::string error;
    REQUIRE(rt.init(ro, error));
    const bool loaded = rt.loadPipeline(std::string(KILN_SOURCE_DIR) + "/pipelines/course.json", error);
    INFO(error);
    REQUIRE(loaded);
    const graph::Plan* before = rt.plan();
    const std::string text = rt.pipelineText();
    std::string big = text;
    const std::string from = R"("params": { "size": 2048 })";
    const size_t at = big.find(from);
    REQUIRE(at != std::string::npos);
    big.replace(at, from.size(), R"("params": { "size": 4096 })");
    std::string errors;
    CHECK_FALSE(rt.loadPipelineText(big, "big.json", errors));
    CHECK_THAT(errors, Catch::Contains("big.json: its textures would take") && Catch::Contains("over the texture budget of 80 MiB"));
    CHECK(rt.plan() == before);
    CHECK(rt.pipelineText() == text);
    // A resize past the budget is refused; the textures keep their size.
    CHECK_FALSE(rt.resize(4096, 4096, errors));
    CHECK_THAT(errors, Catch::Contains("over the texture budget"));
    CHECK(rt.findTexture("gbuffer", "albedo")->width == 64);
    // Past GL_MAX_TEXTURE_SIZE (16384 on llvmpipe) whatever the budget.
    GLint max2D = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max2D);
    CHECK_FALSE(rt.resize(max2D + 1, 8, errors));
    CHECK_THAT(errors, Catch::Contains("beyond this GL's GL_MAX_TEXTURE_SIZE " + std::to_string(max2D)));
    CHECK(rt.resize(80, 80, errors));
    CHECK(rt.findTexture("gbuffer", "albedo")->width == 80);
}

TEST_CASE("setParam changes the running pass without a recompile, refuses bad values by name, resizes by recompiling", "[runtime][gl]") {
    Fixture f;
    run::Runtime& rt = f.app.runtime();
    std::string errors;
    REQUIRE(rt.loadPipelineText(pipelineWithExposure(1.0), "a.json", errors));
    f.app.frame();
    auto centreLuma = [&] {
        const TextureRef* t = rt.findTexture("composite", "color");
        const FloatImage img = readTexture(t->id, t->target, t->format, t->width, t->height);
        const float* p = img.at(img.width / 2, img.height / 2);
        return p[0] + p[1] + p[2];
    };
    auto ran = [&](const std::string& id) {
        for (auto& r : rt.stats())
            if (r.id == id) return r.ranFrames;
        return -1;
    };
    const float before = centreLuma();
    const int gbufferRuns = ran("gbuffer"), compositeRuns = ran("composite");
    const std::string fileText = rt.pipelineText();

    std::string error;
    REQUIRE(rt.setParam("composite", "exposure", 0.25f, error));
    CHECK(*rt.plan()->passes[size_t(rt.plan()->find("composite"))].params.get<float>("exposure") == 0.25f);
    f.app.frame();
    CHECK(ran("composite") == compositeRuns + 1);  // it runs again ...
    CHECK(ran("gbuffer") == gbufferRuns);          // ... and nothing upstream does
    CHECK(centreLuma() < before * 0.75f);          // a quarter of the exposure, through ACES
    CHECK(rt.pipelineText() == fileText);          // the file's text is only changed by write-back
    // The description carries the edit (what write-back writes and a recompile keeps).
    const graph::PassDesc& desc = rt.pipelineDesc()->passes[size_t(rt.pipelineDesc()->find("composite"))];
    CHECK(std::any_of(desc.params.begin(), desc.params.end(),
                      [](auto& p) { return p.first == "exposure" && p.second.f == 0.25; }));

    CHECK_FALSE(rt.setParam("composite", "exposure", 99.0f, error));
    CHECK_THAT(error, Catch::Contains("composite.params.exposure") && Catch::Contains("out of range"));
    CHECK_FALSE(rt.setParam("composite", "exposure", std::string("bright"), error));
    CHECK_THAT(error, Catch::Contains("expected float"));
    CHECK_FALSE(rt.setParam("composite", "nope", 1.0f, error));
    CHECK_THAT(error, Catch::Contains("no parameter \"nope\""));
    CHECK_FALSE(rt.setParam("ghost", "exposure", 1.0f, error));
    CHECK_THAT(error, Catch::Contains("no pass \"ghost\""));
    CHECK(*rt.plan()->passes[size_t(rt.plan()->find("composite"))].params.get<float>("exposure") == 0.25f);  // kept

    // A parameter a texture is sized from goes through a recompile: the texture follows.
    REQUIRE(f.app.runtime().loadPipeline(KILN_SOURCE_DIR "/pipelines/default.json", errors));
    REQUIRE(rt.setParam("shadow", "size", 512, error));
    const TextureRef* depth = rt.findTexture("shadow", "depth");
    REQUIRE(depth);
    CHECK(depth->width == 512);
}

TEST_CASE("the window's clock keeps real time while stepping fits its budget, and drops only what it cannot step",
          "[runtime][gl]") {
    Fixture f(16);
    app::App& app = f.app;
    app.paused = false;
    const double dt = app.scene().dt();
    // A generous budget: half a second of wall clock is half a second simulated (the old
    // fixed cap of 4 steps a frame gave 4 dt, 3 % of it, and dropped the rest).
    app.stepBudgetMs = 1e9;
    double before = app.scene().time();
    app.frame(0.5);
    CHECK(app.lastSteps == int(std::floor(0.5 / dt + 1e-9)));
    CHECK(app.scene().time() - before == Approx(0.5).margin(dt));  // the remainder waits in the accumulator
    CHECK(app.droppedSeconds == 0.0);
    // No budget: one step, and the rest of the half second is counted as dropped.
    app.stepBudgetMs = 0.0;
    before = app.scene().time();
    app.frame(0.5);
    CHECK(app.lastSteps == 1);
    CHECK(app.scene().time() - before == Approx(dt));
    CHECK(app.droppedSeconds == Approx(0.5 - dt).margin(dt));
    // A reset (R) starts the count over.
    app.scene().reset();
    app.frame(0.0);
    CHECK(app.droppedSeconds == 0.0);
}

TEST_CASE("the resolution budget never halves the image on its own, and comes back when frames are cheap", "[runtime]") {
    app::WindowState state;
    state.budgetMs = 16.0f;
    state.frameMs = 1000.0;  // far over the budget, and fewer pixels do not help
    double now = 0.0;
    float lowest = 1.0f;
    for (int frame = 0; frame < 200; ++frame, now += 1.0) {  // a second a frame: every frame may step
        app::followBudget(state, now);
        lowest = std::min(lowest, state.renderScale);
    }
    CHECK(lowest < 0.6f);   // it did step down,
    CHECK(lowest >= 0.5f);  // but not below half size
    state.frameMs = 1.0;    // cheap frames: back to full size
    for (int frame = 0; frame < 200; ++frame, now += 1.0) app::followBudget(state, now);
    CHECK(state.renderScale == 1.0f);
}

TEST_CASE("a pixel traced through the graph: each 2D texture where the pixel falls in it, the 3D ones at its world position",
          "[runtime][gl]") {
    constexpr int kSize = 32, kX = 22, kY = 24;  // high on the back wall right of the lamp, y up; nothing there at t = 0
    Fixture f(kSize);
    f.app.frame();
    const glm::vec2 uv((kX + 0.5f) / kSize, (kY + 0.5f) / kSize);
    const app::PixelTrace trace = app::tracePixel(f.app.runtime(), glm::inverse(f.app.viewProj()), f.app.voxelVolume(), f.app.voxelExtent(), uv);

    // The world position, another way: the camera's ray through that pixel meets the back
    // wall z = −1. Tolerance 2 mm: depth quantisation is ~0.1 mm here; half a pixel off
    // would be ~5 cm.
    CHECK(trace.depthTexture == "gbuffer.depth");
    REQUIRE(trace.world);
    glm::vec3 origin, direction;
    f.app.camera().rayThrough(kX, kSize - 1 - kY, kSize, kSize, origin, direction);
    const glm::vec3 onWall = origin + direction * ((-1.0f - origin.z) / direction.z);
    REQUIRE(std::max(std::abs(onWall.x), std::abs(onWall.y)) < 0.95f);  // the pixel is on the back wall
    INFO("traced " << trace.world->x << "," << trace.world->y << "," << trace.world->z << "; ray " << onWall.x << ","
                   << onWall.y << "," << onWall.z);
    CHECK(glm::length(*trace.world - onWall) < 2e-3f);

    // The textures of the plan appear; 2D values equal a whole-texture read-back at the
    // texel the pixel falls in (full size: the pixel itself; the half-size bloom: half).
    std::set<std::string> traced;
    int full = 0, half = 0, tiledRows = 0;
    for (const app::TraceRow& r : trace.rows) {
        traced.insert(r.pass + "." + r.name);
        const TextureRef* t = f.app.runtime().findTexture(r.pass, r.name);
        REQUIRE(t);
        INFO(r.pass << "." << r.name);
        if (!r.volume) {
            CHECK(r.texel == glm::ivec3(int(uv.x * t->width), int(uv.y * t->height), 0));
            full += t->width == kSize && r.texel == glm::ivec3(kX, kY, 0);
            half += t->width == kSize / 2 && r.texel == glm::ivec3(kX / 2, kY / 2, 0);
            const FloatImage whole = readTexture(t->id, t->target, t->format, t->width, t->height);
            for (int c = 0; c < whole.channels && c < 4; ++c) CHECK(r.value[c] == whole.at(r.texel.x, r.texel.y)[c]);
            continue;
        }
        REQUIRE(r.read);
        // Blocks are cubes of the texture's height, side by side along x.
        const glm::ivec3 voxel = glm::ivec3((*trace.world + 1.0f) * 0.5f * float(t->height));
        CHECK(r.texel == glm::ivec3(voxel.x + std::max(r.tile, 0) * t->height, voxel.y, voxel.z));
        tiledRows += r.tile >= 0;
        if (r.pass == "voxelize" && r.name == "radiance") CHECK(r.value.a > 0.0f);  // the wall's voxel is occupied
    }
    // Every texture that holds this frame's data: an output its pass writes only when
    // read, and nothing reads (composite.hdr here), is stale and left out; one nothing
    // reads that its pass writes anyway (voxel_mip.aniso, blended into the fixed cones) is in.
    int stale = 0, unreadButWritten = 0;
    for (const auto& t : f.app.runtime().textures()) {
        if (t.ref.bound) CHECK(traced.count(t.pass + "." + t.name) == (t.stale ? 0u : 1u));
        stale += t.stale;
        unreadButWritten += !t.read && !t.stale;
    }
    CHECK(stale == 1);
    CHECK(unreadButWritten >= 1);
    CHECK(full >= 4);   // gbuffer's outputs, composite's
    CHECK(half >= 1);   // bloom at half resolution
    CHECK(tiledRows >= 12);  // the fixed cones' atlas, one row per direction
}
