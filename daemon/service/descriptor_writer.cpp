#include "service/descriptor_writer.h"

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <cerrno>
#include <exception>
#include <string>
#include <utility>

#include "io/log.h"

namespace everytouch::service {

int DescriptorWriter::adopt(int fd) {
    struct stat status {};
    if (::fstat(fd, &status) < 0)
        return -errno;
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0)
        return -errno;
    if ((flags & O_ACCMODE) == O_RDONLY)
        return -EBADF;
    if (S_ISREG(status.st_mode) || S_ISBLK(status.st_mode)) {
        kind_ = Kind::File;
        fd_.reset(::fcntl(fd, F_DUPFD_CLOEXEC, 3));
    } else if (S_ISSOCK(status.st_mode)) {
        kind_ = Kind::Socket;
        fd_.reset(::fcntl(fd, F_DUPFD_CLOEXEC, 3));
    } else {
        // A new open file description of the same pipe, FIFO or device: O_NONBLOCK on it is ours alone.
        kind_ = Kind::Stream;
        const std::string path = "/proc/self/fd/" + std::to_string(fd);
        fd_.reset(::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
    }
    return fd_ ? 0 : -errno;
}

int DescriptorWriter::start(sd_event* event, std::vector<unsigned char> bytes, Finished finished) {
    bytes_ = std::move(bytes);
    written_ = 0;
    finished_ = std::move(finished);
    sd_event_source* source = nullptr;
    // epoll refuses regular files, which are always ready: they are written on the loop's next turn.
    const int r = kind_ == Kind::File
                      ? sd_event_add_defer(event, &source, onDeferred, this)
                      : sd_event_add_io(event, &source, fd_.get(), EPOLLOUT, onWritable, this);
    if (r < 0)
        return r;
    source_.reset(source);
    return 0;
}

int DescriptorWriter::writeSome() {
    while (written_ < bytes_.size()) {
        const unsigned char* data = bytes_.data() + written_;
        const std::size_t size = bytes_.size() - written_;
        const ssize_t n = kind_ == Kind::Socket ? ::send(fd_.get(), data, size, MSG_DONTWAIT | MSG_NOSIGNAL)
                                                : ::write(fd_.get(), data, size);
        if (n >= 0) {
            written_ += static_cast<std::size_t>(n);
            continue;
        }
        if (errno == EINTR)
            continue;
        if (errno == EAGAIN)
            return 0;
        return -errno;
    }
    return 1;
}

void DescriptorWriter::onReady() {
    const int r = writeSome();
    if (r == 0)
        return;  // the next EPOLLOUT goes on
    source_.reset();
    // `finished` may destroy this writer: nothing of it is touched afterwards.
    const Finished finished = std::move(finished_);
    finished(r > 0 ? 0 : r);
}

int DescriptorWriter::onWritable(sd_event_source*, int, uint32_t, void* userdata) noexcept {
    try {
        static_cast<DescriptorWriter*>(userdata)->onReady();
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    return 0;
}

int DescriptorWriter::onDeferred(sd_event_source*, void* userdata) noexcept {
    return onWritable(nullptr, -1, 0, userdata);
}

}  // namespace everytouch::service
