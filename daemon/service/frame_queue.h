#pragma once

#include <chrono>
#include <cstdint>

#include "core/frame.h"
#include "service/bounded_queue.h"

namespace everytouch::service {

// A camera frame and the moment the daemon received it (for the latency it reports).
struct QueuedFrame {
    core::Frame frame;
    std::chrono::steady_clock::time_point arrival;
    // No frame: the source lost its camera after the frames before this one, for the `sourceLost`th time
    // (counted from 1; 0 for a frame). Nothing they showed holds.
    std::uint64_t sourceLost = 0;
};

// Hands camera frames from the camera thread to the pipeline thread.
using FrameQueue = BoundedQueue<QueuedFrame>;

}  // namespace everytouch::service
