#include "service/calibration_runner.h"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>

#include "io/thread_name.h"

namespace everytouch::service {

namespace {

using Clock = std::chrono::steady_clock;

// How long a calibration step waits for its frame pairs: a fixed allowance plus a generous time per pair.
std::chrono::milliseconds captureTimeout(std::size_t pairs) {
    return std::chrono::milliseconds(5000 + 100 * static_cast<long>(pairs));
}

}  // namespace

CalibrationRunner::CalibrationRunner(FrameTap& tap, io::ProjectorOutput* projector, std::size_t queueFrames,
                                     CalibrationJob job, ProgressFunction progress, FinishFunction finished)
    : tap_(tap),
      projector_(projector),
      queueFrames_(queueFrames),
      job_(std::move(job)),
      progress_(std::move(progress)),
      finished_(std::move(finished)),
      thread_([this] {
          io::nameThisThread("et-calibration");
          run();
      }) {}

CalibrationRunner::~CalibrationRunner() {
    cancelled_ = true;
    thread_.join();
}

std::optional<std::vector<core::FramePair>> CalibrationRunner::capture(std::size_t pairs) {
    struct Handover {
        std::mutex mutex;
        std::condition_variable arrived;
        std::optional<std::vector<core::FramePair>> pairs;
    };
    auto handover = std::make_shared<Handover>();
    const FrameTap::Ticket ticket = tap_.request(pairs, [handover](std::vector<TappedPair>&& captured) {
        std::vector<core::FramePair> framePairs;
        framePairs.reserve(captured.size());
        for (TappedPair& tapped : captured)
            framePairs.push_back(std::move(tapped.pair));
        std::lock_guard lock(handover->mutex);
        handover->pairs = std::move(framePairs);
        handover->arrived.notify_all();
    });
    const auto deadline = Clock::now() + captureTimeout(pairs);
    std::unique_lock lock(handover->mutex);
    while (!handover->pairs && !cancelled_ && Clock::now() < deadline)
        handover->arrived.wait_for(lock, std::chrono::milliseconds(100));
    if (handover->pairs)
        return std::move(handover->pairs);
    // Cancelling waits for a delivery under way, which needs the handover's lock; what it delivered is used.
    lock.unlock();
    tap_.cancel(ticket);
    lock.lock();
    return std::move(handover->pairs);
}

void CalibrationRunner::run() {
    const CaptureFunction capture = [this](std::size_t pairs) { return this->capture(pairs); };
    CalibrationOutcome outcome;
    try {
        // Whatever ends the job, the desktop comes back when the lease goes.
        io::ProjectorLease lease(projector_);
        const ShowFunction show = [this, &lease](const cv::Mat& projectorImage) {
            if (!projector_)
                return;
            lease.show(projectorImage);
            // Frames exposed before the image changed may still be queued, and one may be under way.
            this->capture(queueFrames_ + 2);
        };
        outcome = runCalibration(job_.steps, job_.options, job_.start, job_.projectorSize, capture, show,
                                 progress_);
    } catch (const std::exception& error) {
        outcome.message = error.what();
    }
    finished_(outcome);
}

}  // namespace everytouch::service
