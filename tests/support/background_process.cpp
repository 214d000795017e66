#include "support/background_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace everytouch::test {

BackgroundProcess::BackgroundProcess(const std::vector<std::string>& argv,
                                     const std::filesystem::path& logFile,
                                     const std::vector<std::pair<std::string, std::string>>& environment)
    : logFile_(logFile) {
    std::vector<std::string> variables;
    for (char** entry = environ; *entry; ++entry) {
        const std::string variable = *entry;
        bool replaced = false;
        for (const auto& [name, value] : environment)
            replaced = replaced || variable.starts_with(name + "=");
        if (!replaced)
            variables.push_back(variable);
    }
    for (const auto& [name, value] : environment)
        variables.push_back(name + "=" + value);
    std::vector<char*> envp;
    for (std::string& variable : variables)
        envp.push_back(variable.data());
    envp.push_back(nullptr);
    std::vector<char*> args;
    for (const std::string& arg : argv)
        args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    const int spawned = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0)
        throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(spawned));
    // glibc 2.36 declares pidfd_open without C linkage for C++; the system call itself is fine.
    pidFd_ = static_cast<int>(::syscall(SYS_pidfd_open, pid_, 0));
}

BackgroundProcess::~BackgroundProcess() {
    if (running()) {
        ::kill(pid_, SIGKILL);
        waitExit(std::chrono::seconds(10));
    }
    ::close(pidFd_);
}

void BackgroundProcess::signal(int signalNumber) const {
    ::kill(pid_, signalNumber);
}

bool BackgroundProcess::running() {
    return !waitExit(std::chrono::milliseconds(0));
}

std::optional<int> BackgroundProcess::waitExit(std::chrono::milliseconds timeout) {
    if (status_)
        return status_;
    // The pidfd becomes readable when the process ends.
    pollfd ended{pidFd_, POLLIN, 0};
    if (::poll(&ended, 1, static_cast<int>(timeout.count())) <= 0)
        return std::nullopt;
    int status = 0;
    if (::waitpid(pid_, &status, 0) == pid_)
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return status_;
}

std::string BackgroundProcess::log() const {
    std::ifstream in(logFile_);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace everytouch::test
