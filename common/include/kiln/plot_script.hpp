// kiln/plot_script.hpp — how a benchmark command draws its figures: it writes a CSV, then
// runs scripts/plot.py (matplotlib, Debian's python3-matplotlib) on it. Drawing is left to
// a plotting library, so labels, log axes and legends are matplotlib's; a figure can be
// redrawn from its CSV without measuring again. Header-only: kiln-sim and the GL benches
// both use it.
#pragma once

#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "kiln/data_root.hpp"

extern char** environ;

namespace kiln {

// Runs `plot.py arguments...` and waits for it. On failure returns false and says why in
// `error` (the script's own message went to stderr); the CSV it was given stays.
inline bool drawPlot(const std::vector<std::string>& arguments, std::string& error) {
    const std::string python = "/usr/bin/python3", script = (shippedFiles().data / "scripts/plot.py").string();
    std::vector<std::string> words{python, script};
    words.insert(words.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    pid_t child = 0;
    if (const int failed = posix_spawn(&child, python.c_str(), nullptr, nullptr, argv.data(), environ)) {
        error = "cannot run " + python + " (Debian's python3, for " + script + "): " + std::strerror(failed);
        return false;
    }
    int status = 0;
    while (waitpid(child, &status, 0) < 0)
        if (errno != EINTR) {
            error = std::string("waiting for ") + script + ": " + std::strerror(errno);
            return false;
        }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return true;
    error = script + (WIFEXITED(status) ? " exited with status " + std::to_string(WEXITSTATUS(status))
                                        : " was killed by signal " + std::to_string(WTERMSIG(status))) +
            " (is python3-matplotlib installed? scripts/setup.sh installs it)";
    return false;
}

}  // namespace kiln
