// What the tests of bad modules share: the bug a faulty test module is to have
// (tests/core/modules/faulty.cpp reads KILN_TEST_FAULT), the watchdog's limit for one
// test, and a library as a linker leaves it mid-write.
#pragma once

#include <chrono>
#include <cstdlib>
#include <string>

#include "kiln/guard.hpp"

namespace kiln::test {

// KILN_TEST_FAULT="<kind>@<entry>" while it lives, removed after.
struct FaultSpec {
    explicit FaultSpec(const std::string& spec) { setenv("KILN_TEST_FAULT", spec.c_str(), 1); }
    ~FaultSpec() { unsetenv("KILN_TEST_FAULT"); }
    FaultSpec(const FaultSpec&) = delete;
    FaultSpec& operator=(const FaultSpec&) = delete;
};

// The watchdog's limit while it lives, the previous one restored after.
struct WatchdogLimit {
    std::chrono::milliseconds saved = guard::watchdogLimit();
    explicit WatchdogLimit(std::chrono::milliseconds limit) { guard::setWatchdogLimit(limit); }
    ~WatchdogLimit() { guard::setWatchdogLimit(saved); }
    WatchdogLimit(const WatchdogLimit&) = delete;
    WatchdogLimit& operator=(const WatchdogLimit&) = delete;
};

// A library's bytes torn as a linker leaves them mid-write: the full size, the ELF header
// and room for its program headers intact, the rest zeros.
inline std::string tornLibrary(const std::string& library) {
    const size_t headers = 64 + 56 * 16;
    return library.substr(0, headers) + std::string(library.size() - headers, '\0');
}

}  // namespace kiln::test
