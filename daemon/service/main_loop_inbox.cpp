#include "service/main_loop_inbox.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <exception>

#include "io/log.h"

namespace everytouch::service {

int MainLoopInbox::attach(sd_event* event) {
    eventFd_.reset(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
    if (!eventFd_)
        return -errno;
    sd_event_source* source = nullptr;
    const int r = sd_event_add_io(event, &source, eventFd_.get(), EPOLLIN, onReadable, this);
    source_.reset(source);
    return r < 0 ? r : 0;
}

void MainLoopInbox::post(std::function<void()> task) {
    {
        std::lock_guard lock(mutex_);
        tasks_.push_back(std::move(task));
    }
    const std::uint64_t one = 1;
    // A full counter (2^64 - 2 wake-ups unread) cannot happen; a failed write would only delay the task.
    [[maybe_unused]] const ssize_t written = ::write(eventFd_.get(), &one, sizeof one);
}

int MainLoopInbox::onReadable(sd_event_source*, int fd, uint32_t, void* userdata) noexcept {
    auto* inbox = static_cast<MainLoopInbox*>(userdata);
    std::uint64_t count = 0;
    [[maybe_unused]] const ssize_t consumed = ::read(fd, &count, sizeof count);
    std::vector<std::function<void()>> tasks;
    {
        std::lock_guard lock(inbox->mutex_);
        tasks.swap(inbox->tasks_);
    }
    for (std::function<void()>& task : tasks) {
        try {
            task();
        } catch (const std::exception& error) {
            ET_LOG(Error) << "internal error: " << error.what();
        }
    }
    return 0;
}

}  // namespace everytouch::service
