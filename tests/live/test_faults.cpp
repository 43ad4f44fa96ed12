// A pass module with a bug in execute() or destroy(), in a running Kiln: the fault is
// named once, the frame completes and the next ones render, the module is rolled back
// to the build it replaced (with the running parameters) or its passes wait for a new
// build, and a fixed build is picked up live. (Faults at load time, and in create() and
// declare(), are tests/core/test_guard.cpp's.) The module is tests/core/modules/faulty.cpp
// (its bug chosen by KILN_TEST_FAULT); `tint` after it runs whenever its output changes.
#include <cstdlib>

#include "live/sandbox.hpp"
#include "support/faults.hpp"

namespace fs = std::filesystem;
using namespace kiln;
using namespace kiln::test;

namespace {

const fs::path kBuggy = fs::path(FAULTY_MODULE_DIR) / "libpass_test_faulty.so";
const fs::path kFixed = fs::path(FIXED_FAULTY_MODULE_DIR) / "libpass_test_faulty.so";

const std::string kPipeline = R"({"output": "tint.color",
    "passes": [{"id": "bad", "module": "test_faulty", "params": {"level": 0.25}},
               {"id": "tint", "module": "live_tint", "inputs": {"under": "bad.color"}, "params": {"level": 0.25}}]})";

// Sandbox with `module` installed as libpass_test_faulty.so and the tint v1 build.
Sandbox faultSandbox(const std::string& name, const fs::path& module) {
    return Sandbox(name, "faulty.json", kPipeline, [&](const fs::path& root) {
        fs::copy_file(module, root / "modules/libpass_test_faulty.so");
        fs::copy_file(fs::path(LIVE_MODULE_BUILDS) / "tint_v1.so", root / "modules/libpass_live_tint.so");
    });
}

int countOf(const std::vector<std::string>& lines, const std::string& text) {
    int n = 0;
    for (auto& l : lines) n += l.find(text) != std::string::npos;
    return n;
}

}  // namespace

TEST_CASE("a pass that faults in execute() is named, the frame goes on, and a fixed build is picked up live",
          "[live][gl][guard]") {
    WatchdogLimit limit(std::chrono::milliseconds(1000));
    const std::vector<std::pair<std::string, std::string>> kinds = {
        {"segv", "SIGSEGV"}, {"abort", "SIGABRT"}, {"throw", "exception of type int"}, {"loop", "no return after 1.0 s"},
        {"stack", "SIGSEGV"}, {"fpe", "SIGFPE"}};
    for (auto& [kind, expect] : kinds) {
        INFO(kind);
        FaultSpec spec(kind + "@execute");
        Sandbox box = faultSandbox("fault-execute-" + kind, kBuggy);
        // The first frame faulted: one standing error names the pass, the file, the fault
        // and the entry point, and says there is no build to go back to.
        auto errors = box.app.runtime().activeErrors();
        CHECK(countOf(errors, "pass \"bad\" (libpass_test_faulty.so): " + expect) == 1);
        CHECK(countOf(errors, "in execute(); its passes are off until libpass_test_faulty.so changes") == 1);
        // The frame completed, and the next ones render: tint follows a parameter edit.
        std::string error;
        REQUIRE(box.app.runtime().setParam("tint", "level", 0.75f, error));
        CHECK(box.waitFor([&] { return near(box.centre(), {1.0f, 0.75f, 0.0f}); }));
        // The faulted pass is not called again (no second error).
        CHECK(countOf(box.app.runtime().activeErrors(), "libpass_test_faulty.so") == 1);
        // A fixed build, written as a build would: picked up, the error gone, its output right.
        writeByRename(box.root / "modules/libpass_test_faulty.so", slurp(kFixed));
        CHECK(box.waitFor([&] { return near(box.centreOf("bad.color"), {0.25f, 1.0f, 0.0f}); }));
        CHECK(countOf(box.app.runtime().activeErrors(), "libpass_test_faulty.so") == 0);
    }
}

TEST_CASE("a new build that faults in execute() is rolled back to the previous one, edits kept", "[live][gl][guard]") {
    Sandbox box = faultSandbox("fault-rollback", kFixed);
    CHECK(near(box.centreOf("bad.color"), {0.25f, 1.0f, 0.0f}));
    std::string error;
    REQUIRE(box.app.runtime().setParam("bad", "level", 0.5f, error));  // an unsaved edit
    CHECK(box.waitFor([&] { return near(box.centreOf("bad.color"), {0.5f, 1.0f, 0.0f}); }));

    FaultSpec spec("segv@execute");
    writeByRename(box.root / "modules/libpass_test_faulty.so", slurp(kBuggy));
    CHECK(box.waitFor([&] { return box.errorMentions("rolled back"); }));
    auto errors = box.app.runtime().activeErrors();
    CHECK(countOf(errors, "pass \"bad\" (libpass_test_faulty.so): SIGSEGV") == 1);
    CHECK(countOf(errors, "in execute(); rolled back to the build loaded before it") == 1);
    // The previous build runs again with the edited parameter.
    CHECK(box.waitFor([&] { return near(box.centreOf("bad.color"), {0.5f, 1.0f, 0.0f}); }));

    // A fixed build again: loaded, the error cleared.
    unsetenv("KILN_TEST_FAULT");
    writeByRename(box.root / "modules/libpass_test_faulty.so", slurp(kFixed));
    CHECK(box.waitFor([&] { return !box.errorMentions("libpass_test_faulty.so"); }));
    CHECK(box.waitFor([&] { return near(box.centreOf("bad.color"), {0.5f, 1.0f, 0.0f}); }));
}

TEST_CASE("a new build that faults in destroy() is refused when probed, and the running one kept", "[live][gl][guard]") {
    Sandbox box = faultSandbox("fault-destroy", kFixed);
    CHECK(near(box.centreOf("bad.color"), {0.25f, 1.0f, 0.0f}));
    {
        FaultSpec spec("segv@destroy");
        writeByRename(box.root / "modules/libpass_test_faulty.so", slurp(kBuggy));
        CHECK(box.waitFor([&] { return box.errorMentions("in destroy()"); }));
    }
    CHECK(box.errorMentions("SIGSEGV"));
    CHECK(box.errorMentions("the previous module keeps running"));
    std::string error;
    REQUIRE(box.app.runtime().setParam("bad", "level", 0.5f, error));
    CHECK(box.waitFor([&] { return near(box.centreOf("bad.color"), {0.5f, 1.0f, 0.0f}); }));  // the fixed build runs
    writeByRename(box.root / "modules/libpass_test_faulty.so", slurp(kFixed));
    CHECK(box.waitFor([&] { return !box.errorMentions("libpass_test_faulty.so"); }));
}
