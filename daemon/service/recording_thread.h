#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
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

// Writes a recording on threads of its own, so that encoding and writing frames never holds up the camera
// thread. With QueueOverflow::DropOldest (a live camera, which cannot wait) the frames that find the queue
// full are left out of the recording and counted: the recording has a gap there, which a replay pairs
// across as it does a dropped frame. With QueueOverflow::Block (the simulator, a replay) the camera thread
// waits instead, and the recording is whole.
//
// Encoding a frame as PNG takes longer than a 120 Hz camera's frame period (11 ms for a 648 x 488 colour
// frame), so several encoder threads take frames from the queue in turn, and one writer puts them on the
// disk in the order they were taken.
class RecordingThread {
public:
    // One encoder per hardware thread, at most four.
    static int defaultEncoders();
    // Frame images the recording can hold at once, besides the one the caller is adding: those queued, those
    // being encoded or waiting for their turn to be written, and the one being written.
    static std::size_t imagesHeld(std::size_t capacity, int encoders);

    // `images`: where a frame's image goes once written, for the camera to fill again. `stopped` runs on the
    // writer's thread when a write fails; the writer then takes nothing more and keeps the frames complete
    // on the disk. Starts the threads. Throws std::invalid_argument for fewer than one encoder.
    RecordingThread(io::RecordingWriter& writer, std::size_t capacity, QueueOverflow overflow,
                    FramePool& images, std::function<void(const std::string& problem)> stopped,
                    int encoders = defaultEncoders());
    // finish()
    ~RecordingThread();
    RecordingThread(const RecordingThread&) = delete;
    RecordingThread& operator=(const RecordingThread&) = delete;

    // Queues the frame (its image shared, not copied: a camera fills a new buffer for each frame) and a
    // copy of the truth's mask, which the simulator draws again for the next frame. A mask the writer
    // refuses stops the recording, as a failed write does.
    void add(const core::Frame& frame, const std::optional<std::vector<core::FingerTruth>>& truth,
             const std::optional<cv::Mat>& mask);
    // Writes what is queued, puts the recording's tables on the disk and ends the threads; once.
    void finish();
    // Frames left out of the recording because the writer could not keep up.
    std::uint64_t dropped() const { return queue_.dropped(); }

private:
    struct Item {
        core::Frame frame;
        std::optional<std::vector<core::FingerTruth>> truth;
        cv::Mat mask;                     // empty without one
        std::uint64_t turn = 0;           // its place in the order the encoders took the queue's items
        std::vector<uchar> encodedImage;  // PNG; empty when encoding failed, and the writer tries again
        std::vector<uchar> encodedMask;
    };

    void encode();
    void writeInOrder();
    // Writes one item unless the writer stopped; a failure stops it.
    void write(Item& item);

    io::RecordingWriter& writer_;
    FramePool& images_;
    FramePool masks_;
    std::function<void(const std::string&)> stopped_;
    BoundedQueue<Item> queue_;

    std::mutex takeMutex_;  // one encoder takes from the queue at a time, so turns follow the queue's order
    std::uint64_t nextTurn_ = 0;

    std::mutex mutex_;  // guards what follows
    std::condition_variable changed_;
    // Items taken but not yet written, by turn modulo its size: at most that many are taken at once, so a
    // writer held up by the disk holds the encoders up too, and the camera's queue overflows as it should.
    std::vector<std::optional<Item>> encoded_;
    std::size_t taken_ = 0;  // items in encoding or in encoded_
    std::uint64_t nextWritten_ = 0;
    int encodersRunning_ = 0;

    std::vector<std::thread> encoders_;
    std::thread writerThread_;
};

}  // namespace everytouch::service
