#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace everytouch::test {

struct ProcessResult {
    int exitCode = -1;  // the exit status, or 128 + signal number
    std::string out;    // everything written to stdout
    std::string err;    // everything written to stderr
};

// Runs a program to completion with the given arguments, capturing its output. Fails the test if it cannot
// start.
ProcessResult runProcess(const std::vector<std::string>& argv);

// A program running beside the test (searched in $PATH), its stdout and stderr going to `outputFile`.
// Killed and reaped when the object goes, unless it ended before.
class BackgroundProcess {
public:
    // `environment`: variables set for the program on top of this process's environment.
    BackgroundProcess(const std::vector<std::string>& argv, const std::filesystem::path& outputFile,
                      const std::vector<std::pair<std::string, std::string>>& environment = {});
    ~BackgroundProcess();
    BackgroundProcess(const BackgroundProcess&) = delete;
    BackgroundProcess& operator=(const BackgroundProcess&) = delete;

    pid_t pid() const { return pid_; }
    // Whether the program holds `file` open right now.
    bool hasOpen(const std::filesystem::path& file) const;
    void signal(int number) const;
    // The exit status (128 + signal number when killed), or nothing if it is still running after `timeout`.
    std::optional<int> wait(std::chrono::milliseconds timeout);
    bool running() { return !wait(std::chrono::milliseconds(0)); }
    // What it has written so far.
    std::string output() const;
    // Waits up to `timeout` for `text` to appear in what it writes; true when it did.
    bool waitForOutput(const std::string& text, std::chrono::milliseconds timeout) const;

private:
    std::filesystem::path outputFile_;
    pid_t pid_ = -1;
    std::optional<int> exitCode_;
};

}  // namespace everytouch::test
