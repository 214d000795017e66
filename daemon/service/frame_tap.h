#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <vector>

#include "core/frame.h"

namespace everytouch::service {

// Copies of the next frame pairs the pipeline forms, for whoever asks: a snapshot wants one, a calibration
// step several. The pipeline thread pays for a copy only while someone waits.
class FrameTap {
public:
    using Ticket = std::uint64_t;
    // Runs on the pipeline thread with the requested pairs; must be quick (hand them over and return).
    using Done = std::function<void(std::vector<core::FramePair>&&)>;

    // Asks for the next `pairs` pairs; `done` receives them.
    Ticket request(std::size_t pairs, Done done);
    // Withdraws a request; `done` will not run unless it already has.
    void cancel(Ticket ticket);

    // Pipeline thread: a new pair was formed.
    void offer(const core::FramePair& pair);

private:
    struct Pending {
        std::size_t wanted = 0;
        std::vector<core::FramePair> pairs;
        Done done;
    };

    std::atomic<bool> wanted_{false};  // any request pending; checked without the lock on every pair
    std::mutex mutex_;
    Ticket nextTicket_ = 1;
    std::map<Ticket, Pending> pending_;
};

}  // namespace everytouch::service
