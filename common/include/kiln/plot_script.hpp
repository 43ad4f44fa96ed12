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
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "kiln/data_root.hpp"

extern char** environ;

namespace kiln {

// A figure's `--about` line: what it was measured on (the picture's size, the device),
// and today's date, so a figure copied into the documentation says where it came from.
inline std::string plotAbout(const std::string& sizeAndDevice) {
    char date[16] = "";
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    if (gmtime_r(&now, &utc)) std::strftime(date, sizeof date, "%Y-%m-%d", &utc);
    return sizeAndDevice + ", " + date;
}

// The same for a rendered figure: its size in pixels and the GL device that drew it.
inline std::string plotAbout(int width, int height, const std::string& device) {
    return plotAbout(std::to_string(width) + "x" + std::to_string(height) + ", " + device);
}

// The CPU's model as /proc/cpuinfo names it (for a figure of CPU-only work), or "CPU".
inline std::string cpuModel() {
    std::ifstream info("/proc/cpuinfo");
    for (std::string line; std::getline(info, line);)
        if (line.rfind("model name", 0) == 0)
            if (const size_t colon = line.find(':'); colon != std::string::npos && colon + 2 <= line.size())
                return line.substr(colon + 2);
    return "CPU";
}

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
