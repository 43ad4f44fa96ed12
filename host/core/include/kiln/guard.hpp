// kiln/guard.hpp — calls into code the host does not trust (a pass module's entry
// points) so that a bug in it becomes an error message instead of the end of Kiln.
//
// guarded(fn) runs fn() and returns what went wrong, if anything:
//   - a fatal signal raised on this thread inside fn (SIGSEGV, SIGBUS, SIGFPE, SIGILL,
//     SIGABRT — abort(), a failed assert, std::terminate): "SIGSEGV (invalid memory
//     access at 0x0)"; the handler runs on an alternate stack, so a stack overflow is
//     caught too;
//   - any exception, std::exception or not: `exception std::runtime_error("what()")`,
//     `exception of type int`;
//   - running past the watchdog's limit: "no return after 10.0 s (an endless loop?)".
//     Given the module's code range, the watchdog interrupts only while that code runs,
//     never inside the driver or the C library (which may hold locks, and where
//     llvmpipe waits out a long compute dispatch): a call past its limit is sampled
//     every second until it is caught in its own code.
// Control comes back with siglongjmp, which does not unwind: the destructors of
// whatever fn had on its stack never run, locks it held stay held, memory it was
// writing stays half-written. What it promises is that the host gets control back and
// names the culprit; what it cannot promise is that a module which corrupted the heap
// or faulted inside a driver call leaves the process sound. The caller treats
// everything the faulty code owns as lost (see run/runtime.cpp).
//
// Outside a guarded call the signals keep whatever disposition they had before (the
// default, or a sanitizer's handler): a bug in the host itself still crashes, loudly.
#pragma once

#include <signal.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

namespace kiln::guard {

// The bound on one guarded call, for every thread; zero turns the watchdog off.
void setWatchdogLimit(std::chrono::milliseconds limit);
std::chrono::milliseconds watchdogLimit();

// The signals the guard turns into errors.
inline constexpr int kFatalSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

// A fault that was an exception unwound the stack (destructors ran, locks released); a
// signal or the watchdog did not, and leaves the faulting library's state suspect.
inline bool unwound(const std::string& fault) { return fault.rfind("exception", 0) == 0; }

// The name of a signal: "SIGSEGV", "SIGABRT", ...
std::string signalName(int signal);
// What a call that overran `limit` is reported as.
std::string overrun(std::chrono::milliseconds limit);

// Addresses of a module's executable code; empty: anywhere.
struct CodeRange {
    uintptr_t begin = 0, end = 0;
    bool contains(uintptr_t pc) const { return begin >= end || (pc >= begin && pc < end); }
};

// What the watchdog may do to a call: nothing (a dlopen, which holds the dynamic
// loader's lock), or interrupt it past the limit while it runs in `code`.
struct Watch {
    bool on = true;
    CodeRange code;
};
inline constexpr Watch kUnwatched{false, {}};

namespace detail {
std::optional<std::string> call(void (*thunk)(void*), void* fn, const Watch& watch);
}

// Runs fn() under the guard; nullopt when it returned normally.
template <class F>
std::optional<std::string> guarded(F&& fn, const Watch& watch = {}) {
    return detail::call([](void* f) { (*static_cast<std::remove_reference_t<F>*>(f))(); },
                        const_cast<void*>(static_cast<const void*>(&fn)), watch);
}

}  // namespace kiln::guard
