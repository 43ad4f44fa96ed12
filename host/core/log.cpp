#include "kiln/log.hpp"

#include <cstdio>
#include <mutex>

namespace kiln::log {
namespace {
std::mutex gMutex;  // the watcher may log from its own thread
Level gMin = Level::Info;
const char* prefix(Level l) {
    switch (l) {
        case Level::Debug: return "kiln: debug: ";
        case Level::Info: return "kiln: ";
        case Level::Warn: return "kiln: warning: ";
        case Level::Error: return "kiln: error: ";
    }
    return "kiln: ";
}
}  // namespace

void setMinLevel(Level l) {
    std::lock_guard lock(gMutex);
    gMin = l;
}

void write(Level level, std::string message) {
    std::lock_guard lock(gMutex);
    if (level < gMin) return;
    std::fprintf(stderr, "%s%s\n", prefix(level), message.c_str());
}

}  // namespace kiln::log
