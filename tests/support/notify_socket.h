#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

namespace everytouch::test {

// Plays systemd's side of sd_notify(3): a datagram socket to pass as NOTIFY_SOCKET, collecting what the
// service reports (READY=1, STATUS=..., WATCHDOG=1).
class NotifySocket {
public:
    explicit NotifySocket(const std::filesystem::path& path);
    ~NotifySocket();
    NotifySocket(const NotifySocket&) = delete;
    NotifySocket& operator=(const NotifySocket&) = delete;

    const std::filesystem::path& path() const { return path_; }

    // Waits up to `timeout` for a message with a line equal to `line` (or starting with it when it ends in
    // '='); true when one came. Every message read is kept in messages().
    bool waitFor(const std::string& line, std::chrono::milliseconds timeout);
    const std::vector<std::string>& messages() const { return messages_; }

private:
    bool seen(const std::string& line, std::size_t from) const;

    std::filesystem::path path_;
    int fd_ = -1;
    std::vector<std::string> messages_;
};

}  // namespace everytouch::test
