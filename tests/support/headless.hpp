// One headless GL 4.5 context per test process (EGL surfaceless), made current on
// first use and kept for the process's lifetime.
#pragma once

#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "app/app.hpp"
#include "app/cli.hpp"
#include "app/context.hpp"
#include "kiln/image_io.hpp"

namespace kiln::test {

inline bool ensureHeadlessContext() {
    static std::string error;
    static std::unique_ptr<app::HeadlessContext> context = app::HeadlessContext::create(true, error);
    if (!context) FAIL("no headless GL context: " << error);
    return bool(context);
}

// Options for an in-process headless run of the source tree's defaults: size² pixels,
// simulation paused (time frozen), live reloading off.
inline app::Options pausedHeadlessOptions(int size) {
    app::Options o;
    app::applyDefaults(o);
    o.headless = true;
    o.width = o.height = size;
    o.paused = true;
    o.live = false;
    return o;
}

// Pass `pass`'s texture `name` as the app's last frame left it, read back; fails the
// test when the running plan has none.
inline FloatImage readOutput(const app::App& app, const std::string& pass, const std::string& name) {
    const TextureRef* t = app.runtime().findTexture(pass, name);
    REQUIRE(t);
    return readTexture(t->id, t->target, t->format, t->width, t->height);
}

}  // namespace kiln::test
