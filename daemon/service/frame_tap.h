#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "core/frame.h"
#include "core/touch_pipeline.h"

namespace everytouch::service {

// A frame pair as the pipeline thread formed it, and what detection made of it.
struct TappedPair {
    core::FramePair pair;
    // The pipeline's result for the pair (its images, mask, fingertips and contacts), copied; nothing when
    // the pair did not reach the pipeline.
    std::shared_ptr<const core::PipelineResult> detection;
};

// Copies of the next frame pairs the pipeline forms, for whoever asks: a snapshot wants one, a calibration
// step several. The pipeline thread pays for a copy only while someone waits.
class FrameTap {
public:
    using Ticket = std::uint64_t;
    // Runs on the pipeline thread with the requested pairs; must be quick (hand them over and return).
    using Done = std::function<void(std::vector<TappedPair>&&)>;

    // Asks for the next `pairs` pairs; `done` receives them, with a copy of what detection made of each when
    // `withDetection` (a snapshot shows it; a calibration step needs only the frames).
    Ticket request(std::size_t pairs, Done done, bool withDetection = false);
    // Withdraws a request; `done` will not run unless it already has. When it is running on the pipeline
    // thread, waits until it has returned, so that what it uses may go once cancel returns (unless called
    // from that `done` itself).
    void cancel(Ticket ticket);

    // Pipeline thread: a new pair was formed and, unless `detection` is null, processed.
    void offer(const core::FramePair& pair, const core::PipelineResult* detection);

private:
    struct Pending {
        std::size_t wanted = 0;
        bool withDetection = false;
        std::vector<TappedPair> pairs;
        Done done;
    };

    std::atomic<bool> wanted_{false};  // any request pending; checked without the lock on every pair
    std::mutex mutex_;
    Ticket nextTicket_ = 1;
    std::map<Ticket, Pending> pending_;
    // The requests whose `done` runs now, outside the lock, on the thread delivering them.
    std::vector<Ticket> delivering_;
    std::thread::id deliveringThread_;
    std::condition_variable delivered_;
};

}  // namespace everytouch::service
