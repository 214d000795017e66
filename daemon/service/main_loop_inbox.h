#pragma once

#include <functional>
#include <mutex>
#include <vector>

#include <systemd/sd-event.h>

#include "io/handles.h"

namespace everytouch::service {

// Lets other threads hand work to the thread running the sd-event loop, which owns the bus: post() queues a
// task and wakes the loop through an eventfd; the loop runs the tasks in the order they came.
class MainLoopInbox {
public:
    // Returns 0 or a negative errno.
    int attach(sd_event* event);

    // Any thread.
    void post(std::function<void()> task);

private:
    static int onReadable(sd_event_source* source, int fd, uint32_t events, void* userdata) noexcept;

    io::UniqueFd eventFd_;
    io::EventSource source_;
    std::mutex mutex_;
    std::vector<std::function<void()>> tasks_;
};

}  // namespace everytouch::service
