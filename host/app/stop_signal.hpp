// app/stop_signal.hpp — SIGINT and SIGTERM as a request to stop at the next frame
// boundary, so the window saves its panel layout and a --watch run says it stopped,
// rather than dying mid-frame.
#pragma once

#include <csignal>

namespace kiln::app {

inline volatile std::sig_atomic_t stopSignalled = 0;

inline void catchStopSignals() {
    struct sigaction stop {};
    stop.sa_handler = [](int) { stopSignalled = 1; };
    sigaction(SIGINT, &stop, nullptr);
    sigaction(SIGTERM, &stop, nullptr);
}

}  // namespace kiln::app
