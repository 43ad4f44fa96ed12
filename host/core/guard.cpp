#include "kiln/guard.hpp"

#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <ucontext.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cxxabi.h>
#include <exception>
#include <typeinfo>
#include <mutex>
#include <thread>
#include <vector>

namespace kiln::guard {

namespace {

using Clock = std::chrono::steady_clock;

// Sent by the watchdog to the thread whose call overran; real-time, so it queues a
// value (the call's id) and never collides with a signal someone else sends.
int watchdogSignal() { return SIGRTMIN + 4; }

// One guarded call on one thread's stack; calls nest (a guarded load creates a pass).
struct Frame {
    sigjmp_buf jump;
    Frame* outer = nullptr;
    uint64_t id = 0;
    std::chrono::milliseconds limit{0};  // of the watchdog; 0: not watched
    CodeRange interruptible;             // where the watchdog may stop it
    volatile int signal = 0;
    volatile int code = 0;
    void* volatile address = nullptr;
};

// Initial-exec: the handler reads it, and must not be the first to touch a lazily
// allocated TLS block.
__attribute__((tls_model("initial-exec"))) thread_local Frame* tCurrent = nullptr;
thread_local bool tHasAltStack = false;

struct sigaction gPrevious[NSIG];
std::once_flag gInstallOnce;

// Where the thread was when the signal came; 0 where the platform is not known here
// (then anywhere counts as the module's code).
uintptr_t interruptedAt(void* context) {
    const auto* uc = static_cast<const ucontext_t*>(context);
#if defined(__x86_64__)
    return uintptr_t(uc->uc_mcontext.gregs[REG_RIP]);
#elif defined(__aarch64__)
    return uintptr_t(uc->uc_mcontext.pc);
#else
    (void)uc;
    return 0;
#endif
}

void onSignal(int sig, siginfo_t* info, void* context) {
    if (sig == watchdogSignal()) {
        // Stale (the call returned meanwhile) unless a frame on this thread has the id;
        // ignored (the watchdog asks again) while the thread is outside the module's code.
        const auto id = reinterpret_cast<uintptr_t>(info->si_value.sival_ptr);
        for (Frame* f = tCurrent; f; f = f->outer)
            if (info->si_code == SI_QUEUE && f->id == id) {
                const uintptr_t pc = interruptedAt(context);
                if (pc && !f->interruptible.contains(pc)) return;
                f->signal = sig;
                siglongjmp(f->jump, 1);
            }
        return;
    }
    if (Frame* f = tCurrent) {
        f->signal = sig;
        f->code = info->si_code;
        f->address = info->si_addr;
        siglongjmp(f->jump, 1);
    }
    // Not ours: whoever had the signal before us (a sanitizer), or the default action.
    const struct sigaction& previous = gPrevious[sig];
    if (previous.sa_flags & SA_SIGINFO) {
        if (previous.sa_sigaction) previous.sa_sigaction(sig, info, context);
        return;
    }
    if (previous.sa_handler == SIG_IGN) return;
    if (previous.sa_handler != SIG_DFL) {
        previous.sa_handler(sig);
        return;
    }
    // The default: a fault re-executes the faulting instruction and ends the process as
    // if no handler were there; a sent signal (abort(), kill) is sent again.
    ::signal(sig, SIG_DFL);
    if (info->si_code <= 0) raise(sig);
}

// The first install keeps what was there (the default, or a sanitizer's handler) to
// hand unguarded signals to. Someone may install a handler over ours later (a test
// framework does, per test case): each guarded call checks one signal, one system
// call, and takes them back, without chaining to the newcomer.
void install(bool first) {
    struct sigaction action {};
    action.sa_sigaction = onSignal;
    action.sa_flags = SA_SIGINFO | SA_ONSTACK | SA_RESTART;  // a watchdog signal it ignores restarts the wait it broke
    sigemptyset(&action.sa_mask);
    for (int sig : kFatalSignals) sigaction(sig, &action, first ? &gPrevious[sig] : nullptr);
    sigaction(watchdogSignal(), &action, first ? &gPrevious[watchdogSignal()] : nullptr);
}

void ensureInstalled() {
    std::call_once(gInstallOnce, [] { install(true); });
    struct sigaction current {};
    if (sigaction(SIGSEGV, nullptr, &current) == 0 &&
        (!(current.sa_flags & SA_SIGINFO) || current.sa_sigaction != onSignal))
        install(false);
}

// The handler needs a stack of its own to report a stack overflow. A thread that has
// one already (a sanitizer's) keeps it.
void ensureAltStack() {
    if (tHasAltStack) return;
    tHasAltStack = true;
    stack_t current{};
    if (sigaltstack(nullptr, &current) == 0 && !(current.ss_flags & SS_DISABLE)) return;
    constexpr size_t kSize = 256 * 1024;
    stack_t stack{};
    stack.ss_sp = std::malloc(kSize);  // lives as long as the thread may take a signal
    stack.ss_size = kSize;
    if (stack.ss_sp) sigaltstack(&stack, nullptr);
}

// The watchdog: one thread for the process, started by the first watched call.
struct Deadline {
    pthread_t thread;
    uint64_t id;
    Clock::time_point deadline;
};
std::atomic<int64_t> gLimitMs{10000};
std::atomic<uint64_t> gNextId{1};
std::mutex gWatchMutex;
std::vector<Deadline> gDeadlines;
std::once_flag gWatchdogOnce;

void watchdogLoop() {
    for (;;) {
        const int64_t limit = gLimitMs.load();
        std::this_thread::sleep_for(std::chrono::milliseconds(limit > 0 ? std::clamp<int64_t>(limit / 10, 5, 200) : 200));
        std::lock_guard lock(gWatchMutex);
        const auto now = Clock::now();
        for (Deadline& w : gDeadlines) {
            if (now < w.deadline) continue;
            union sigval value;
            value.sival_ptr = reinterpret_cast<void*>(static_cast<uintptr_t>(w.id));
            pthread_sigqueue(w.thread, watchdogSignal(), value);
            w.deadline = now + std::chrono::seconds(1);  // again, should that one be lost
        }
    }
}

void startWatching(uint64_t id, std::chrono::milliseconds limit) {
    std::call_once(gWatchdogOnce, [] { std::thread(watchdogLoop).detach(); });
    std::lock_guard lock(gWatchMutex);
    gDeadlines.push_back({pthread_self(), id, Clock::now() + limit});
}

void stopWatching(uint64_t id) {
    std::lock_guard lock(gWatchMutex);
    std::erase_if(gDeadlines, [id](const Deadline& w) { return w.id == id; });
}

std::string demangled(const char* name) {
    int status = 0;
    char* readable = abi::__cxa_demangle(name, nullptr, nullptr, &status);
    std::string text = status == 0 && readable ? readable : name;
    std::free(readable);
    return text;
}

std::string hex(const void* p) {
    char text[32];
    std::snprintf(text, sizeof text, "%p", p);
    return text;
}

std::string describe(const Frame& f) {
    const int sig = f.signal;
    if (sig == watchdogSignal()) return overrun(f.limit);
    const std::string name = signalName(sig);
    switch (sig) {
    case SIGSEGV: return name + " (invalid memory access at " + hex(f.address) + ")";
    case SIGBUS: return name + " (bus error at " + hex(f.address) + ")";
    case SIGFPE:
        return name + (f.code == FPE_INTDIV ? " (integer division by zero)" : " (arithmetic fault)");
    case SIGILL: return name + " (illegal instruction at " + hex(f.address) + ")";
    case SIGABRT: return name + " (abort(): a failed assertion or std::terminate?)";
    default: return name;
    }
}

}  // namespace

void setWatchdogLimit(std::chrono::milliseconds limit) { gLimitMs = limit.count(); }
std::chrono::milliseconds watchdogLimit() { return std::chrono::milliseconds(gLimitMs.load()); }

std::string overrun(std::chrono::milliseconds limit) {
    char text[96];
    std::snprintf(text, sizeof text, "no return after %.1f s (an endless loop?)", double(limit.count()) / 1000.0);
    return text;
}

std::string signalName(int signal) {
    switch (signal) {
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGABRT: return "SIGABRT";
    case SIGKILL: return "SIGKILL";
    case SIGTERM: return "SIGTERM";
    default: return "signal " + std::to_string(signal);
    }
}

namespace detail {

std::optional<std::string> call(void (*thunk)(void*), void* fn, const Watch& watch) {
    ensureInstalled();
    ensureAltStack();
    Frame frame;
    frame.outer = tCurrent;
    frame.id = gNextId++;
    frame.limit = watch.on ? watchdogLimit() : std::chrono::milliseconds(0);
    frame.interruptible = watch.code;
    if (frame.limit.count() > 0) startWatching(frame.id, frame.limit);

    // Written only before the jump can happen or after it landed: safe across it.
    std::optional<std::string> fault;
    if (sigsetjmp(frame.jump, 1) == 0) {
        tCurrent = &frame;
        try {
            thunk(fn);
        } catch (const std::exception& e) {
            fault = "exception " + demangled(typeid(e).name()) + "(\"" + e.what() + "\")";
        } catch (...) {
            const std::type_info* type = abi::__cxa_current_exception_type();
            fault = "exception of type " + (type ? demangled(type->name()) : std::string("unknown"));
        }
    } else {
        fault = describe(frame);
    }
    tCurrent = frame.outer;
    if (frame.limit.count() > 0) stopWatching(frame.id);
    return fault;
}

}  // namespace detail

}  // namespace kiln::guard
