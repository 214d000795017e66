#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace everytouch::test {

// Plays systemd's side of sd_notify(3): a datagram socket to pass as NOTIFY_SOCKET, collecting what the
// service reports (READY=1, STATUS=..., WATCHDOG=1). It reads all the time, as systemd does: a socket left
// unread fills up after a few messages (net.unix.max_dgram_qlen, 10 by default), and then the service's
// next sd_notify blocks its main loop.
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
    std::vector<std::string> messages() const;

private:
    void read();
    // Reads every message waiting on the socket; true when there was one. With mutex_ held.
    bool drain();
    bool seen(const std::string& line) const;

    std::filesystem::path path_;
    int fd_ = -1;
    mutable std::mutex mutex_;
    std::condition_variable arrived_;
    std::vector<std::string> messages_;
    std::atomic<bool> stopping_{false};
    std::thread reader_;
};

}  // namespace everytouch::test
