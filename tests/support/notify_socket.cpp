#include "support/notify_socket.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <sstream>
#include <stdexcept>

namespace everytouch::test {

NotifySocket::NotifySocket(const std::filesystem::path& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    if (fd_ < 0 || path.string().size() >= sizeof address.sun_path)
        throw std::runtime_error("cannot create the notify socket");
    std::strcpy(address.sun_path, path.c_str());
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) < 0)
        throw std::runtime_error("cannot bind the notify socket " + path.string());
    reader_ = std::thread([this] { read(); });
}

NotifySocket::~NotifySocket() {
    stopping_ = true;
    reader_.join();
    ::close(fd_);
    ::unlink(path_.c_str());
}

void NotifySocket::read() {
    // Polls briefly, so that the destructor's stop is seen soon.
    constexpr int kPollMs = 50;
    while (!stopping_) {
        pollfd readable{fd_, POLLIN, 0};
        if (::poll(&readable, 1, kPollMs) <= 0)
            continue;
        std::lock_guard lock(mutex_);
        if (drain())
            arrived_.notify_all();
    }
}

bool NotifySocket::drain() {
    bool any = false;
    char buffer[4096];
    for (ssize_t n; (n = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT)) > 0; any = true)
        messages_.emplace_back(buffer, static_cast<std::size_t>(n));
    return any;
}

bool NotifySocket::seen(const std::string& line) const {
    const bool prefix = !line.empty() && line.back() == '=';
    for (const std::string& message : messages_) {
        std::istringstream lines(message);
        for (std::string candidate; std::getline(lines, candidate);)
            if (prefix ? candidate.starts_with(line) : candidate == line)
                return true;
    }
    return false;
}

bool NotifySocket::waitFor(const std::string& line, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    drain();  // what was sent before this call counts even with no time to wait
    return arrived_.wait_for(lock, timeout, [&] { return seen(line); });
}

std::vector<std::string> NotifySocket::messages() const {
    std::lock_guard lock(mutex_);
    return messages_;
}

}  // namespace everytouch::test
