#include "service/calibration_runner.h"

#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_rig.h"

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

constexpr std::size_t kQueueFrames = 4;

// Offers numbered frame pairs to a tap, as the pipeline thread does, one every millisecond: pair n has
// latest().index == n, and offered() is n once it has been offered.
class PairFeeder {
public:
    explicit PairFeeder(FrameTap& tap)
        : thread_([this, &tap] {
              for (std::uint64_t n = 1; !stopping_; ++n) {
                  core::FramePair pair;
                  pair.positive.index = n - 1;
                  pair.negative.index = n;
                  tap.offer(pair, nullptr);
                  offered_ = n;
                  std::this_thread::sleep_for(1ms);
              }
          }) {}
    ~PairFeeder() {
        stopping_ = true;
        thread_.join();
    }

    std::uint64_t offered() const { return offered_; }

private:
    std::atomic<bool> stopping_{false};
    std::atomic<std::uint64_t> offered_{0};
    std::thread thread_;
};

// Remembers what the job asked of the projector, and how many pairs had been offered when it last showed.
class RecordingProjector final : public io::ProjectorOutput {
public:
    explicit RecordingProjector(const PairFeeder* feeder = nullptr) : feeder_(feeder) {}

    void show(const cv::Mat&) override {
        ++shows;
        if (feeder_)
            offeredAtShow = feeder_->offered();
    }
    void release() noexcept override { ++releases; }
    void setDisplayToProjector(cv::Size, const Eigen::Matrix3d&) override { ++keystones; }
    cv::Size size() const override { return {64, 48}; }
    std::string describe() const override { return "a test projector"; }

    std::atomic<int> shows{0};
    std::atomic<int> releases{0};
    std::atomic<int> keystones{0};
    std::atomic<std::uint64_t> offeredAtShow{0};

private:
    const PairFeeder* feeder_;
};

// What a job reported, collected from its thread.
class Report {
public:
    ProgressFunction progress() {
        return [this](const std::string& step, double fraction, const std::string& message) {
            std::lock_guard lock(mutex_);
            messages_.push_back(step + " " + std::to_string(fraction) + " " + message);
        };
    }
    // Also notes how often the projector had been released when the job finished.
    FinishFunction finished(const RecordingProjector* projector = nullptr) {
        return [this, projector](const CalibrationOutcome& outcome) {
            releasesAtFinish_ = projector ? projector->releases.load() : 0;
            outcome_.set_value(outcome);
        };
    }
    CalibrationOutcome outcome() {
        std::future<CalibrationOutcome> future = outcome_.get_future();
        if (future.wait_for(30s) != std::future_status::ready)
            throw std::runtime_error("the job did not finish");
        return future.get();
    }
    std::vector<std::string> messages() {
        std::lock_guard lock(mutex_);
        return messages_;
    }
    int releasesAtFinish() const { return releasesAtFinish_; }

private:
    std::mutex mutex_;
    std::vector<std::string> messages_;
    std::promise<CalibrationOutcome> outcome_;
    std::atomic<int> releasesAtFinish_{-1};
};

// A step that shows a white image, then captures `pairs` pairs and notes the newer frame of the first.
CalibrationStep capturingStep(std::size_t pairs, std::atomic<std::uint64_t>& firstCaptured) {
    return {"table", "the test step", [pairs, &firstCaptured](const StepContext& context) -> EstimateResult {
                context.show(cv::Mat(context.projectorSize, CV_8UC1, cv::Scalar(255)));
                const std::optional<std::vector<core::FramePair>> captured = context.capture(pairs);
                if (!captured)
                    return core::Failure{"no frames"};
                firstCaptured = captured->front().latest().index;
                return Estimate{test::paperLikeCalibration(), 0.25, cv::Mat()};
            }};
}

CalibrationJob jobOf(std::vector<CalibrationStep> steps) {
    return CalibrationJob{std::move(steps), CalibrationOptions(), std::nullopt, cv::Size(64, 48)};
}

TEST(CalibrationRunner, ShowsTheImageSkipsThePairsThatPredateItAndGivesTheProjectorBack) {
    FrameTap tap;
    PairFeeder feeder(tap);
    RecordingProjector projector(&feeder);
    Report report;
    std::atomic<std::uint64_t> firstCaptured{0};
    CalibrationRunner runner(tap, &projector, kQueueFrames, jobOf({capturingStep(3, firstCaptured)}),
                             report.progress(), report.finished(&projector));
    const CalibrationOutcome outcome = report.outcome();

    EXPECT_TRUE(outcome.ok) << outcome.message;
    ASSERT_TRUE(outcome.calibration);
    EXPECT_DOUBLE_EQ(outcome.rmsPx, 0.25);
    EXPECT_EQ(projector.shows, 1);
    EXPECT_EQ(report.releasesAtFinish(), 1);
    // The keystone changes when the daemon makes the outcome active, not before.
    EXPECT_EQ(projector.keystones, 0);
    // The queue's worth of pairs and two more after the image changed may predate it: the step never sees
    // them.
    EXPECT_GT(firstCaptured.load(), projector.offeredAtShow + kQueueFrames + 2);
    EXPECT_THAT(report.messages(), ::testing::Contains(HasSubstr("table 1.000000 Done with the test step")));
}

TEST(CalibrationRunner, WithoutAProjectorOutputTheStepsStillRun) {
    FrameTap tap;
    PairFeeder feeder(tap);
    Report report;
    std::atomic<std::uint64_t> firstCaptured{0};
    CalibrationRunner runner(tap, nullptr, kQueueFrames, jobOf({capturingStep(2, firstCaptured)}),
                             report.progress(), report.finished());
    const CalibrationOutcome outcome = report.outcome();
    EXPECT_TRUE(outcome.ok) << outcome.message;
    EXPECT_GT(firstCaptured.load(), 0u);
}

TEST(CalibrationRunner, DestroyingItCancelsAJobWaitingForFrames) {
    FrameTap tap;  // nobody offers pairs
    RecordingProjector projector;
    Report report;
    std::atomic<std::uint64_t> firstCaptured{0};
    std::optional<CalibrationRunner> runner;
    runner.emplace(tap, &projector, kQueueFrames, jobOf({capturingStep(3, firstCaptured)}), report.progress(),
                   report.finished(&projector));
    std::this_thread::sleep_for(50ms);
    const auto begun = std::chrono::steady_clock::now();
    runner.reset();
    // A capture gives up within its polling interval, far below its own timeout of several seconds.
    EXPECT_LT(std::chrono::steady_clock::now() - begun, 1s);

    const CalibrationOutcome outcome = report.outcome();
    EXPECT_FALSE(outcome.ok);
    EXPECT_FALSE(outcome.calibration);
    EXPECT_EQ(outcome.message, "the table step failed: no frames");
    EXPECT_EQ(report.releasesAtFinish(), 1);
}

TEST(CalibrationRunner, AStepThatThrowsEndsTheJobWithTheReasonAndGivesTheProjectorBack) {
    FrameTap tap;
    PairFeeder feeder(tap);
    RecordingProjector projector(&feeder);
    Report report;
    const CalibrationStep throwing{"table", "the test step",
                                   [](const StepContext& context) -> EstimateResult {
                                       context.show(cv::Mat(context.projectorSize, CV_8UC1, cv::Scalar(255)));
                                       throw std::runtime_error("the projector went dark");
                                   }};
    CalibrationRunner runner(tap, &projector, kQueueFrames, jobOf({throwing}), report.progress(),
                             report.finished(&projector));
    const CalibrationOutcome outcome = report.outcome();
    EXPECT_FALSE(outcome.ok);
    EXPECT_EQ(outcome.message, "the projector went dark");
    EXPECT_EQ(report.releasesAtFinish(), 1);
}

}  // namespace
}  // namespace everytouch::service
