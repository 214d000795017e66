#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace everytouch::test {

// A program running beside the test, its stdout and stderr going to a log file. Killed if still running
// when the object goes.
class BackgroundProcess {
public:
    // `environment`: variables set for the program on top of this process's environment.
    BackgroundProcess(const std::vector<std::string>& argv, const std::filesystem::path& logFile,
                      const std::vector<std::pair<std::string, std::string>>& environment = {});
    ~BackgroundProcess();
    BackgroundProcess(const BackgroundProcess&) = delete;
    BackgroundProcess& operator=(const BackgroundProcess&) = delete;

    pid_t pid() const { return pid_; }
    void signal(int signalNumber) const;

    // Waits up to `timeout` for the program to end; its exit status (128 + signal when killed) or nothing.
    std::optional<int> waitExit(std::chrono::milliseconds timeout);
    bool running();

    std::string log() const;

private:
    pid_t pid_ = 0;
    int pidFd_ = -1;
    std::optional<int> status_;
    std::filesystem::path logFile_;
};

}  // namespace everytouch::test
