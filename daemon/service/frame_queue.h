#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "core/frame.h"

namespace everytouch::service {

// A camera frame and the moment the daemon received it (for the latency it reports).
struct QueuedFrame {
    core::Frame frame;
    std::chrono::steady_clock::time_point arrival;
    // No frame: the source lost its camera after the frames before this one. Nothing they showed holds.
    bool sourceLost = false;
};

// Hands camera frames from the camera thread to the pipeline thread through a fixed ring of slots. A live
// camera cannot wait: when the ring is full the oldest frame is dropped and counted. A recording or the
// simulator can: with Overflow::Block the producer waits for a free slot instead.
class FrameQueue {
public:
    enum class Overflow { DropOldest, Block };
    enum class PopResult { Frame, Timeout, Closed };

    FrameQueue(std::size_t capacity, Overflow overflow);

    // False once the queue is closed (the frame is not queued).
    bool push(QueuedFrame&& frame);

    // Takes the oldest frame, waiting up to `timeout`. After close() the frames still queued are delivered
    // before Closed is reported.
    PopResult pop(QueuedFrame& frame, std::chrono::milliseconds timeout);

    // Ends the stream: push fails from now on and waiting producers and consumers wake up.
    void close();

    std::uint64_t dropped() const;

private:
    mutable std::mutex mutex_;
    std::condition_variable notEmpty_;
    std::condition_variable notFull_;
    std::vector<QueuedFrame> slots_;
    Overflow overflow_;
    std::size_t head_ = 0;  // the oldest frame
    std::size_t count_ = 0;
    std::uint64_t dropped_ = 0;
    bool closed_ = false;
};

}  // namespace everytouch::service
