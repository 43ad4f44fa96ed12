#include "kiln/log.hpp"

#include <cstdio>
#include <deque>
#include <mutex>

namespace kiln::log {
namespace {
std::mutex gMutex;
std::deque<std::pair<Level, std::string>> gRing;
Level gMin = Level::Info;
constexpr size_t kRingSize = 1000;
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
    gRing.emplace_back(level, std::move(message));
    if (gRing.size() > kRingSize) gRing.pop_front();
}

std::vector<std::pair<Level, std::string>> recent(size_t maxLines) {
    std::lock_guard lock(gMutex);
    size_t n = std::min(maxLines, gRing.size());
    return {gRing.end() - static_cast<long>(n), gRing.end()};
}

}  // namespace kiln::log
