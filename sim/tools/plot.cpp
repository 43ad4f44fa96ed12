#include "plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <stb_easy_font.h>
#include <stb_image_write.h>

namespace {

struct Canvas {
    int w, h;
    std::vector<uint8_t> rgb;
    Canvas(int width, int height) : w(width), h(height), rgb(size_t(width) * size_t(height) * 3, 255) {}
    void put(int x, int y, std::array<uint8_t, 3> c) {
        if (x < 0 || y < 0 || x >= w || y >= h) return;
        uint8_t* p = &rgb[(size_t(y) * size_t(w) + size_t(x)) * 3];
        p[0] = c[0], p[1] = c[1], p[2] = c[2];
    }
    void rect(int x0, int y0, int x1, int y1, std::array<uint8_t, 3> c) {
        for (int y = std::min(y0, y1); y <= std::max(y0, y1); ++y)
            for (int x = std::min(x0, x1); x <= std::max(x0, x1); ++x) put(x, y, c);
    }
    // A line `thick` pixels wide (square brush), DDA.
    void line(double x0, double y0, double x1, double y1, std::array<uint8_t, 3> c, int thick = 1) {
        const int n = int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
        for (int i = 0; i <= n; ++i) {
            const double s = double(i) / n;
            const int x = int(std::lround(x0 + s * (x1 - x0))), y = int(std::lround(y0 + s * (y1 - y0)));
            rect(x - thick / 2, y - thick / 2, x + (thick - 1) / 2, y + (thick - 1) / 2, c);
        }
    }
    // Text at (x, y) (top-left), `scale` × stb_easy_font's ~7 px glyphs.
    void text(int x, int y, const std::string& s, int scale = 2, std::array<uint8_t, 3> c = {0, 0, 0}) {
        static char buffer[64000];
        std::string copy = s;
        const int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, buffer, sizeof buffer);
        for (int q = 0; q < quads; ++q) {
            const float* v = reinterpret_cast<const float*>(buffer + q * 64);  // 4 vertices × 16 bytes
            const float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];
            rect(x + int(qx0 * scale), y + int(qy0 * scale), x + int(qx1 * scale) - 1, y + int(qy1 * scale) - 1, c);
        }
    }
    int textWidth(const std::string& s, int scale = 2) {
        std::string copy = s;
        return stb_easy_font_width(copy.data()) * scale;
    }
};

std::string decadeLabel(int e) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "1e%d", e);
    return buf;
}

// An axis over [log10 lo, log10 hi] of the data: whole decades when the data spans three
// or more, else the 1-2-5 values around it (so a sweep from 80 to 160 ms is not a sliver
// of a 10..1000 axis). Returns the ends (log10) and the ticks (log10, label).
struct LogAxis {
    double lo, hi;
    std::vector<std::pair<double, std::string>> ticks;
};
LogAxis logAxis(double l0, double l1) {
    LogAxis a;
    if (l1 - l0 >= 3.0) {
        const int e0 = int(std::floor(l0)), e1 = std::max(e0 + 1, int(std::ceil(l1)));
        a.lo = e0, a.hi = e1;
        const int step = std::max(1, (e1 - e0 + 7) / 8);
        for (int e = e0; e <= e1; e += step) a.ticks.emplace_back(e, decadeLabel(e));
        return a;
    }
    std::vector<double> nice;  // 1, 2, 5 × 10^k around the data
    for (int e = int(std::floor(l0)) - 1; e <= int(std::ceil(l1)) + 1; ++e)
        for (double m : {1.0, 2.0, 5.0}) nice.push_back(std::log10(m) + e);
    a.lo = l0, a.hi = l1;
    for (double v : nice) if (v <= l0 + 1e-9) a.lo = v;
    for (auto it = nice.rbegin(); it != nice.rend(); ++it) if (*it >= l1 - 1e-9) a.hi = *it;
    if (a.hi <= a.lo) a.hi = a.lo + std::log10(2.0);
    for (double v : nice)
        if (v >= a.lo - 1e-9 && v <= a.hi + 1e-9) {
            char buf[24];
            std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, v));
            a.ticks.emplace_back(v, buf);
        }
    return a;
}

}  // namespace

bool writeLogLogPng(const std::string& path, const LogLogPlot& plot, std::string& error, int width, int height) {
    double lx0 = 1e300, lx1 = -1e300, ly0 = 1e300, ly1 = -1e300;
    for (auto& s : plot.series)
        for (auto& [x, y] : s.points)
            if (x > 0 && y > 0 && std::isfinite(x) && std::isfinite(y)) {
                lx0 = std::min(lx0, std::log10(x)), lx1 = std::max(lx1, std::log10(x));
                ly0 = std::min(ly0, std::log10(y)), ly1 = std::max(ly1, std::log10(y));
            }
    if (lx0 > lx1) lx0 = 0, lx1 = 1, ly0 = 0, ly1 = 1;
    const LogAxis ax = logAxis(lx0, lx1), ay = logAxis(ly0, ly1);
    Canvas c(width, height);
    const int left = 90, right = width - 30, top = 60, bottom = height - 70;
    auto px = [&](double lx) { return left + (lx - ax.lo) / (ax.hi - ax.lo) * (right - left); };
    auto py = [&](double ly) { return bottom - (ly - ay.lo) / (ay.hi - ay.lo) * (bottom - top); };
    const std::array<uint8_t, 3> grid{225, 225, 225}, axis{60, 60, 60};
    for (auto& [v, l] : ax.ticks) {
        c.line(px(v), top, px(v), bottom, grid);
        c.text(int(px(v)) - c.textWidth(l) / 2, bottom + 8, l);
    }
    for (auto& [v, l] : ay.ticks) {
        c.line(left, py(v), right, py(v), grid);
        c.text(left - 8 - c.textWidth(l), int(py(v)) - 6, l);
    }
    c.line(left, bottom, right, bottom, axis, 2);
    c.line(left, top, left, bottom, axis, 2);
    c.text(left, 14, plot.title, 3);
    c.text(left + 4, top - 20, plot.yLabel);
    c.text((left + right) / 2 - c.textWidth(plot.xLabel) / 2, bottom + 36, plot.xLabel);
    // The legend goes in the top corner with fewer points under it.
    int leftCount = 0, rightCount = 0;
    for (auto& s : plot.series)
        for (auto& [x, y] : s.points)
            if (x > 0 && y > 0 && py(std::log10(y)) < (top + bottom) / 2.0)
                (px(std::log10(x)) < (left + right) / 2.0 ? leftCount : rightCount)++;
    const bool legendLeft = leftCount < rightCount;
    int legendY = top + 10;
    for (auto& s : plot.series) {
        bool have = false;
        double ox = 0, oy = 0;
        for (auto& [x, y] : s.points) {
            if (!(x > 0 && y > 0 && std::isfinite(x) && std::isfinite(y))) continue;
            const double X = px(std::log10(x)), Y = py(std::log10(y));
            if (have && s.connect) c.line(ox, oy, X, Y, s.color, 2);
            c.rect(int(X) - s.marker, int(Y) - s.marker, int(X) + s.marker, int(Y) + s.marker, s.color);
            ox = X, oy = Y, have = true;
        }
        const int lx = legendLeft ? left + 16 : right - 16 - c.textWidth(s.label) - 30;
        c.rect(lx, legendY + 2, lx + 20, legendY + 8, s.color);
        c.text(lx + 28, legendY, s.label);
        legendY += 22;
    }
    if (!stbi_write_png(path.c_str(), width, height, 3, c.rgb.data(), width * 3)) {
        error = "cannot write " + path;
        return false;
    }
    return true;
}
