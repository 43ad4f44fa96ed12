#include "run/pass_stats.hpp"

#include <algorithm>
#include <iomanip>
#include <numeric>
#include <sstream>

namespace kiln::run {

namespace {

double median(std::deque<double> v) {
    if (v.empty()) return -1.0;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

double recentMean(const std::deque<double>& v, size_t lastN) {
    if (v.empty()) return -1.0;
    const size_t n = std::min(lastN, v.size());
    return std::accumulate(v.end() - static_cast<long>(n), v.end(), 0.0) / static_cast<double>(n);
}

std::string formatMs(double v) {
    std::ostringstream s;
    if (v < 0) s << "-";
    else s << std::fixed << std::setprecision(3) << v;
    return s.str();
}

}  // namespace

void PassTimings::addCpu(double ms) {
    cpu_.push_back(ms);
    if (cpu_.size() > kMaxSamples) cpu_.pop_front();
}

void PassTimings::collectGpu() {
    timer.collect(gpu_);
    while (gpu_.size() > kMaxSamples) gpu_.pop_front();
}

void PassTimings::reset() {
    collectGpu();
    gpu_.clear();
    cpu_.clear();
    ranFrames = skippedFrames = partialFrames = 0;
}

PassRow PassTimings::row(const std::string& id, const std::string& module) const {
    PassRow r;
    r.id = id;
    r.module = module;
    r.state = state;
    r.why = why;
    r.gpuMs = recentMean(gpu_, kRollingWindow);
    r.cpuMs = cpu_.empty() ? 0.0 : recentMean(cpu_, kRollingWindow);
    r.gpuMedianMs = median(gpu_);
    r.cpuMedianMs = cpu_.empty() ? 0.0 : median(cpu_);
    r.ranFrames = ranFrames;
    r.skippedFrames = skippedFrames;
    r.partialFrames = partialFrames;
    r.ranThisFrame = state == "ran" || state == "nothing to do";
    return r;
}

std::string formatStatsTable(const std::vector<PassRow>& rows) {
    std::ostringstream os;
    os << std::left << std::setw(14) << "pass" << std::setw(12) << "module" << std::setw(15) << "state" << std::right
       << std::setw(10) << "gpu ms" << std::setw(10) << "cpu ms" << std::setw(6) << "ran" << std::setw(8) << "skipped"
       << "  note\n";
    double gpuTotal = 0, cpuTotal = 0;
    for (auto& r : rows) {
        os << std::left << std::setw(14) << r.id << std::setw(12) << r.module << std::setw(15) << r.state << std::right
           << std::setw(10) << formatMs(r.gpuMedianMs) << std::setw(10) << formatMs(r.ranFrames ? r.cpuMedianMs : -1)
           << std::setw(6) << r.ranFrames << std::setw(8) << r.skippedFrames << "  " << r.why << "\n";
        if (r.gpuMedianMs > 0) gpuTotal += r.gpuMedianMs;
        if (r.ranFrames) cpuTotal += r.cpuMedianMs;
    }
    os << std::left << std::setw(41) << "total (medians)" << std::right << std::setw(10) << std::fixed
       << std::setprecision(3) << gpuTotal << std::setw(10) << cpuTotal << "\n";
    return os.str();
}

}  // namespace kiln::run
