#pragma once

#include <systemd/sd-event.h>

#include <cstddef>
#include <functional>
#include <vector>

#include "io/handles.h"

namespace everytouch::service {

// Writes bytes to a descriptor another process passed us (a Snapshot call's), from the main loop and without
// ever blocking it: a reader that is slow or never reads holds up nothing but its own write. The caller's
// file description keeps its flags: pipes and FIFOs are opened anew, non-blocking, through /proc/self/fd;
// sockets are written with MSG_DONTWAIT; regular files never wait for a reader and are written at once.
class DescriptorWriter {
public:
    // 0, or a negative errno: the result of the whole write.
    using Finished = std::function<void(int result)>;

    DescriptorWriter() = default;
    DescriptorWriter(const DescriptorWriter&) = delete;
    DescriptorWriter& operator=(const DescriptorWriter&) = delete;

    // Keeps a private descriptor for writing to `fd`. Returns 0 or a negative errno (-EBADF when `fd` is not
    // open for writing, -ENXIO for a pipe whose reader has gone).
    int adopt(int fd);
    // Writes `bytes` as the descriptor accepts them; `finished` runs once on `event`'s loop, unless the
    // writer is destroyed first. Returns 0 or a negative errno when the writing cannot start.
    int start(sd_event* event, std::vector<unsigned char> bytes, Finished finished);

private:
    enum class Kind { File, Socket, Stream };

    // 1 when everything is written, 0 when the descriptor takes no more for now, or a negative errno.
    int writeSome();
    void onReady();
    static int onWritable(sd_event_source* source, int fd, uint32_t events, void* userdata) noexcept;
    static int onDeferred(sd_event_source* source, void* userdata) noexcept;

    io::UniqueFd fd_;
    Kind kind_ = Kind::File;
    std::vector<unsigned char> bytes_;
    std::size_t written_ = 0;
    Finished finished_;
    io::EventSource source_;
};

}  // namespace everytouch::service
