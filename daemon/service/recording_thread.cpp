#include "service/recording_thread.h"

#include <chrono>
#include <exception>
#include <utility>

#include "io/thread_name.h"

namespace everytouch::service {

RecordingThread::RecordingThread(io::RecordingWriter& writer, std::size_t capacity, QueueOverflow overflow,
                                 FramePool& images, std::function<void(const std::string& problem)> stopped)
    : writer_(writer),
      images_(images),
      masks_(capacity + 1),
      stopped_(std::move(stopped)),
      queue_(capacity, overflow),
      thread_([this] {
          io::nameThisThread("et-recording");
          run();
      }) {}

RecordingThread::~RecordingThread() {
    finish();
}

void RecordingThread::add(const core::Frame& frame,
                          const std::optional<std::vector<core::FingerTruth>>& truth,
                          const std::optional<cv::Mat>& mask) {
    // Queued even after a write failed: the writer is the recording thread's alone, which drops the item.
    Item item{frame, truth, {}};
    if (mask) {
        item.mask = masks_.take();
        mask->copyTo(item.mask);
    }
    queue_.push(std::move(item));
}

void RecordingThread::finish() {
    queue_.close();
    if (thread_.joinable())
        thread_.join();
}

void RecordingThread::run() {
    Item item;
    // The queue delivers what it holds after close(), then says Closed.
    for (;;) {
        const QueuePop result = queue_.pop(item, std::chrono::milliseconds(100));
        if (result == QueuePop::Closed)
            break;
        if (result == QueuePop::Item)
            write(item);
    }
    if (writer_.stopped())
        return;
    try {
        writer_.flush();
    } catch (const std::exception& error) {
        stopped_(error.what());
    }
}

void RecordingThread::write(Item& item) {
    if (!writer_.stopped()) {
        try {
            writer_.addFrame(item.frame);
            if (item.truth)
                writer_.addTruth(*item.truth);
            if (!item.mask.empty())
                writer_.addMask(item.frame.index, item.mask);
        } catch (const std::exception& error) {
            stopped_(error.what());
        }
    }
    images_.giveBack(std::move(item.frame.image));
    masks_.giveBack(std::move(item.mask));
    item.frame.image.release();
    item.mask.release();
}

}  // namespace everytouch::service
