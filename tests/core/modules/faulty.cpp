// A module with a bug in whichever entry point the environment names, for the tests of
// the guard: KILN_TEST_FAULT="<kind>@<entry>", kind one of segv, abort, throw, loop,
// stack (unbounded recursion), fpe; entry one of static (its static initialisers), entry
// (kiln_pass_module), create, declare, execute, destroy. Built twice: the buggy build
// fills its output with (1, level, 1), the fixed one (FAULTY_FIXED) ignores the
// environment and fills it with (level, 1, 0).
#include <kiln/pass.hpp>

#include <sys/mman.h>

#include <csignal>
#include <cstdlib>
#include <cstring>

namespace {

bool faultHere(const char* entry) {
#if FAULTY_FIXED
    (void)entry;
    return false;
#else
    const char* spec = std::getenv("KILN_TEST_FAULT");
    const char* at = spec ? std::strchr(spec, '@') : nullptr;
    return at && std::strcmp(at + 1, entry) == 0;
#endif
}

volatile int gSink = 0;

int recurse(int depth) {
    if (depth > (1 << 30)) return 0;  // never: the stack ends long before
    volatile char frame[512];
    frame[depth % 512] = char(depth);
    return recurse(depth + 1) + frame[0];  // not a tail call
}

void fault(const char* entry) {
    if (!faultHere(entry)) return;
    const char* kind = std::getenv("KILN_TEST_FAULT");
    auto is = [&](const char* k) { return std::strncmp(kind, k, std::strlen(k)) == 0 && kind[std::strlen(k)] == '@'; };
    if (is("segv")) {
        // A page mapped with no access, not address 0: a write to page zero does not
        // fault on every machine (it did not on the one this was written on).
        auto* volatile page = static_cast<int*>(mmap(nullptr, 4096, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
        *page = 1;
    } else if (is("abort")) {
        std::abort();
    } else if (is("throw")) {
        throw 42;
    } else if (is("loop")) {
        for (;;) gSink = gSink + 1;
    } else if (is("stack")) {
        gSink = recurse(0);
    } else if (is("fpe")) {
        std::raise(SIGFPE);  // a division by zero gave 0 and no signal on one test machine
    }
}

struct AtLoad {
    AtLoad() { fault("static"); }
} gAtLoad;

class Faulty final : public kiln::Pass {
public:
    Faulty() { fault("create"); }
    ~Faulty() override { fault("destroy"); }
    kiln::PassDeclaration declare() const override {
        fault("declare");
        kiln::PassDeclaration d;
        d.output({.name = "color", .format = kiln::Format::RGBA8})
            .param(kiln::floatParam("level", 0.5f, 0.0, 1.0, "a channel of the fill colour"));
        return d;
    }
    void execute(kiln::PassContext& ctx) override {
        if (!ctx.framebuffer({"color"})) return;
        const float level = ctx.getFloat("level");
        const float c[4] = {FAULTY_FIXED ? level : 1.0f, FAULTY_FIXED ? 1.0f : level, FAULTY_FIXED ? 0.0f : 1.0f, 1.0f};
        glClearBufferfv(GL_COLOR, 0, c);
        // State a crash leaves behind, which the host must clear.
        glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 1, -1, "faulty");
        glEnable(GL_SCISSOR_TEST);
        glScissor(0, 0, 1, 1);
        fault("execute");
        glDisable(GL_SCISSOR_TEST);
        glPopDebugGroup();
    }
};

kiln::Pass* create() { return new Faulty(); }
void destroy(kiln::Pass* p) { delete p; }
const KilnPassModule kModule{kiln::kPassAbiVersion, "test_faulty", &create, &destroy};

}  // namespace

extern "C" __attribute__((visibility("default"))) const KilnPassModule* kiln_pass_module() {
    fault("entry");
    return &kModule;
}
