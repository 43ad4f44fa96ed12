// A small log-log line plot written as PNG (stb_image_write; labels with stb_easy_font):
// enough for the benchmark's time-vs-error figures, no plotting dependency.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

struct PlotSeries {
    std::string label;
    std::array<uint8_t, 3> color{0, 0, 0};
    std::vector<std::pair<double, double>> points;  // (x, y), both > 0; others skipped
    bool connect = true;                            // false: markers only (a scatter)
    int marker = 3;                                 // half-size of the square marker, px
};

struct LogLogPlot {
    std::string title, xLabel, yLabel;
    std::vector<PlotSeries> series;
};

// Writes `plot` to `path` (RGB PNG, width × height). On failure returns false and says
// why in `error`.
bool writeLogLogPng(const std::string& path, const LogLogPlot& plot, std::string& error, int width = 900,
                    int height = 620);
