// One headless GL 4.5 context per test process (EGL surfaceless), made current on
// first use and kept for the process's lifetime.
#pragma once

#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "app/cli.hpp"
#include "app/context.hpp"

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

}  // namespace kiln::test
