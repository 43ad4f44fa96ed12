// run/pass_stats.hpp — per-pass timing and run/skip bookkeeping: GPU time from
// timestamp queries, CPU time around execute(), what happened this frame and why,
// and the table --stats prints.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "kiln/gl.hpp"

namespace kiln::run {

struct PassRow {
    std::string id, module;
    std::string state;        // ran / skipped / culled / disabled / error / nothing to do
    std::string why;
    double gpuMs = -1.0;      // rolling average over the frames it ran (−1: none yet)
    double cpuMs = 0.0;
    double gpuMedianMs = -1.0, cpuMedianMs = 0.0;
    int ranFrames = 0, skippedFrames = 0;
    int partialFrames = 0;      // runs handed part of the picture to redraw (FrameInfo::redraw)
    bool ranThisFrame = false;  // ran or nothing to do; skipped/culled/disabled/error cost 0
};

class PassTimings {
public:
    static constexpr size_t kMaxSamples = 2000;
    static constexpr size_t kRollingWindow = 30;

    gl::GpuTimer timer;
    std::string state = "not run", why;
    int ranFrames = 0, skippedFrames = 0;
    int partialFrames = 0;  // of ranFrames, those handed part of the picture (FrameInfo::redraw)

    void addCpu(double ms);
    // Harvests finished GPU queries; never waits.
    void collectGpu();
    // Forgets every sample and count (benchmarks call it after warm-up).
    void reset();
    void note(std::string newState, std::string reason) { state = std::move(newState), why = std::move(reason); }
    PassRow row(const std::string& id, const std::string& module) const;

private:
    std::deque<double> gpu_, cpu_;
};

// Fixed-width table: pass, module, state, median GPU and CPU ms, ran/skipped, note;
// then the totals of the medians.
std::string formatStatsTable(const std::vector<PassRow>&);

}  // namespace kiln::run
