// Runs the kiln binary (KILN_BINARY) as a user would, with its stdout and stderr
// captured in files of their own (ctest runs test cases in parallel processes).
// A run longer than `timeoutSeconds` is killed: exit code 124 means it hung.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

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

// A run's directory is kept for a look after a failure; the next run of the same test
// removes it and its other predecessors (an install is ~170 MB): `base` is <dir>/<name>-<pid>.
inline void removeEarlierRuns(const std::filesystem::path& base) {
    const std::string name = base.filename().string(), stem = name.substr(0, name.rfind('-') + 1);
    std::error_code ec;
    if (std::filesystem::is_directory(base.parent_path(), ec))
        for (const auto& entry : std::filesystem::directory_iterator(base.parent_path()))
            if (entry.path().filename().string().rfind(stem, 0) == 0) std::filesystem::remove_all(entry.path(), ec);
}

inline Run runKiln(const std::string& args, int timeoutSeconds = 120, const std::string& cwd = {}) {
    return runProgram(KILN_BINARY, args, timeoutSeconds, cwd);
}

// A program left running while the test goes on (a kiln --watch), its stdout and stderr
// in `log`. stop() sends SIGTERM and waits for the exit status (SIGKILL after the grace).
class Background {
public:
    Background(const std::vector<std::string>& argv, const std::string& log, const std::string& cwd) {
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        pid_ = fork();
        if (pid_ == 0) {  // only async-signal-safe calls until exec
            const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (fd < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0 || chdir(cwd.c_str()) != 0) _exit(126);
            execv(args[0], args.data());
            _exit(127);
        }
    }
    ~Background() { stop(std::chrono::seconds(5)); }
    bool started() const { return pid_ > 0; }
    bool running() {
        if (pid_ <= 0 || exited_) return false;
        int status = 0;
        if (waitpid(pid_, &status, WNOHANG) == pid_) record(status);
        return !exited_;
    }
    // The exit status (128 + N for a signal N; 124 when it had to be killed).
    int stop(std::chrono::seconds grace) {
        if (pid_ <= 0 || !running()) return exitCode_;
        kill(pid_, SIGTERM);
        const auto deadline = std::chrono::steady_clock::now() + grace;
        while (running() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (running()) {
            kill(pid_, SIGKILL);
            int status = 0;
            waitpid(pid_, &status, 0);
            exited_ = true;
            exitCode_ = 124;
        }
        return exitCode_;
    }

private:
    void record(int status) {
        exited_ = true;
        exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    }
    pid_t pid_ = -1;
    bool exited_ = false;
    int exitCode_ = -1;
};

}  // namespace kiln::test
