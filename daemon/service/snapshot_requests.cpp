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
    if (requests_.size() >= kMostPending)
        throw BusError(bus::kErrorBusy,
                       std::to_string(kMostPending) +
                           " snapshots are being taken already; ask again once they are answered");
    const std::uint64_t id = nextId_++;
    Request& request = requests_[id];
    if (const int r = request.writer.adopt(fd); r < 0) {
        requests_.erase(id);
        throw BusError(SD_BUS_ERROR_FAILED,
                       std::string("Cannot keep the file descriptor: ") + std::strerror(-r));
    }
    request.owner = this;
    request.id = id;
    request.reply = std::move(reply);
    request.kind = kind;
    request.asked = std::chrono::steady_clock::now();
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
    Request& request = it->second;
    cv::Mat image;
    render_(request.kind, tapped, image);
    request.writing = true;
    const auto writeUsec = std::chrono::duration_cast<std::chrono::microseconds>(timeouts_.write).count();
    int r = sd_event_source_set_time_relative(request.timeout.get(), static_cast<std::uint64_t>(writeUsec));
    if (r >= 0)
        r = sd_event_source_set_enabled(request.timeout.get(), SD_EVENT_ONESHOT);
    if (r >= 0)
        r = request.writer.start(event_, encodePng(image), [this, id](int result) { written(id, result); });
    if (r < 0)
        fail(id, SD_BUS_ERROR_IO_ERROR, std::string("Cannot write the PNG: ") + std::strerror(-r));
}

void SnapshotRequests::written(std::uint64_t id, int result) {
    if (result < 0) {
        fail(id, SD_BUS_ERROR_IO_ERROR, std::string("Cannot write the PNG: ") + std::strerror(-result));
        return;
    }
    const auto it = requests_.find(id);
    if (it == requests_.end())
        return;
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

int SnapshotRequests::onTimeout(sd_event_source* source, uint64_t, void* userdata) noexcept {
    auto* request = static_cast<Request*>(userdata);
    try {
        const SnapshotTimeouts& timeouts = request->owner->timeouts_;
        std::ostringstream message;
        if (request->writing) {
            message << "The reader did not take the PNG within "
                    << std::chrono::duration<double>(timeouts.write).count() << " s";
            request->owner->fail(request->id, SD_BUS_ERROR_IO_ERROR, message.str());
        } else if (!request->owner->loop_.processing()) {
            message << "No camera frame pair arrived within "
                    << std::chrono::duration<double>(timeouts.frame).count() << " s";
            request->owner->fail(request->id, bus::kErrorNoCamera, message.str());
        } else if (std::chrono::steady_clock::now() - request->asked < timeouts.frame + timeouts.busy) {
            const auto waitUsec =
                std::chrono::duration_cast<std::chrono::microseconds>(timeouts.frame).count();
            int r = sd_event_source_set_time_relative(source, static_cast<std::uint64_t>(waitUsec));
            if (r >= 0)
                r = sd_event_source_set_enabled(source, SD_EVENT_ONESHOT);
            if (r < 0)
                request->owner->fail(request->id, SD_BUS_ERROR_FAILED,
                                     std::string("Cannot set a timeout: ") + std::strerror(-r));
        } else {
            message << "Detection has been working on one frame pair for more than "
                    << std::chrono::duration<double>(timeouts.busy).count() << " s";
            request->owner->fail(request->id, bus::kErrorBusy, message.str());
        }
    } catch (const std::exception& error) {
        ET_LOG(Error) << "internal error: " << error.what();
    }
    return 0;
}

}  // namespace everytouch::service
