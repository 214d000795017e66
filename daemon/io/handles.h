#pragma once

#include <sys/mman.h>
#include <systemd/sd-bus.h>
#include <systemd/sd-event.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>

namespace everytouch::io {

// Owners for C library handles: `UniqueHandle<sd_bus, sd_bus_flush_close_unref>` and the like, so that no
// handle is ever released by hand. Aliases for sd-bus, sd-event and file descriptors follow the template;
// libevdev's are in io/evdev_handles.h.
template <auto releaseFunction>
struct HandleDeleter {
    template <typename T>
    void operator()(T* handle) const {
        releaseFunction(handle);
    }
};

template <typename T, auto releaseFunction>
using UniqueHandle = std::unique_ptr<T, HandleDeleter<releaseFunction>>;

// sd-bus and sd-event (libsystemd). A bus is flushed before it closes, so queued replies still go out.
using Bus = UniqueHandle<sd_bus, sd_bus_flush_close_unref>;
using BusMessage = UniqueHandle<sd_bus_message, sd_bus_message_unref>;
using BusSlot = UniqueHandle<sd_bus_slot, sd_bus_slot_unref>;
using BusCreds = UniqueHandle<sd_bus_creds, sd_bus_creds_unref>;
using BusTrack = UniqueHandle<sd_bus_track, sd_bus_track_unref>;
using Event = UniqueHandle<sd_event, sd_event_unref>;
using EventSource = UniqueHandle<sd_event_source, sd_event_source_disable_unref>;

// Frees an sd_bus_error when it goes out of scope.
class UniqueBusError {
public:
    UniqueBusError() = default;
    UniqueBusError(const UniqueBusError&) = delete;
    UniqueBusError& operator=(const UniqueBusError&) = delete;
    ~UniqueBusError() { sd_bus_error_free(&error_); }

    sd_bus_error* get() { return &error_; }
    const sd_bus_error* get() const { return &error_; }
    const char* name() const { return error_.name ? error_.name : ""; }
    const char* message() const { return error_.message ? error_.message : ""; }
    bool has(const char* name) const { return sd_bus_error_has_name(&error_, name); }

private:
    sd_bus_error error_ = SD_BUS_ERROR_NULL;
};

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

// Owns a memory mapping (mmap); unmaps it once.
class MemoryMapping {
public:
    MemoryMapping() = default;
    MemoryMapping(void* start, std::size_t length) : start_(start), length_(length) {}
    MemoryMapping(MemoryMapping&& other) noexcept
        : start_(std::exchange(other.start_, MAP_FAILED)), length_(std::exchange(other.length_, 0)) {}
    MemoryMapping& operator=(MemoryMapping&& other) noexcept {
        reset();
        start_ = std::exchange(other.start_, MAP_FAILED);
        length_ = std::exchange(other.length_, 0);
        return *this;
    }
    MemoryMapping(const MemoryMapping&) = delete;
    MemoryMapping& operator=(const MemoryMapping&) = delete;
    ~MemoryMapping() { reset(); }

    const std::uint8_t* data() const { return static_cast<const std::uint8_t*>(start_); }
    std::size_t length() const { return length_; }
    explicit operator bool() const { return start_ != MAP_FAILED; }
    void reset() {
        if (start_ != MAP_FAILED)
            ::munmap(start_, length_);
        start_ = MAP_FAILED;
        length_ = 0;
    }

private:
    void* start_ = MAP_FAILED;
    std::size_t length_ = 0;
};

}  // namespace everytouch::io
