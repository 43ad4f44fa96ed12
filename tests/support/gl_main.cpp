// main() of the GL test executables: Catch2's session, then a check that no test
// caused a GL error. The debug callback (installed on every test context) counts
// GL_DEBUG_TYPE_ERROR messages; Kiln must cause none, so any makes the run fail even
// when every assertion passed. ctest runs one test case per process, so a failure
// names the test that caused it.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdio>

#include "kiln/gl.hpp"

int main(int argc, char** argv) {
    const int failed = Catch::Session().run(argc, argv);
    if (const uint64_t errors = kiln::gl::debugErrorCount()) {
        std::fprintf(stderr, "GL errors: %llu reported by the debug callback (logged above as \"GL [id]\")\n",
                     static_cast<unsigned long long>(errors));
        return failed ? failed : 1;
    }
    return failed;
}
