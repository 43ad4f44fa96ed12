// Live editing with the real watcher on real files in a temporary copy of the
// project's shaders, pipelines and scene. Waits poll frames with a generous timeout
// and assert behaviour, never speed.
#include "live/sandbox.hpp"
#include "support/base64.hpp"
#include "support/faults.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using namespace kiln::test;

namespace {

// composite.frag with its final colour forced to `rgb`.
std::string forcedComposite(const std::string& original, const char* rgb) {
    std::string text = original;
    const size_t end = text.rfind('}');
    return text.substr(0, end) + "    o_color = vec4(" + rgb + ", 1.0);\n}\n";
}

}  // namespace

TEST_CASE("a shader edited in place, then by rename, is replaced", "[live][gl]") {
    Sandbox box("shader-edit");
    const fs::path frag = box.root / "shaders/composite/composite.frag";
    const std::string original = slurp(frag);
    writeInPlace(frag, forcedComposite(original, "1.0, 0.0, 1.0"));
    CHECK(box.waitFor([&] { return near(box.centre(), {1, 0, 1}); }));
    writeByRename(frag, forcedComposite(original, "0.0, 1.0, 0.0"));
    CHECK(box.waitFor([&] { return near(box.centre(), {0, 1, 0}); }));
    CHECK(box.app.live().shaderReloads == 2);
}

TEST_CASE("a broken include keeps the last good program and names the file and line", "[live][gl]") {
    Sandbox box("broken-include");
    const glm::vec4 before = box.centre();
    const fs::path light = box.root / "shaders/common/light.glsl";
    const std::string original = slurp(light);
    // Line 3 of light.glsl becomes a syntax error.
    std::string broken = original;
    size_t second = broken.find('\n', broken.find('\n') + 1);
    broken.insert(second + 1, "float broken = ;\n");
    writeInPlace(light, broken);
    CHECK(box.waitFor([&] { return box.errorMentions("shaders/common/light.glsl:3:"); }));
    box.app.camera().yaw += 0.0f;
    CHECK(near(box.centre(), glm::vec3(before)));  // the old program still renders
    writeInPlace(light, original);
    CHECK(box.waitFor([&] { return box.app.runtime().activeErrors().empty(); }));
}

TEST_CASE("a pipeline edit changes the plan and keeps unchanged passes' textures", "[live][gl]") {
    Sandbox box("pipeline-edit");
    const fs::path file = box.root / "pipelines/default.json";
    const GLuint albedo = box.app.runtime().findTexture("gbuffer", "albedo")->id;
    std::string text = slurp(file);
    const std::string from = R"({ "id": "shadow", "module": "shadow")";
    REQUIRE(text.find(from) != std::string::npos);
    text.replace(text.find(from), from.size(), R"({ "id": "shadow", "module": "shadow", "enabled": false)");
    writeByRename(file, text);
    auto shadowState = [&] {
        const graph::Plan* plan = box.app.runtime().plan();
        return plan->passes[size_t(plan->find("shadow"))].state;
    };
    CHECK(box.waitFor([&] { return shadowState() == graph::PassState::Disabled; }));
    CHECK(box.app.runtime().findTexture("gbuffer", "albedo")->id == albedo);
    // An invalid file: the running plan stays, the error names the place.
    writeInPlace(file, R"({"output": "composite.color", "passes": [{"id": "gbuffer", "module": "gbufer"}]})");
    CHECK(box.waitFor([&] { return box.errorMentions("passes[0].module"); }));
    CHECK(shadowState() == graph::PassState::Disabled);
    CHECK(box.app.runtime().findTexture("gbuffer", "albedo")->id == albedo);
}

TEST_CASE("a pipeline that extends another reloads when either is saved, and a broken base names itself", "[live][gl]") {
    Sandbox box("extends-edit", "mine.json",
                R"({"extends": "default.json", "passes": [{"id": "composite", "params": {"exposure": 2.0}}]})");
    auto state = [&](const char* id) {
        const graph::Plan* plan = box.app.runtime().plan();
        return plan->passes[size_t(plan->find(id))].state;
    };
    auto exposure = [&] {
        const graph::Plan* plan = box.app.runtime().plan();
        return std::get<float>(*plan->passes[size_t(plan->find("composite"))].params.find("exposure"));
    };
    REQUIRE(box.app.runtime().pipelineChain().size() == 2);
    CHECK(exposure() == 2.0f);
    // The base changes: the pipeline follows, the child's value kept.
    const fs::path base = box.root / "pipelines/default.json";
    std::string text = slurp(base);
    const std::string from = R"({ "id": "shadow", "module": "shadow")";
    REQUIRE(text.find(from) != std::string::npos);
    text.replace(text.find(from), from.size(), R"({ "id": "shadow", "module": "shadow", "enabled": false)");
    writeByRename(base, text);
    CHECK(box.waitFor([&] { return state("shadow") == graph::PassState::Disabled; }));
    CHECK(exposure() == 2.0f);
    // A broken base: named, the running pipeline kept.
    writeInPlace(base, "{ broken");
    CHECK(box.waitFor([&] { return box.errorMentions("pipelines/default.json:1:3"); }));
    CHECK(state("shadow") == graph::PassState::Disabled);
    // The child changes.
    writeByRename(box.root / "pipelines/mine.json", R"({"extends": "default.json", "passes": []})");
    writeByRename(base, slurp(fs::path(KILN_SOURCE_DIR) / "pipelines/default.json"));
    CHECK(box.waitFor([&] { return state("shadow") != graph::PassState::Disabled && exposure() == 1.0f; }));
}

TEST_CASE("a rebuilt module is swapped in with its parameters kept, unsaved edits included, a broken one is refused", "[live][gl]") {
    const std::string pipeline = R"({"output": "tint.color",
        "passes": [{"id": "tint", "module": "live_tint", "params": {"level": 0.25}}]})";
    const fs::path v1 = fs::path(LIVE_MODULE_BUILDS) / "tint_v1.so", v2 = fs::path(LIVE_MODULE_BUILDS) / "tint_v2.so";
    Sandbox box("module-swap", "tint.json", pipeline,
                [&](const fs::path& root) { fs::copy_file(v1, root / "modules/libpass_live_tint.so"); });
    CHECK(box.waitFor([&] { return near(box.centre(), {1.0f, 0.25f, 0.0f}); }));
    // An edit in the debug view, not saved to the file: the rebuild keeps it.
    std::string error;
    REQUIRE(box.app.runtime().setParam("tint", "level", 0.6f, error));
    CHECK(box.waitFor([&] { return near(box.centre(), {1.0f, 0.6f, 0.0f}); }));

    const fs::path installed = box.root / "modules/libpass_live_tint.so";
    writeByRename(installed, slurp(v2));
    CHECK(box.waitFor([&] { return near(box.centre(), {0.0f, 0.6f, 1.0f}); }));  // new code, the edited level
    CHECK(box.app.live().moduleReloads >= 1);

    writeByRename(installed, "this is not a shared library");
    CHECK(box.waitFor([&] { return box.errorMentions("libpass_live_tint.so"); }));
    box.app.camera().yaw += 0.1f;
    CHECK(near(box.centre(), {0.0f, 0.6f, 1.0f}));  // the previous module keeps running
}

TEST_CASE("a module written in two halves or torn is retried, not reported broken, and one left truncated is", "[live][gl]") {
    const std::string pipeline = R"({"output": "tint.color",
        "passes": [{"id": "tint", "module": "live_tint", "params": {"level": 0.25}}]})";
    const fs::path v1 = fs::path(LIVE_MODULE_BUILDS) / "tint_v1.so", v2 = fs::path(LIVE_MODULE_BUILDS) / "tint_v2.so";
    Sandbox box("module-midwrite", "tint.json", pipeline,
                [&](const fs::path& root) { fs::copy_file(v1, root / "modules/libpass_live_tint.so"); });
    REQUIRE(box.waitFor([&] { return near(box.centre(), {1.0f, 0.25f, 0.0f}); }));
    const fs::path installed = box.root / "modules/libpass_live_tint.so";
    const std::string full = slurp(v2);
    const int failures = box.app.live().failures;

    // The first half (what an interrupted build or a chunked copy leaves for a moment).
    writeInPlace(installed, full.substr(0, full.size() / 2));
    REQUIRE(box.waitFor([&] { return box.app.live().pendingModules() == 1; }));
    CHECK(box.errorMentions("retrying"));
    CHECK(box.app.live().failures == failures);        // not reported as broken
    CHECK(near(box.centre(), {1.0f, 0.25f, 0.0f}));    // the old module keeps running
    // The rest: swapped in, nothing reported.
    writeInPlace(installed, full);
    CHECK(box.waitFor([&] { return near(box.centre(), {0.0f, 0.25f, 1.0f}); }));
    CHECK(box.app.live().failures == failures);
    CHECK(box.app.live().pendingModules() == 0);
    CHECK_FALSE(box.errorMentions("libpass_live_tint.so"));

    // Torn: the full size and the right headers, a body of zeros (what a linker leaves
    // mid-write). Waited for like a short file, never mapped; then the real bytes.
    writeInPlace(installed, tornLibrary(full));
    REQUIRE(box.waitFor([&] { return box.app.live().pendingModules() == 1; }));
    CHECK(box.app.live().failures == failures);
    CHECK(near(box.centre(), {0.0f, 0.25f, 1.0f}));
    writeInPlace(installed, slurp(v1));
    CHECK(box.waitFor([&] { return near(box.centre(), {1.0f, 0.25f, 0.0f}); }));
    CHECK(box.app.live().pendingModules() == 0);
    writeInPlace(installed, full);
    CHECK(box.waitFor([&] { return near(box.centre(), {0.0f, 0.25f, 1.0f}); }));

    // Left truncated: after the retry window it is a named error, once.
    writeInPlace(installed, full.substr(0, 4096));
    CHECK(box.waitFor([&] { return box.errorMentions("still invalid"); }));
    CHECK(box.errorMentions("libpass_live_tint.so"));
    CHECK(box.app.live().failures == failures + 1);
    CHECK(box.app.live().pendingModules() == 0);
    box.app.camera().yaw += 0.1f;
    CHECK(near(box.centre(), {0.0f, 0.25f, 1.0f}));  // the previous module keeps running
}

TEST_CASE("a scene with a number beyond double range keeps the running world", "[live][gl]") {
    Sandbox box("scene-overflow");
    const fs::path scene = box.root / "scenes/cornell.json";
    REQUIRE(box.app.scene().sim().tumblers().size() == 5);
    writeByRename(scene, R"({"tumblers": [{"position": [0.0, 0.0]}], "physics": {"dt": 1e999}})");
    CHECK(box.waitFor([&] { return box.errorMentions("physics.dt"); }));
    CHECK(box.errorMentions("number overflow"));
    CHECK(box.app.scene().sim().tumblers().size() == 5);
    writeByRename(scene, "{\"tumblers\": [], \"note\": " + std::string(100000, '[') + std::string(100000, ']') + "}");
    CHECK(box.waitFor([&] { return box.errorMentions("nested deeper than 32 levels"); }));
    CHECK(box.app.scene().sim().tumblers().size() == 5);
}

TEST_CASE("a scene edit resets the world, an invalid scene keeps it", "[live][gl]") {
    Sandbox box("scene-edit");
    const fs::path scene = box.root / "scenes/cornell.json";
    REQUIRE(box.app.scene().sim().tumblers().size() == 5);
    writeByRename(scene, R"({"tumblers": [{"position": [0.0, 0.0]}]})");
    CHECK(box.waitFor([&] { return box.app.scene().sim().tumblers().size() == 1; }));
    writeInPlace(scene, R"({"tumblers": [{"position": [0.0, 0.0], "colour": [1, 0, 0]}]})");
    CHECK(box.waitFor([&] { return box.errorMentions("tumblers[0].colour: unknown key"); }));
    CHECK(box.app.scene().sim().tumblers().size() == 1);
}

namespace {
// The x of the emissive centroid of gbuffer.emissive (texels): where the lamp dome is.
float emissiveCentroidX(app::App& app) {
    const TextureRef* t = app.runtime().findTexture("gbuffer", "emissive");
    FloatImage img = readTexture(t->id, t->target, t->format, t->width, t->height);
    double sum = 0, weighted = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.at(x, y);
            sum += p[0] + p[1] + p[2];
            weighted += x * double(p[0] + p[1] + p[2]);
        }
    return sum > 0 ? float(weighted / sum) : -1.0f;
}
// The mean albedo of the G-buffer texels whose normal points up (the floor).
glm::vec3 floorAlbedo(app::App& app) {
    const TextureRef* a = app.runtime().findTexture("gbuffer", "albedo");
    const TextureRef* n = app.runtime().findTexture("gbuffer", "normal");
    FloatImage albedo = readTexture(a->id, a->target, a->format, a->width, a->height);
    FloatImage normal = readTexture(n->id, n->target, n->format, n->width, n->height);
    glm::vec3 sum(0.0f);
    int count = 0;
    for (int y = 0; y < albedo.height; ++y)
        for (int x = 0; x < albedo.width; ++x)
            if (normal.at(x, y)[1] > 0.99f) sum += glm::vec3(albedo.at(x, y)[0], albedo.at(x, y)[1], albedo.at(x, y)[2]), ++count;
    return count ? sum / float(count) : glm::vec3(-1.0f);
}
std::string sceneWithLampAt(float x, const char* woodRgb) {
    return std::string(R"({"tumblers": [{"position": [0.0, 0.3]}], "marbles": [], "fireballs": [],
        "box": {"floor_wood": {"light": )") + woodRgb + R"(, "dark": )" + woodRgb + R"(, "ring_frequency": 14}},
        "lamp": {"center": [)" + std::to_string(x) + R"(, 1.1, 0.0], "radius": 0.3}})";
}
}  // namespace

TEST_CASE("a scene edit re-renders what the file says: the lamp dome moves, the floor takes its wood", "[live][gl]") {
    Sandbox box("scene-look");
    const fs::path scene = box.root / "scenes/cornell.json";
    writeByRename(scene, sceneWithLampAt(-0.5f, "[0.0, 1.0, 0.0]"));
    REQUIRE(box.waitFor([&] { return box.app.scene().sim().tumblers().size() == 1; }));
    box.app.frame();
    const float left = emissiveCentroidX(box.app);
    // Light and dark wood both pure green: every floor texel is (0, 1, 0) exactly.
    const glm::vec3 green = floorAlbedo(box.app);
    INFO("floor albedo " << green.x << " " << green.y << " " << green.z);
    CHECK(glm::length(green - glm::vec3(0.0f, 1.0f, 0.0f)) < 1e-3f);

    writeByRename(scene, sceneWithLampAt(0.5f, "[1.0, 0.0, 0.0]"));
    REQUIRE(box.waitFor([&] { return glm::length(floorAlbedo(box.app) - glm::vec3(1, 0, 0)) < 1e-3f; }));
    const float right = emissiveCentroidX(box.app);
    INFO("dome centroid x: " << left << " px, then " << right << " px (of 32)");
    // The dome moved 1.0 m to the right: at 32 px across a 2 m box seen from the front,
    // its centroid moves ≈ 10 px; 5 px is a margin a stale mesh (0 px) cannot reach.
    CHECK(left > 0.0f);
    CHECK(right - left > 5.0f);
}

TEST_CASE("ten saves in a burst cause one reload", "[live][gl]") {
    Sandbox box("burst");
    const fs::path frag = box.root / "shaders/composite/composite.frag";
    const std::string original = slurp(frag);
    for (int i = 0; i < 10; ++i) {
        const std::string rgb = "0.0, " + std::to_string(i / 10.0) + ", 1.0";
        writeInPlace(frag, forcedComposite(original, rgb.c_str()));
    }
    // No frame runs during the burst, and the watcher stamps an event when a frame polls
    // it: the ten saves are one pending change however slowly the machine wrote them.
    CHECK(box.waitFor([&] { return near(box.centre(), {0.0f, 0.9f, 1.0f}); }));
    CHECK(box.app.live().shaderReloads == 1);
    // A straggling event of the burst would be read before a later save's (inotify
    // keeps order): one more save, waited for by its colour, makes exactly two reloads.
    writeInPlace(frag, forcedComposite(original, "1.0, 0.0, 0.0"));
    CHECK(box.waitFor([&] { return near(box.centre(), {1.0f, 0.0f, 0.0f}); }));
    CHECK(box.app.live().shaderReloads == 2);
}

TEST_CASE("shaders/ deleted and checked out again is watched again: its changed files reload", "[live][gl]") {
    // What `git checkout` of another branch does to a watched root: the directory goes,
    // and a new one with other contents takes its place. The watcher had no parent
    // watch to see it come back; it now looks for a missing root every 250 ms, and
    // compares each file with what it held before.
    Sandbox box("rewatch-root");
    const fs::path shaders = box.root / "shaders", away = box.root / "shaders-away";
    const fs::path composite = shaders / "composite/composite.frag";
    const std::string original = slurp(composite);
    fs::rename(shaders, away);
    for (int i = 0; i < 5; ++i) box.app.frame();  // the watcher sees it go
    fs::create_directories(shaders);
    fs::copy(away, shaders, fs::copy_options::recursive);
    writeInPlace(composite, forcedComposite(original, "vec3(0.0, 1.0, 0.0)"));
    CHECK(box.waitFor([&] { return near(box.centre(), {0, 1, 0}); }));
    // Watched for good: the next save lands too.
    writeByRename(composite, forcedComposite(original, "vec3(1.0, 0.0, 0.0)"));
    CHECK(box.waitFor([&] { return near(box.centre(), {1, 0, 0}); }));
}

namespace {
// A square x, y ∈ [-0.6, 0.6] at z = 0 facing the camera, of base colour `rgb`, as glTF
// with its buffer in a data URI; `index` replaces its last index (4 is beyond its vertices).
std::string squareGltf(const char* rgb, int lastIndex = 3) {
    // Positions (-.6,-.6,0) (.6,-.6,0) (.6,.6,0) (-.6,.6,0) as float32, then six uint8 indices.
    const float p[12] = {-0.6f, -0.6f, 0, 0.6f, -0.6f, 0, 0.6f, 0.6f, 0, -0.6f, 0.6f, 0};
    std::vector<uint8_t> bin(reinterpret_cast<const uint8_t*>(p), reinterpret_cast<const uint8_t*>(p) + 48);
    for (int i : {0, 1, 2, 0, 2, lastIndex}) bin.push_back(uint8_t(i));
    const std::string b64 = base64(bin);
    return std::string(R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
      "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [)") + rgb + R"(, 1]}}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                    {"bufferView": 0, "byteOffset": 48, "componentType": 5121, "count": 6, "type": "SCALAR"}],
      "bufferViews": [{"buffer": 0, "byteLength": 54}],
      "buffers": [{"byteLength": 54, "uri": "data:application/octet-stream;base64,)" + b64 + R"("}]})";
}
}  // namespace

TEST_CASE("a glTF model saved live re-renders, a broken save keeps the last good model", "[live][gl]") {
    Sandbox box("gltf-edit");
    const fs::path scene = box.root / "scenes/cornell.json";
    const fs::path model = box.root / "scenes/square.gltf";
    writeInPlace(model, squareGltf("1, 0, 0"));
    writeByRename(scene, R"({"tumblers": [], "models": [{"file": "square.gltf"}]})");
    auto centreAlbedo = [&] { return box.centreOf("gbuffer.albedo"); };
    REQUIRE(box.waitFor([&] { return std::abs(centreAlbedo().r - 1.0f) < 0.01f && centreAlbedo().g < 0.01f; }));
    // Saved in place (the world keeps its state: no reset), then by rename.
    writeInPlace(model, squareGltf("0, 1, 0"));
    CHECK(box.waitFor([&] { return centreAlbedo().g > 0.99f && centreAlbedo().r < 0.01f; }));
    writeByRename(model, squareGltf("0, 0, 1"));
    CHECK(box.waitFor([&] { return centreAlbedo().b > 0.99f && centreAlbedo().g < 0.01f; }));
    // An index beyond the vertices: named at its JSON path, the blue square stays.
    writeByRename(model, squareGltf("1, 1, 0", 4));
    CHECK(box.waitFor([&] { return box.errorMentions("square.gltf: meshes[0].primitives[0].indices: index 4"); }));
    for (int i = 0; i < 3; ++i) box.app.frame();
    CHECK(centreAlbedo().b > 0.99f);
    // Fixed again: the error clears and the new colour shows.
    writeByRename(model, squareGltf("1, 1, 1"));
    CHECK(box.waitFor([&] { return centreAlbedo().r > 0.99f && centreAlbedo().g > 0.99f; }));
    CHECK_FALSE(box.errorMentions("square.gltf"));
}
