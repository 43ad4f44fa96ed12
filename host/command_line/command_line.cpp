#include "command_line/command_line.hpp"

#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <iostream>
#include <vector>

#include "kiln/names.hpp"
#include "kiln/pass.hpp"

namespace kiln::cli {

std::string versionLine(const std::string& program) {
    return program + " " KILN_VERSION " (pass ABI " + std::to_string(kPassAbiVersion) + ")";
}

void configure(CLI::App& app) {
    app.set_version_flag("--version", versionLine(app.get_name()), "print the version and exit");
    app.set_help_flag("-h,--help", "print this help and exit");
    app.get_formatter()->column_width(28);
}

int usageError(const CLI::App& app, const std::string& message) {
    std::fprintf(stderr, "%s: error: %s (see %s --help)\n", app.get_name().c_str(), message.c_str(),
                 app.get_name().c_str());
    return kExitUsage;
}

namespace {

// Long names only: "-h" would be the nearest name of every short typo. A subcommand's
// options count too (kiln-sim run --stepz).
void optionNames(const CLI::App& app, std::vector<std::string>& names) {
    for (const CLI::Option* option : app.get_options())
        for (const std::string& n : option->get_lnames()) names.push_back("--" + n);
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) optionNames(*sub, names);
}

// What CLI11 left over: a misspelt option gets its nearest name.
std::string describeExtras(const CLI::App& app) {
    for (const std::string& extra : app.remaining(true)) {
        if (extra.size() > 1 && extra[0] == '-') {
            const std::string name = extra.substr(0, extra.find('='));
            std::vector<std::string> names;
            optionNames(app, names);
            return "unknown option " + name + suggestion(name, names, "options");
        }
        return "unexpected argument \"" + elide(extra) + "\"";
    }
    return "unexpected arguments";
}

}  // namespace

std::optional<int> parse(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::cout << app.help();
        return 0;
    } catch (const CLI::CallForVersion& e) {
        std::cout << e.what() << "\n";
        return 0;
    } catch (const CLI::ExtrasError&) {
        return usageError(app, describeExtras(app));
    } catch (const CLI::ParseError& e) {
        return usageError(app, e.what());
    }
    return std::nullopt;
}

CLI::Option* addSize(CLI::App& app, const std::string& name, int& w, int& h, int lo, int hi, const std::string& help) {
    auto parseSide = [](std::string_view s, int& out) {
        auto r = std::from_chars(s.data(), s.data() + s.size(), out);
        return r.ec == std::errc() && r.ptr == s.data() + s.size();
    };
    return app
        .add_option_function<std::string>(
            name,
            [&w, &h, parseSide, lo, hi, name](const std::string& v) {
                const size_t x = v.find('x');
                int width = 0, height = 0;
                if (x == std::string::npos || !parseSide(std::string_view(v).substr(0, x), width) ||
                    !parseSide(std::string_view(v).substr(x + 1), height) || width < lo || height < lo || width > hi ||
                    height > hi)
                    throw CLI::ValidationError(name, v + ": expected WxH with " + std::to_string(lo) + " <= W, H <= " +
                                                         std::to_string(hi) + " (e.g. 720x720)");
                w = width;
                h = height;
            },
            help)
        ->type_name("WxH");
}

Progress::Progress(std::string what, int total)
    : what_(std::move(what)), total_(total), terminal_(isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()), lastDrawn_(start_) {}

Progress::~Progress() {
    if (terminal_ && drawnWidth_) std::fprintf(stderr, "\r%*s\r", int(drawnWidth_), "");
}

void Progress::advance(int done) {
    if (!terminal_ || total_ <= 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total_ && now - lastDrawn_ < std::chrono::milliseconds(100)) return;
    lastDrawn_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::string line = what_ + " " + std::to_string(done) + "/" + std::to_string(total_);
    if (done > 0 && done < total_) {
        char left[48];
        std::snprintf(left, sizeof left, ", %.1f s left", elapsed / done * (total_ - done));
        line += left;
    }
    const size_t width = line.size();
    if (width < drawnWidth_) line.append(drawnWidth_ - width, ' ');
    std::fprintf(stderr, "\r%s", line.c_str());
    std::fflush(stderr);
    drawnWidth_ = std::max(drawnWidth_, width);
}

}  // namespace kiln::cli
