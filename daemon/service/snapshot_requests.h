#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include <systemd/sd-event.h>
#include <opencv2/core/mat.hpp>

#include "core/frame.h"
#include "io/handles.h"
#include "service/descriptor_writer.h"
#include "service/frame_loop.h"
#include "service/main_loop_inbox.h"
#include "service/snapshot.h"

namespace everytouch::service {

// Draws `kind` of a pair and what detection made of it into `image` (8-bit) for a snapshot. Runs on the main
// thread.
using SnapshotRenderer = std::function<void(SnapshotKind kind, const TappedPair& tapped, cv::Mat& image)>;

// How one Snapshot call is answered. Both run on the main thread; exactly one of them runs, once.
struct SnapshotReply {
    std::function<void()> done;  // the PNG has been written
    std::function<void(const char* errorName, const std::string& message)> failed;
};

struct SnapshotTimeouts {
    // A request fails with NoCamera when no frame pair arrives within this time.
    std::chrono::milliseconds frame{3000};
    // How long the receiving end of a descriptor may take to accept the PNG; it is written while the main
    // loop goes on, and a client that never reads gets an error after this time.
    std::chrono::milliseconds write{3000};
    // A request whose pair has not come within `frame` waits on while detection works on a pair (the first
    // pair of a new calibration prepares it: a few tenths of a second, seconds on a slow machine), up to this
    // much longer.
    std::chrono::milliseconds busy{30000};
};

// The Snapshot calls waiting for a frame pair: each keeps its own descriptor for the caller's and a timeout,
// asks the frame loop's tap for the next pair, and once it arrives has it rendered, writes it to the
// descriptor as a PNG without blocking the main loop (DescriptorWriter) and answers the call. Main thread
// only.
class SnapshotRequests {
public:
    // Requests held at once, each with its caller's descriptor: a client that floods the daemon with
    // snapshots gets Busy beyond these instead of using up the daemon's descriptors and main thread.
    static constexpr std::size_t kMostPending = 8;

    // `event` runs the timeouts; `inbox` brings the pairs from the pipeline thread to the main thread. All
    // three must outlive the requests, and no task the inbox holds may run once they are gone.
    SnapshotRequests(sd_event* event, FrameLoop& loop, MainLoopInbox& inbox, SnapshotRenderer render,
                     SnapshotTimeouts timeouts = {});
    SnapshotRequests(const SnapshotRequests&) = delete;
    SnapshotRequests& operator=(const SnapshotRequests&) = delete;

    // Takes a request for `kind` of the next pair, to be written to `fd`, which stays the caller's. Throws
    // BusError when the descriptor is not open for writing or cannot be kept, the camera delivers no frames,
    // or kMostPending requests are waiting (Busy).
    void add(SnapshotKind kind, int fd, SnapshotReply reply);
    // Answers every pending request with this error.
    void failAll(const char* errorName, const std::string& message);
    std::size_t pending() const { return requests_.size(); }

private:
    struct Request {
        SnapshotRequests* owner = nullptr;
        std::uint64_t id = 0;
        SnapshotReply reply;
        DescriptorWriter writer;
        bool writing = false;  // the pair came; the timeout is now the write's
        std::chrono::steady_clock::time_point asked;
        SnapshotKind kind = SnapshotKind::Camera;
        FrameTap::Ticket ticket = 0;
        io::EventSource timeout;
    };

    void complete(std::uint64_t id, const TappedPair& tapped);
    void written(std::uint64_t id, int result);
    void fail(std::uint64_t id, const char* errorName, const std::string& message);
    static int onTimeout(sd_event_source* source, uint64_t usec, void* userdata) noexcept;

    sd_event* event_;
    FrameLoop& loop_;
    MainLoopInbox& inbox_;
    SnapshotRenderer render_;
    SnapshotTimeouts timeouts_;
    std::map<std::uint64_t, Request> requests_;
    std::uint64_t nextId_ = 1;
};

}  // namespace everytouch::service
