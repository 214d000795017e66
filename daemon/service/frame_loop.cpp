#include "service/frame_loop.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <utility>

#include "io/log.h"
#include "io/thread_name.h"

namespace everytouch::service {

namespace {

using Clock = std::chrono::steady_clock;

// The latency is smoothed with this time constant: long enough to be readable, short enough to follow a
// pipeline that slows down.
constexpr double kSmoothingSeconds = 1.0;
// The pipeline thread wakes at least this often, so its heartbeat shows it is alive while no frame comes.
constexpr std::chrono::milliseconds kPipelineWake{100};
// A camera slower than LoopOptions::stallAfter allows has stalled when silent for this many of its intervals.
constexpr int kStallIntervals = 8;
// A lost camera is asked again after this, then after twice as long each time, up to the most.
constexpr std::chrono::milliseconds kFirstReconnectWait{250};
constexpr std::chrono::milliseconds kMostReconnectWait{5000};
// Pipeline times kept for the median and the 99th percentile: a minute at 120 Hz.
constexpr std::size_t kPipelineSamples = 8192;

// The weight of one new sample when samples come at `perSecond`, so that a second's worth of them counts
// as much as everything before.
double smoothingWeight(double perSecond) {
    return perSecond > 0.0 ? 1.0 - std::exp(-1.0 / (perSecond * kSmoothingSeconds)) : 1.0;
}

}  // namespace

FrameLoop::FrameLoop(io::FrameSource& source, core::PairPipeline& pipeline, std::vector<io::TouchSink*> sinks,
                     io::RecordingWriter* recorder, LoopOptions options, core::PipelineSettings settings,
                     std::function<void()> notify, SettingsHook onSettings)
    : source_(source),
      pipeline_(pipeline),
      sinks_(std::move(sinks)),
      recorder_(recorder),
      options_(options),
      notify_(std::move(notify)),
      onSettings_(std::move(onSettings)),
      queue_(options.queueCapacity, options.overflow),
      // Every frame that can be held at once: those queued, the one paired with the next, one being filled,
      // and those waiting to be recorded.
      spareFrames_(
          options.queueCapacity + 2 +
          (recorder ? RecordingThread::imagesHeld(options.recordingCapacity, options.recordingEncoders) : 0)),
      settings_(std::move(settings)),
      pipelineMs_(kPipelineSamples, 0.0) {}

FrameLoop::~FrameLoop() {
    stop();
}

void FrameLoop::start() {
    {
        std::lock_guard lock(mutex_);
        started_ = Clock::now();
    }
    heartbeatNs_ = Clock::now().time_since_epoch().count();
    if (recorder_)
        recording_.emplace(
            *recorder_, options_.recordingCapacity, options_.overflow, spareFrames_,
            [this](const std::string& problem) { stopRecording(problem); }, options_.recordingEncoders);
    pipelineThread_ = std::thread([this] {
        io::nameThisThread("et-pipeline");
        runPipeline();
    });
    camera_ = std::thread([this] {
        io::nameThisThread("et-camera");
        runCamera();
    });
}

void FrameLoop::stop() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    stopRequested_.notify_all();
    queue_.close();
    if (camera_.joinable())
        camera_.join();
    if (recording_)
        recording_->finish();
    if (pipelineThread_.joinable())
        pipelineThread_.join();
}

void FrameLoop::fail(const std::string& problem) {
    std::lock_guard lock(mutex_);
    if (!failure_)
        failure_ = problem;
}

std::optional<std::string> FrameLoop::failure() const {
    std::lock_guard lock(mutex_);
    return failure_;
}

std::optional<std::string> FrameLoop::sourceLost() const {
    std::lock_guard lock(mutex_);
    return lossesReleased_ == losses_ ? sourceLost_ : std::nullopt;
}

bool FrameLoop::waitForLostSource(const std::string& reason, std::chrono::milliseconds& backOff) {
    std::unique_lock lock(mutex_);
    const bool first = !sourceLost_;
    sourceLost_ = reason;
    if (first) {
        const std::uint64_t loss = ++losses_;
        lock.unlock();
        ET_LOG(Error) << "camera: " << reason << "; every contact is released, and the camera is asked again "
                      << "until it answers";
        // After the frames already queued, so that their contacts go too; the loss is told once they have.
        QueuedFrame marker;
        marker.sourceLost = loss;
        queue_.push(std::move(marker));
        lock.lock();
    }
    stopRequested_.wait_for(lock, backOff, [this] { return stopping_.load(); });
    backOff = std::min(2 * backOff, kMostReconnectWait);
    return !stopping_;
}

void FrameLoop::sourceBack() {
    {
        std::lock_guard lock(mutex_);
        if (!sourceLost_)
            return;
        sourceLost_.reset();
    }
    ET_LOG(Notice) << "camera: frames come again";
    notify_();
}

std::string FrameLoop::idleReason() const {
    std::lock_guard lock(mutex_);
    return idleReason_;
}

LoopStatistics FrameLoop::statistics() const {
    std::lock_guard lock(mutex_);
    LoopStatistics statistics = statistics_;
    std::vector<double> times(
        pipelineMs_.begin(),
        pipelineMs_.begin() + static_cast<long>(std::min(pipelineSamples_, kPipelineSamples)));
    if (!times.empty()) {
        const auto at = [&times](double fraction) {
            const auto nth =
                times.begin() + static_cast<long>(fraction * static_cast<double>(times.size() - 1));
            std::nth_element(times.begin(), nth, times.end());
            return *nth;
        };
        statistics.pipelineMedianMs = at(0.5);
        statistics.pipelineP99Ms = at(0.99);
    }
    statistics.dropped = queue_.dropped() + source_.droppedFrames();
    if (recording_)
        statistics.recordingDropped = recording_->dropped();
    statistics.frameRate = arrivals_.perSecond(Clock::now());
    if (!finished_)
        statistics.seconds = std::chrono::duration<double>(Clock::now() - started_).count();
    return statistics;
}

core::Contacts FrameLoop::contacts(std::uint64_t& version) const {
    std::lock_guard lock(mutex_);
    version = contactsVersion_;
    return contacts_;
}

std::chrono::steady_clock::time_point FrameLoop::heartbeat() const {
    return Clock::time_point(Clock::duration(heartbeatNs_.load()));
}

std::optional<core::CalibrationCorrection> FrameLoop::takeCorrection() {
    std::lock_guard lock(mutex_);
    return std::exchange(correction_, std::nullopt);
}

std::string FrameLoop::calibrationProblem() const {
    std::lock_guard lock(mutex_);
    return calibrationProblem_;
}

void FrameLoop::setSettings(core::PipelineSettings settings) {
    std::lock_guard lock(mutex_);
    settings_ = std::move(settings);
    ++settingsVersion_;
    judged_ = false;  // what detection made of the last pair says nothing about the next one's settings
}

void FrameLoop::runCamera() {
    std::chrono::milliseconds backOff = kFirstReconnectWait;
    while (!stopping_) {
        {
            std::lock_guard lock(mutex_);
            if (options_.maxFrames != 0 && statistics_.frames >= options_.maxFrames)
                break;
        }
        QueuedFrame item;
        try {
            std::optional<core::Frame> frame = source_.next(spareFrames_.take());
            if (!frame)
                break;
            sourceBack();
            backOff = kFirstReconnectWait;
            item.frame = std::move(*frame);
            record(item.frame);
        } catch (const io::SourceLost& lost) {
            if (!waitForLostSource(lost.what(), backOff))
                break;
            continue;
        } catch (const std::exception& error) {
            fail(std::string("camera: ") + error.what());
            break;
        }
        item.arrival = Clock::now();
        {
            std::lock_guard lock(mutex_);
            arrivals_.add(item.arrival);
            ++statistics_.frames;
        }
        if (!queue_.push(std::move(item)))
            break;
    }
    if (recording_)
        recording_->finish();
    queue_.close();
}

void FrameLoop::record(const core::Frame& frame) {
    if (recording_)
        recording_->add(frame, source_.truth(), source_.truthMask());
}

void FrameLoop::stopRecording(const std::string& problem) {
    const std::string stopped = "the recording stopped: " + problem + "; it keeps the " +
                                std::to_string(recorder_->framesWritten()) +
                                " frames before, and detection goes on";
    ET_LOG(Error) << stopped;
    std::lock_guard lock(mutex_);
    statistics_.recordingStopped = stopped;
}

void FrameLoop::publish(std::uint64_t frameIndex, std::int64_t timestampUs, const core::Contacts& contacts) {
    for (io::TouchSink* sink : sinks_)
        sink->publish(frameIndex, timestampUs, contacts);
    bool changed = false;
    {
        std::lock_guard lock(mutex_);
        if (contacts != contacts_) {
            contacts_ = contacts;
            ++contactsVersion_;
            changed = true;
        }
    }
    if (changed)
        notify_();
}

void FrameLoop::recordPipelineTime(double ms) {
    std::lock_guard lock(mutex_);
    pipelineMs_[pipelineSamples_ % kPipelineSamples] = ms;
    ++pipelineSamples_;
}

void FrameLoop::processPair(const core::FramePair& pair, const core::PipelineSettings& settings) {
    const Clock::time_point start = Clock::now();
    const core::PipelineResult* result = nullptr;
    processing_ = true;
    try {
        result = &pipeline_.process(pair, settings);
        processing_ = false;
    } catch (const std::exception& error) {
        processing_ = false;
        // Every contact goes at once; the failure is told once, not for every pair while it lasts.
        pipeline_.reset();
        if (detecting_.exchange(false))
            notify_();
        {
            std::lock_guard lock(mutex_);
            ++statistics_.pipelineFailures;
            idleReason_ = std::string("detection failed: ") + error.what();
        }
        if (!failingNow_.exchange(true)) {
            ET_LOG(Error) << "detection failed on frame " << pair.latest().index << ": " << error.what()
                          << "; every contact is released until it works again";
            notify_();
        }
        tap_.offer(pair, nullptr);
        publish(pair.latest().index, pair.latest().timestampUs, core::Contacts{});
        return;
    }
    if (failingNow_.exchange(false)) {
        ET_LOG(Notice) << "detection works again from frame " << pair.latest().index;
        notify_();
    }
    recordPipelineTime(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    if (result->polaritySwaps != polaritySwaps_) {
        polaritySwaps_ = result->polaritySwaps;
        {
            std::lock_guard lock(mutex_);
            statistics_.polaritySwaps = polaritySwaps_;
        }
        ET_LOG(Notice) << "from frame " << pair.latest().index << " the camera's frames are taken the "
                       << (result->framesSwapped ? "other way round: " : "way they are labelled again: ")
                       << "the code's sign says which shows O + P";
    }
    const bool changed = detecting_ != result->detecting;
    {
        std::lock_guard lock(mutex_);
        if (changed || !result->detecting)
            idleReason_ = result->idleReason;
        statistics_.calibrationErrorPx =
            result->calibrationErrorPx.value_or(std::numeric_limits<double>::quiet_NaN());
        if (result->calibrationErrorPx &&
            !(*result->calibrationErrorPx <= statistics_.mostCalibrationErrorPx))
            statistics_.mostCalibrationErrorPx = *result->calibrationErrorPx;
    }
    if (result->correction || result->calibrationProblem != calibrationProblemSeen_) {
        if (result->calibrationProblem != calibrationProblemSeen_ && !result->calibrationProblem.empty())
            ET_LOG(Warning) << "calibration: " << result->calibrationProblem
                            << "; run \"everytouch-calib calibrate table\"";
        calibrationProblemSeen_ = result->calibrationProblem;
        {
            std::lock_guard lock(mutex_);
            if (result->correction)
                correction_ = result->correction;
            calibrationProblem_ = calibrationProblemSeen_;
        }
        notify_();
    }
    detecting_ = result->detecting;
    if (changed)
        notify_();
    tap_.offer(pair, result);
    publish(result->frameIndex, result->timestampUs, result->contacts);
}

void FrameLoop::stalled(Clock::duration silence) {
    const std::string reason =
        "the camera has delivered no frame for " +
        std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(silence).count()) + " ms";
    ET_LOG(Warning) << "camera: " << reason << "; every contact is released until frames come again";
    pipeline_.reset();
    pairer_.reset();
    {
        std::lock_guard lock(mutex_);
        idleReason_ = reason;
    }
    detecting_ = false;
    judged_ = true;
    notify_();
}

void FrameLoop::runPipeline() {
    QueuedFrame item;
    std::uint64_t lastIndex = 0;
    std::int64_t lastTimestampUs = 0;
    // The last frame's arrival, while the camera is watched for a stall (from its first frame on, not while
    // lost).
    Clock::time_point lastArrival{};
    Clock::duration typicalInterval{};  // between frames' arrivals, averaged over the last few
    bool watchingForStall = false;
    bool stalledNow = false;
    // A camera is stalled when it is silent for stallAfter, or for many of its own intervals when it is
    // slower than that (a simulated camera under a debugger or the sanitizers).
    const auto stallLimit = [&] {
        return std::max<Clock::duration>(*options_.stallAfter, kStallIntervals * typicalInterval);
    };
    core::PipelineSettings settings;
    std::uint64_t settingsVersion = ~std::uint64_t{0};
    const core::Contacts noContacts;
    try {
        while (!stopping_) {
            // Woken when the camera would count as stalled, so its contacts go as soon as it does.
            std::chrono::milliseconds wait = kPipelineWake;
            if (options_.stallAfter && watchingForStall && !stalledNow)
                wait = std::clamp(
                    std::chrono::ceil<std::chrono::milliseconds>(lastArrival + stallLimit() - Clock::now()),
                    std::chrono::milliseconds(1), kPipelineWake);
            const FrameQueue::PopResult result = queue_.pop(item, wait);
            const Clock::time_point now = Clock::now();
            heartbeatNs_ = now.time_since_epoch().count();
            if (result == FrameQueue::PopResult::Closed)
                break;
            if (result == FrameQueue::PopResult::Timeout && options_.stallAfter && watchingForStall &&
                !stalledNow && now - lastArrival >= stallLimit()) {
                stalledNow = true;
                stalled(now - lastArrival);
                publish(lastIndex, lastTimestampUs, noContacts);
            }
            if (result == FrameQueue::PopResult::Timeout || stopping_)
                continue;
            if (item.sourceLost != 0) {
                pipeline_.reset();
                pairer_.reset();
                publish(lastIndex, lastTimestampUs, noContacts);
                watchingForStall = false;  // a lost camera is not also a stalled one
                stalledNow = false;
                {
                    std::lock_guard lock(mutex_);
                    lossesReleased_ = item.sourceLost;
                }
                notify_();
                continue;
            }
            if (watchingForStall && !stalledNow) {
                const Clock::duration interval = item.arrival - lastArrival;
                typicalInterval = typicalInterval == Clock::duration::zero()
                                      ? interval
                                      : typicalInterval + (interval - typicalInterval) / 8;
            }
            if (stalledNow) {
                stalledNow = false;
                ET_LOG(Notice) << "camera: frames come again after "
                               << std::chrono::duration_cast<std::chrono::milliseconds>(item.arrival -
                                                                                        lastArrival)
                                      .count()
                               << " ms";
            }
            lastArrival = item.arrival;
            watchingForStall = true;
            lastIndex = item.frame.index;
            lastTimestampUs = item.frame.timestampUs;
            std::optional<core::FramePair> pair = pairer_.push(item.frame);
            if (!pair)
                continue;
            bool newSettings = false;
            {
                std::lock_guard lock(mutex_);
                ++statistics_.pairs;
                if (settingsVersion != settingsVersion_) {
                    settings = settings_;
                    settingsVersion = settingsVersion_;
                    newSettings = true;
                }
            }
            if (newSettings && onSettings_)
                onSettings_(settings);
            processPair(*pair, settings);
            // The older frame is paired no more; its memory takes a later frame.
            core::Frame& older =
                pair->positive.index < pair->negative.index ? pair->positive : pair->negative;
            spareFrames_.giveBack(std::move(older.image));
            {
                std::lock_guard lock(mutex_);
                judged_ = judged_ || settingsVersion == settingsVersion_;
            }
            const double latencyS = std::chrono::duration<double>(Clock::now() - item.arrival).count();
            std::lock_guard lock(mutex_);
            const double weight =
                statistics_.pairs == 1 ? 1.0 : smoothingWeight(arrivals_.perSecond(Clock::now()));
            statistics_.latencyMs += weight * (1e3 * latencyS - statistics_.latencyMs);
        }
    } catch (const std::exception& error) {
        fail(std::string("pipeline: ") + error.what());
    }
    try {
        pipeline_.reset();
        publish(lastIndex, lastTimestampUs, noContacts);
    } catch (const std::exception& error) {
        fail(std::string("releasing the contacts: ") + error.what());
    }
    {
        std::lock_guard lock(mutex_);
        statistics_.seconds = std::chrono::duration<double>(Clock::now() - started_).count();
    }
    finished_ = true;
    // A failed pipeline stops the camera too; a finished stream has already closed the queue.
    queue_.close();
    notify_();
}

}  // namespace everytouch::service
