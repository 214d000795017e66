#include "service/snapshot_requests.h"

#include <fcntl.h>
#include <time.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <sstream>

#include "io/log.h"
#include "service/bus_error.h"
#include "service/bus_names.h"

namespace everytouch::service {

SnapshotRequests::SnapshotRequests(sd_event* event, FrameLoop& loop, MainLoopInbox& inbox,
                                   SnapshotRenderer render, SnapshotTimeouts timeouts)
    : event_(event), loop_(loop), inbox_(inbox), render_(std::move(render)), timeouts_(timeouts) {}

void SnapshotRequests::add(SnapshotKind kind, int fd, SnapshotReply reply) {
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || (flags & O_ACCMODE) == O_RDONLY)
        throw BusError(SD_BUS_ERROR_INVALID_ARGS, "The file descriptor is not open for writing");
    if (loop_.finished())
        throw BusError(bus::kErrorNoCamera, "The camera delivers no frames");
    io::UniqueFd copy(::fcntl(fd, F_DUPFD_CLOEXEC, 3));
    if (!copy)
        throw BusError(SD_BUS_ERROR_FAILED,
                       std::string("Cannot keep the file descriptor: ") + std::strerror(errno));

    const std::uint64_t id = nextId_++;
    Request& request = requests_[id];
    request.owner = this;
    request.id = id;
    request.reply = std::move(reply);
    request.fd = std::move(copy);
    request.kind = kind;
    sd_event_source* timeout = nullptr;
    const auto timeoutUsec = std::chrono::duration_cast<std::chrono::microseconds>(timeouts_.frame).count();
    if (const int r =
            sd_event_add_time_relative(event_, &timeout, CLOCK_MONOTONIC,
                                       static_cast<std::uint64_t>(timeoutUsec), 0, onTimeout, &request);
        r < 0) {
        requests_.erase(id);
        throw BusError(SD_BUS_ERROR_FAILED, std::string("Cannot set a timeout: ") + std::strerror(-r));
    }
    request.timeout.reset(timeout);
    request.ticket = loop_.tap().request(
        1,
        [this, id](std::vector<TappedPair>&& pairs) {
            inbox_.post([this, id, tapped = std::move(pairs.front())] { complete(id, tapped); });
        },
        true);
}

void SnapshotRequests::failAll(const char* errorName, const std::string& message) {
    while (!requests_.empty())
        fail(requests_.begin()->first, errorName, message);
}

void SnapshotRequests::complete(std::uint64_t id, const TappedPair& tapped) {
    const auto it = requests_.find(id);
    if (it == requests_.end())
        return;
    cv::Mat image;
    render_(it->second.kind, tapped, image);
    const int r = writeAllWithin(it->second.fd.get(), encodePng(image), timeouts_.write);
    if (r < 0) {
        fail(id, SD_BUS_ERROR_IO_ERROR, std::string("Cannot write the PNG: ") + std::strerror(-r));
        return;
    }
    const SnapshotReply reply = std::move(it->second.reply);
    requests_.erase(it);
    reply.done();
}

void SnapshotRequests::fail(std::uint64_t id, const char* errorName, const std::string& message) {
    const auto it = requests_.find(id);
    if (it == requests_.end())
        return;
    loop_.tap().cancel(it->second.ticket);
    const SnapshotReply reply = std::move(it->second.reply);
    requests_.erase(it);
    reply.failed(errorName, message);
}

int SnapshotRequests::onTimeout(sd_event_source*, uint64_t, void* userdata) noexcept {
    auto* request = static_cast<Request*>(userdata);
    try {
        std::ostringstream message;
        message << "No camera frame pair arrived within "
                << std::chrono::duration<double>(request->owner->timeouts_.frame).count() << " s";
        request->owner->fail(request->id, bus::kErrorNoCamera, message.str());
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    return 0;
}

}  // namespace everytouch::service
