#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/contact.h"
#include "core/frame.h"
#include "io/recording.h"
#include "service/bounded_queue.h"
#include "service/frame_pool.h"

namespace everytouch::service {

// Writes a recording on a thread of its own, so that encoding and writing frames never holds up the camera
// thread. With QueueOverflow::DropOldest (a live camera, which cannot wait) the frames that find the queue
// full are left out of the recording and counted: the recording has a gap there, which a replay pairs
// across as it does a dropped frame. With QueueOverflow::Block (the simulator, a replay) the camera thread
// waits instead, and the recording is whole.
class RecordingThread {
public:
    // `images`: where a frame's image goes once written, for the camera to fill again. `stopped` runs on the
    // recording thread when a write fails; the writer then takes nothing more and keeps the frames complete
    // on the disk. Starts the thread.
    RecordingThread(io::RecordingWriter& writer, std::size_t capacity, QueueOverflow overflow,
                    FramePool& images, std::function<void(const std::string& problem)> stopped);
    // finish()
    ~RecordingThread();
    RecordingThread(const RecordingThread&) = delete;
    RecordingThread& operator=(const RecordingThread&) = delete;

    // Queues the frame (its image shared, not copied: a camera fills a new buffer for each frame) and a
    // copy of the truth's mask, which the simulator draws again for the next frame.
    void add(const core::Frame& frame, const std::optional<std::vector<core::FingerTruth>>& truth,
             const std::optional<cv::Mat>& mask);
    // Writes what is queued, puts the recording's tables on the disk and ends the thread; once.
    void finish();
    // Frames left out of the recording because the writer could not keep up.
    std::uint64_t dropped() const { return queue_.dropped(); }

private:
    struct Item {
        core::Frame frame;
        std::optional<std::vector<core::FingerTruth>> truth;
        cv::Mat mask;  // empty without one
    };

    void run();
    // Writes one item unless the writer stopped; a failure stops it.
    void write(Item& item);

    io::RecordingWriter& writer_;
    FramePool& images_;
    FramePool masks_;
    std::function<void(const std::string&)> stopped_;
    BoundedQueue<Item> queue_;
    std::thread thread_;
};

}  // namespace everytouch::service
