// command_line/command_line.hpp — the conventions every Kiln program keeps on its command
// line, on top of CLI11:
//   --help prints usage to stdout, exits 0 and runs nothing; --version likewise;
//   --opt value and --opt=value both work;
//   a usage error is one line on stderr, "<program>: error: <what>", with "did you mean"
//   for a misspelt option, and exits 2; a run that fails exits 1; Ctrl+C exits 130.
#pragma once

#include <CLI/CLI.hpp>

#include <chrono>
#include <optional>
#include <string>

namespace kiln::cli {

inline constexpr int kExitFailure = 1;       // the run failed (an error was printed)
inline constexpr int kExitUsage = 2;         // the command line was wrong; nothing ran
inline constexpr int kExitInterrupted = 130; // SIGINT (128 + 2), as a shell reports it

// "<program> <version> (pass ABI N)".
std::string versionLine(const std::string& program);

// --version, and help laid out for an 80-column terminal.
void configure(CLI::App&);

// Parses argv. Returns the exit status when the program must stop now: 0 after --help or
// --version (printed to stdout), kExitUsage after a usage error (printed to stderr);
// nullopt when the program should run.
std::optional<int> parse(CLI::App&, int argc, char** argv);

// For the checks a program makes after parsing (options that exclude each other):
// prints the same one line and returns kExitUsage.
int usageError(const CLI::App&, const std::string& message);

// --NAME WxH, each side in [lo, hi], written into w and h as it parses.
CLI::Option* addSize(CLI::App&, const std::string& name, int& w, int& h, int lo, int hi, const std::string& help);

// A progress line for a long run: on a terminal (stderr), "\r<what> 12/40, 3.1 s left",
// redrawn at most ten times a second and cleared at the end; in a pipe or a file, nothing,
// so logs and CSVs stay clean.
class Progress {
public:
    Progress(std::string what, int total);
    ~Progress();
    void advance(int done);  // `done` of `total` finished
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

private:
    std::string what_;
    int total_;
    bool terminal_;
    std::chrono::steady_clock::time_point start_, lastDrawn_;
    size_t drawnWidth_ = 0;
};

}  // namespace kiln::cli
