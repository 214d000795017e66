#pragma once

#include <libevdev/libevdev-uinput.h>
#include <libevdev/libevdev.h>
#include <unistd.h>

#include <memory>
#include <utility>

namespace everytouch::io {

// Owners for C library handles: `UniqueHandle<sd_bus, sd_bus_flush_close_unref>` and the like, so that no
// handle is ever released by hand. Aliases for the libraries the adapters use follow the template.
template <auto releaseFunction>
struct HandleDeleter {
    template <typename T>
    void operator()(T* handle) const {
        releaseFunction(handle);
    }
};

template <typename T, auto releaseFunction>
using UniqueHandle = std::unique_ptr<T, HandleDeleter<releaseFunction>>;

using UniqueLibevdev = UniqueHandle<libevdev, libevdev_free>;
// Destroying it removes the uinput device and closes /dev/uinput.
using UniqueLibevdevUinput = UniqueHandle<libevdev_uinput, libevdev_uinput_destroy>;

// Owns a file descriptor; closes it once.
class UniqueFd {
public:
    UniqueFd() = default;
    explicit UniqueFd(int fd) : fd_(fd) {}
    UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
    UniqueFd& operator=(UniqueFd&& other) noexcept {
        reset(other.release());
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;
    ~UniqueFd() { reset(); }

    int get() const { return fd_; }
    explicit operator bool() const { return fd_ >= 0; }
    [[nodiscard]] int release() { return std::exchange(fd_, -1); }
    void reset(int fd = -1) {
        if (fd_ >= 0)
            ::close(fd_);
        fd_ = fd;
    }

private:
    int fd_ = -1;
};

}  // namespace everytouch::io
