// One headless GL 4.5 context per test process (EGL surfaceless), made current on
// first use and kept for the process's lifetime.
#pragma once

#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "app/context.hpp"

namespace kiln::test {

inline bool ensureHeadlessContext() {
    static std::string error;
    static std::unique_ptr<app::HeadlessContext> context = app::HeadlessContext::create(true, error);
    if (!context) FAIL("no headless GL context: " << error);
    return bool(context);
}

}  // namespace kiln::test
