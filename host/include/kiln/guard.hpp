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
// Control comes back with siglongjmp, which does not unwind: the destructors of
// whatever fn had on its stack never run, locks it held stay held, memory it was
// writing stays half-written. What it promises is that the host gets control back and
// names the culprit; what it cannot promise is that a module which corrupted the heap
// or was interrupted inside a driver call leaves the process sound. The caller treats
// everything the faulty code owns as lost (see run/runtime.cpp).
//
// Outside a guarded call the signals keep whatever disposition they had before (the
// default, or a sanitizer's handler): a bug in the host itself still crashes, loudly.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <utility>

namespace kiln::guard {

// The bound on one guarded call, for every thread; zero turns the watchdog off.
void setWatchdogLimit(std::chrono::milliseconds limit);
std::chrono::milliseconds watchdogLimit();

// The name of a signal: "SIGSEGV", "SIGABRT", ...
std::string signalName(int signal);
// What a call that overran `limit` is reported as.
std::string overrun(std::chrono::milliseconds limit);

namespace detail {
std::optional<std::string> call(void (*thunk)(void*), void* fn, bool watched);
}

// Runs fn() under the guard; nullopt when it returned normally. `watched` false exempts
// a call from the watchdog (one that may legitimately take long, such as a dlopen of a
// large module on a busy machine).
template <class F>
std::optional<std::string> guarded(F&& fn, bool watched = true) {
    return detail::call([](void* f) { (*static_cast<std::remove_reference_t<F>*>(f))(); },
                        const_cast<void*>(static_cast<const void*>(&fn)), watched);
}

}  // namespace kiln::guard
