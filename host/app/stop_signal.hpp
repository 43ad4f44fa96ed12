// app/stop_signal.hpp — SIGINT and SIGTERM as a request to stop at the next frame
// boundary, so the window saves its panel layout and a --watch run says it stopped,
// rather than dying mid-frame. The run then exits as a shell reports a process that
// signal ended: 128 + N (130 for Ctrl+C).
#pragma once

#include <csignal>

namespace kiln::app {

inline volatile std::sig_atomic_t stopSignalled = 0;  // the signal's number, once one came

inline void catchStopSignals() {
    struct sigaction stop {};
    stop.sa_handler = [](int signal) { stopSignalled = signal; };
    sigaction(SIGINT, &stop, nullptr);
    sigaction(SIGTERM, &stop, nullptr);
}

inline int exitStatusAfterStop() { return 128 + int(stopSignalled); }

}  // namespace kiln::app
