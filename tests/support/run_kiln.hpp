// Runs the kiln binary (KILN_BINARY) as a user would, with its stdout and stderr
// captured in files of their own (ctest runs test cases in parallel processes).
// A run longer than `timeoutSeconds` is killed: exit code 124 means it hung.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace kiln::test {

struct Run {
    int exitCode = -1;  // the shell's: 128 + N for a signal N, 124 for a timeout
    std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// `cwd`: the working directory to run in (empty: the test's own).
inline Run runProgram(const std::string& binary, const std::string& args, int timeoutSeconds = 120,
                      const std::string& cwd = {}) {
    static int serial = 0;
    std::filesystem::create_directories(TEST_OUTPUT_DIR);
    const std::string base = std::string(TEST_OUTPUT_DIR) + "/run-" + std::to_string(getpid()) + "-" + std::to_string(++serial);
    const std::string out = base + ".out", err = base + ".err";
    const std::string cmd = (cwd.empty() ? "" : "cd '" + cwd + "' && ") + "timeout -s KILL " + std::to_string(timeoutSeconds) + " " + binary + " " +
                            args + " > " + out + " 2> " + err;
    const int status = std::system(cmd.c_str());
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    if (code == 128 + 9) code = 124;  // timeout's KILL
    return {code, slurp(out), slurp(err)};
}

inline Run runKiln(const std::string& args, int timeoutSeconds = 120, const std::string& cwd = {}) {
    return runProgram(KILN_BINARY, args, timeoutSeconds, cwd);
}

}  // namespace kiln::test
