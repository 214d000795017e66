#include "service/recording_thread.h"

#include <algorithm>
#include <chrono>
#include <exception>
#include <stdexcept>
#include <utility>

#include "io/thread_name.h"

namespace everytouch::service {

namespace {

// Items an encoder may take ahead of the writer: enough that every encoder has one while the writer waits
// for the slowest.
std::size_t takenAtMost(int encoders) {
    return 2 * static_cast<std::size_t>(encoders);
}

}  // namespace

int RecordingThread::defaultEncoders() {
    return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
}

std::size_t RecordingThread::imagesHeld(std::size_t capacity, int encoders) {
    return capacity + takenAtMost(encoders) + 1;
}

RecordingThread::RecordingThread(io::RecordingWriter& writer, std::size_t capacity, QueueOverflow overflow,
                                 FramePool& images, std::function<void(const std::string& problem)> stopped,
                                 int encoders)
    : writer_(writer),
      images_(images),
      masks_(imagesHeld(capacity, std::max(encoders, 1)) + 1),
      stopped_(std::move(stopped)),
      queue_(capacity, overflow) {
    if (encoders < 1)
        throw std::invalid_argument("a recording needs at least one encoder, got " +
                                    std::to_string(encoders));
    encoded_.resize(takenAtMost(encoders));
    encodersRunning_ = encoders;
    for (int i = 0; i < encoders; ++i)
        encoders_.emplace_back([this] {
            io::nameThisThread("et-encoder");
            encode();
        });
    writerThread_ = std::thread([this] {
        io::nameThisThread("et-recording");
        writeInOrder();
    });
}

RecordingThread::~RecordingThread() {
    finish();
}

void RecordingThread::add(const core::Frame& frame,
                          const std::optional<std::vector<core::FingerTruth>>& truth,
                          const std::optional<cv::Mat>& mask) {
    // Queued even after a write failed: the writer is the writer thread's alone, which drops the item.
    Item item{frame, truth, {}, 0, {}, {}};
    if (mask) {
        item.mask = masks_.take();
        mask->copyTo(item.mask);
    }
    queue_.push(std::move(item));
}

void RecordingThread::finish() {
    queue_.close();
    for (std::thread& encoder : encoders_)
        if (encoder.joinable())
            encoder.join();
    if (writerThread_.joinable())
        writerThread_.join();
}

void RecordingThread::encode() {
    for (;;) {
        Item item;
        {
            std::lock_guard take(takeMutex_);
            {
                std::unique_lock lock(mutex_);
                changed_.wait(lock, [&] { return taken_ < encoded_.size(); });
            }
            // The queue delivers what it holds after close(), then says Closed.
            const QueuePop result = queue_.pop(item, std::chrono::milliseconds(100));
            if (result == QueuePop::Closed)
                break;
            if (result == QueuePop::Timeout)
                continue;
            item.turn = nextTurn_++;
            std::lock_guard lock(mutex_);
            ++taken_;
        }
        // Left empty where encoding fails or the writer refuses the mask: the writer then takes the image
        // itself, fails as here and stops the recording, naming the file.
        const auto encodeInto = [](const cv::Mat& image, std::vector<uchar>& png) {
            try {
                if (io::RecordingWriter::encodePng(image, png))
                    return;
            } catch (const std::exception&) {
            }
            png.clear();
        };
        encodeInto(item.frame.image, item.encodedImage);
        if (!item.mask.empty()) {
            try {
                writer_.checkMask(item.mask);
                encodeInto(item.mask, item.encodedMask);
            } catch (const std::exception&) {
                item.encodedMask.clear();
            }
        }
        {
            std::lock_guard lock(mutex_);
            encoded_[item.turn % encoded_.size()] = std::move(item);
        }
        changed_.notify_all();
    }
    {
        std::lock_guard lock(mutex_);
        --encodersRunning_;
    }
    changed_.notify_all();
}

void RecordingThread::writeInOrder() {
    for (;;) {
        Item item;
        {
            std::unique_lock lock(mutex_);
            std::optional<Item>& next = encoded_[nextWritten_ % encoded_.size()];
            changed_.wait(lock, [&] { return next.has_value() || (encodersRunning_ == 0 && taken_ == 0); });
            if (!next)
                break;
            item = std::move(*next);
            next.reset();
            ++nextWritten_;
            --taken_;
        }
        changed_.notify_all();
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
            if (item.encodedImage.empty())
                writer_.addFrame(item.frame);
            else
                writer_.addFrame(item.frame, item.encodedImage);
            if (item.truth)
                writer_.addTruth(*item.truth);
            if (!item.mask.empty()) {
                if (item.encodedMask.empty())
                    writer_.addMask(item.frame.index, item.mask);
                else
                    writer_.addMask(item.frame.index, item.encodedMask);
            }
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
