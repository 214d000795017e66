#include "support/notify_socket.h"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
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
}

NotifySocket::~NotifySocket() {
    ::close(fd_);
    ::unlink(path_.c_str());
}

bool NotifySocket::seen(const std::string& line, std::size_t from) const {
    const bool prefix = !line.empty() && line.back() == '=';
    for (std::size_t i = from; i < messages_.size(); ++i) {
        std::istringstream lines(messages_[i]);
        for (std::string candidate; std::getline(lines, candidate);)
            if (prefix ? candidate.starts_with(line) : candidate == line)
                return true;
    }
    return false;
}

bool NotifySocket::waitFor(const std::string& line, std::chrono::milliseconds timeout) {
    if (seen(line, 0))
        return true;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (true) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        pollfd readable{fd_, POLLIN, 0};
        if (::poll(&readable, 1, static_cast<int>(std::max<long>(left.count(), 0))) <= 0)
            return false;
        char buffer[4096];
        const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
        if (n <= 0)
            continue;
        messages_.emplace_back(buffer, static_cast<std::size_t>(n));
        if (seen(line, messages_.size() - 1))
            return true;
    }
}

}  // namespace everytouch::test
