// app/cli.hpp — the `kiln` command line (the README's "Command line" lists it).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

namespace kiln::app {

inline constexpr uint64_t kSceneSeed = ~0ull;

struct Options {
    std::string pipeline;     // default: <source>/pipelines/default.json
    std::string scene;        // default: <source>/scenes/cornell.json
    std::string shaderRoot;   // ':'-separated roots; an empty entry: the shipped shaders/
    std::string moduleDir;    // ':'-separated; an empty entry: the shipped modules
    bool headless = false;
    int width = 720, height = 720;
    int windowWidth = 0, windowHeight = 0;  // --window; 0: --size plus the panels' column
    int frames = 1;           // frames rendered before the outputs (then the GI settles)
    std::string out;          // the final image: PNG, OpenEXR or PFM by its extension
    std::string dump;         // directory for every texture of the last frame
    bool stats = false;
    bool noSkip = false;      // run every pass every frame (for timing tables)
    bool fullRedraw = false;  // no partial frames when only bodies moved (App::redrawParts)
    bool printPlan = false;
    std::string dot;          // write the plan as graphviz
    uint64_t seed = kSceneSeed;  // kSceneSeed: the scene file's physics.seed
    bool live = true;         // watch files and reload them while running
    bool watch = false;       // headless: run until interrupted, rewrite the outputs after each reload
    bool paused = false;      // freeze the simulation (time stays at 0 + frames×0)
    std::vector<std::string> sets;  // --set PASS.PARAM=VALUE, in command-line order
    bool listModules = false;  // print the modules found and exit
    std::string describe;      // print a module's declaration ("all": every module) and exit
    std::string screenshot;   // window: save the window after --frames frames and quit
    std::string view;         // "pass.output" to show instead of the graph output
    int budgetMs = 100;       // window: frame-time budget for the render resolution (0: off)
    int watchdogSeconds = 10; // bound on one call into a module (0: none)
    std::string uiProbe;      // window: JSON file of widget rectangles and readouts
};

// Parses argv (the conventions of command_line/command_line.hpp). Returns the options to
// run with, or the exit status when kiln must stop now: 0 after --help or --version, 2
// after a usage error (one line on stderr).
std::variant<Options, int> parseCommandLine(int argc, char** argv);
// Where unset paths point: the working directory when it holds a Kiln tree
// (pipelines/default.json and shaders/), else the shipped files (kiln/data_root.hpp:
// the installation's, or the source tree's for a build-tree kiln).
std::filesystem::path defaultDataRoot();
// The image format a file's extension names, whatever its case: "png", "exr", "pfm",
// or "" for any other (--out refuses those).
std::string imageFormatOf(const std::string& file);
// "a:b::c" → a, b, c (the empty entries dropped; applyDefaults has filled them).
std::vector<std::string> pathList(const std::string& list);
// Fills unset paths: pipelines/default.json and scenes/cornell.json under
// defaultDataRoot(); its shaders/ and the shipped modules where the lists are empty or
// have an empty entry.
void applyDefaults(Options&);

}  // namespace kiln::app
