// kiln-sim bench: the physics benchmarks (a command, not a test).
#pragma once

#include <string>

#include "kiln/sim/scene.hpp"

// Runs every benchmark on `scene`, prints tables, writes CSV into `outDir`; returns the
// process exit code. `quick` shortens the runs (for a smoke test).
int runBenchmarks(const kiln::sim::Scene& scene, const std::string& outDir, bool quick);
