#include "kiln/log.hpp"

#include <cstdio>
#include <string>
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
    // Every line with its prefix (a shader's info log holds several): a line taken out
    // of the terminal, or grep'd for, still says what it is.
    size_t begin = 0;
    do {
        const size_t end = message.find('\n', begin);
        const std::string line = message.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
        std::fprintf(stderr, "%s%s\n", prefix(level), line.c_str());
        begin = end == std::string::npos ? end : end + 1;
    } while (begin != std::string::npos && begin < message.size());
}

}  // namespace kiln::log
