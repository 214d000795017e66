#include "service/frame_loop.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/replay_source.h"
#include "support/coded_recording.h"
#include "support/temp_dir.h"

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

// Records what reaches it; `delay` makes it a slow stage.
class CollectingSink final : public io::TouchSink {
public:
    explicit CollectingSink(std::chrono::milliseconds delay = 0ms) : delay_(delay) {}
    void publish(std::uint64_t frameIndex, std::int64_t, const core::Contacts& contacts) override {
        std::this_thread::sleep_for(delay_);
        std::lock_guard lock(mutex_);
        indices_.push_back(frameIndex);
        if (!contacts.empty())
            touchedIn_.push_back(frameIndex);
        lastWasEmpty_ = contacts.empty();
    }
    std::vector<std::uint64_t> indices() const {
        std::lock_guard lock(mutex_);
        return indices_;
    }
    std::vector<std::uint64_t> touchedIn() const {
        std::lock_guard lock(mutex_);
        return touchedIn_;
    }
    bool lastWasEmpty() const {
        std::lock_guard lock(mutex_);
        return lastWasEmpty_;
    }

private:
    std::chrono::milliseconds delay_;
    mutable std::mutex mutex_;
    std::vector<std::uint64_t> indices_;
    std::vector<std::uint64_t> touchedIn_;
    bool lastWasEmpty_ = false;
};

// A pipeline whose result is scripted: from frame `touchFrom` on a finger touches; on frame `failOn` a stage
// throws. It sees every pair it gets.
class ScriptedPipeline final : public core::PairPipeline {
public:
    std::uint64_t touchFrom = 1000;
    std::uint64_t failOn = 1000;

    const core::PipelineResult& process(const core::FramePair& pair, const core::PipelineSettings&) override {
        const std::uint64_t index = pair.latest().index;
        processed.push_back(index);
        if (index == failOn)
            throw std::runtime_error("scripted failure");
        result_.frameIndex = index;
        result_.timestampUs = pair.latest().timestampUs;
        result_.detecting = true;
        result_.handMask = cv::Mat(pair.latest().image.size(), CV_8UC1, cv::Scalar(index));
        if (index >= touchFrom && result_.contacts.empty())
            result_.contacts.push_back(core::Contact{7, 10.0, 20.0, true, 0.0, false});
        return result_;
    }
    void reset() override {
        ++resets;
        result_.contacts.clear();
    }

    std::vector<std::uint64_t> processed;  // pipeline thread; read after the loop finished
    int resets = 0;

private:
    core::PipelineResult result_;
};

// What the main thread would be told.
class Notifications {
public:
    std::function<void()> callback() {
        return [this] {
            std::lock_guard lock(mutex_);
            ++count_;
            changed_.notify_all();
        };
    }
    bool waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
        std::unique_lock lock(mutex_);
        return changed_.wait_for(lock, timeout, condition);
    }

private:
    std::mutex mutex_;
    std::condition_variable changed_;
    int count_ = 0;
};

// A camera that loses every third frame on its way, as a loaded GigE link can, and counts what it lost.
class LossySource final : public io::FrameSource {
public:
    explicit LossySource(const std::filesystem::path& recording) : recording_(recording, false) {}

    std::optional<core::Frame> read(cv::Mat) override {
        while (std::optional<core::Frame> frame = recording_.next()) {
            if (frame->index % 3 != 2)
                return frame;
            ++lost_;
        }
        return std::nullopt;
    }
    std::optional<io::RigDescription> rig() const override { return recording_.rig(); }
    std::string describe() const override { return "a lossy " + recording_.describe(); }
    std::uint64_t droppedFrames() const override { return lost_.load(); }

private:
    io::ReplaySource recording_;
    std::atomic<std::uint64_t> lost_{0};
};

// A camera that goes away after frame 6 for two attempts to reach it, then comes back.
class AbsentForAWhileSource final : public io::FrameSource {
public:
    explicit AbsentForAWhileSource(const std::filesystem::path& recording) : recording_(recording, false) {}

    std::optional<core::Frame> read(cv::Mat) override {
        if (delivered_ == 7 && absences_ < 2) {
            ++absences_;
            throw io::SourceLost("the camera does not answer");
        }
        ++delivered_;
        return recording_.next();
    }
    std::optional<io::RigDescription> rig() const override { return recording_.rig(); }
    std::string describe() const override { return "an unreliable " + recording_.describe(); }

private:
    io::ReplaySource recording_;
    int delivered_ = 0;
    int absences_ = 0;
};

// A camera that stops delivering after frame 6, without an error, until `resume` is called.
class StallingSource final : public io::FrameSource {
public:
    explicit StallingSource(const std::filesystem::path& recording) : recording_(recording, false) {}

    std::optional<core::Frame> read(cv::Mat) override {
        if (delivered_++ == 7) {
            std::unique_lock lock(mutex_);
            resumed_.wait(lock, [this] { return resume_; });
        }
        return recording_.next();
    }
    std::optional<io::RigDescription> rig() const override { return recording_.rig(); }
    std::string describe() const override { return "a stalling " + recording_.describe(); }

    void resume() {
        std::lock_guard lock(mutex_);
        resume_ = true;
        resumed_.notify_all();
    }

private:
    io::ReplaySource recording_;
    int delivered_ = 0;
    std::mutex mutex_;
    std::condition_variable resumed_;
    bool resume_ = false;
};

// A camera that writes each frame into the memory it is offered, and counts how often that was.
class SpareWitnessSource final : public io::FrameSource {
public:
    explicit SpareWitnessSource(const std::filesystem::path& recording) : recording_(recording, false) {}

    std::optional<core::Frame> read(cv::Mat spare) override {
        std::optional<core::Frame> frame = recording_.next();
        if (frame && !spare.empty()) {
            const uchar* memory = spare.data;
            frame->image.copyTo(spare);
            offered_ += 1;
            written_ += spare.data == memory ? 1 : 0;
            frame->image = spare;
        }
        return frame;
    }
    std::optional<io::RigDescription> rig() const override { return recording_.rig(); }
    std::string describe() const override { return recording_.describe(); }
    int offered() const { return offered_; }
    int written() const { return written_; }

private:
    io::ReplaySource recording_;
    std::atomic<int> offered_{0};
    std::atomic<int> written_{0};
};

class FrameLoopTest : public ::testing::Test {
protected:
    void SetUp() override { test::writeCodedRecording(dir_ / "recording", test::smallRig(), 20, 8333); }

    // A loop on `source` run to the end of its stream, the camera waiting for the pipeline.
    std::unique_ptr<FrameLoop> runToTheEnd(io::FrameSource& source, CollectingSink& sink) {
        LoopOptions options;
        options.overflow = FrameQueue::Overflow::Block;
        auto loop =
            std::make_unique<FrameLoop>(source, pipeline_, std::vector<io::TouchSink*>{&sink}, nullptr,
                                        options, core::PipelineSettings{}, notifications_.callback());
        loop->start();
        EXPECT_TRUE(notifications_.waitUntil([&] { return loop->finished(); }, 30s));
        return loop;
    }

    test::TempDir dir_;
    Notifications notifications_;
    ScriptedPipeline pipeline_;
};

TEST_F(FrameLoopTest, RunsToTheEndOfTheStreamAndReleasesTheContacts) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink sink;
    const std::unique_ptr<FrameLoop> loop = runToTheEnd(source, sink);
    const LoopStatistics statistics = loop->statistics();
    EXPECT_EQ(statistics.frames, 20u);
    EXPECT_EQ(statistics.pairs, 19u);
    EXPECT_EQ(statistics.dropped, 0u);
    EXPECT_FALSE(loop->failure());
    const std::vector<std::uint64_t> indices = sink.indices();
    ASSERT_EQ(indices.size(), 20u);  // one per pair, then the release
    EXPECT_EQ(indices.back(), 19u);
    EXPECT_TRUE(sink.lastWasEmpty());
}

TEST_F(FrameLoopTest, StopsAfterMaxFrames) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink sink;
    LoopOptions options;
    options.maxFrames = 7;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    EXPECT_EQ(loop.statistics().frames, 7u);
    EXPECT_EQ(loop.statistics().pairs, 6u);
}

TEST_F(FrameLoopTest, ASlowPipelineDropsTheOldestFramesAndCountsThem) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink slowSink(20ms);
    LoopOptions options;
    options.queueCapacity = 2;
    FrameLoop loop(source, pipeline_, {&slowSink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    const LoopStatistics statistics = loop.statistics();
    EXPECT_EQ(statistics.frames, 20u);
    EXPECT_GT(statistics.dropped, 0u);
    EXPECT_LT(statistics.pairs, 19u);
}

TEST_F(FrameLoopTest, FramesTheSourceLostCountAsDropped) {
    LossySource source(dir_ / "recording");
    CollectingSink sink;
    const LoopStatistics statistics = runToTheEnd(source, sink)->statistics();
    EXPECT_EQ(statistics.frames, 14u);  // of 20
    EXPECT_EQ(statistics.dropped, 6u);
}

TEST_F(FrameLoopTest, ALostCameraReleasesEveryContactAndIsWaitedFor) {
    AbsentForAWhileSource source(dir_ / "recording");
    pipeline_.touchFrom = 2;
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.sourceLost().has_value(); }, 30s));
    EXPECT_EQ(*loop.sourceLost(), "the camera does not answer");
    // Its last frame's contact is gone (a report of no contact at frame 6) by the time the loss is told.
    const std::vector<std::uint64_t> indices = sink.indices();
    EXPECT_EQ(std::count(indices.begin(), indices.end(), 6u), 2);
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    EXPECT_FALSE(loop.failure());
    EXPECT_FALSE(loop.sourceLost());
    EXPECT_EQ(loop.statistics().frames, 20u);
    const std::vector<std::uint64_t> touched = sink.touchedIn();
    EXPECT_EQ(std::count(touched.begin(), touched.end(), 6u), 1);
    EXPECT_EQ(touched.back(), 19u);  // touching again once frames came back
}

TEST_F(FrameLoopTest, AStalledCameraReleasesEveryContactAndDetectionWaitsForItsFrames) {
    StallingSource source(dir_ / "recording");
    pipeline_.touchFrom = 2;
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    options.stallAfter = 50ms;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    const auto start = std::chrono::steady_clock::now();
    loop.start();
    // Frame 6's contact goes (a second report at frame 6, with no contact) while the camera says nothing.
    ASSERT_TRUE(notifications_.waitUntil(
        [&] {
            const std::vector<std::uint64_t> indices = sink.indices();
            return std::count(indices.begin(), indices.end(), 6u) == 2;
        },
        30s));
    EXPECT_GE(std::chrono::steady_clock::now() - start, 50ms);
    EXPECT_TRUE(sink.lastWasEmpty());
    EXPECT_FALSE(loop.detecting());
    EXPECT_THAT(loop.idleReason(), HasSubstr("the camera has delivered no frame for"));
    EXPECT_FALSE(loop.finished());
    source.resume();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    EXPECT_FALSE(loop.failure());
    EXPECT_EQ(loop.statistics().frames, 20u);
    const std::vector<std::uint64_t> touched = sink.touchedIn();
    EXPECT_EQ(std::count(touched.begin(), touched.end(), 6u), 1);
    EXPECT_EQ(touched.back(), 19u);  // detecting and touching again once frames came back
    EXPECT_EQ(std::count(touched.begin(), touched.end(), 7u), 0);  // frame 7 is only the first of a new pair
}

TEST_F(FrameLoopTest, TheCameraWritesFramesIntoTheMemoryOfFramesThePipelineIsDoneWith) {
    SpareWitnessSource source(dir_ / "recording");
    CollectingSink sink;
    EXPECT_EQ(runToTheEnd(source, sink)->statistics().pairs, 19u);
    // The first frames fill the queue before any pair is done with; from then on memory comes back.
    EXPECT_GE(source.offered(), 20 - static_cast<int>(LoopOptions{}.queueCapacity) - 3);
    EXPECT_EQ(source.written(), source.offered());
}

TEST_F(FrameLoopTest, TheTapDeliversCopiesOfTheNextPairs) {
    io::ReplaySource source(dir_ / "recording", false);
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, pipeline_, {}, nullptr, options, {}, notifications_.callback());
    std::mutex mutex;
    std::vector<TappedPair> captured;
    loop.tap().request(
        3,
        [&](std::vector<TappedPair>&& pairs) {
            std::lock_guard lock(mutex);
            captured = std::move(pairs);
        },
        true);
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    std::lock_guard lock(mutex);
    ASSERT_EQ(captured.size(), 3u);
    for (std::size_t i = 0; i < captured.size(); ++i) {
        EXPECT_EQ(captured[i].pair.latest().index, i + 1);
        // What the pipeline made of that very pair travels with it, copied.
        ASSERT_TRUE(captured[i].detection);
        EXPECT_EQ(captured[i].detection->frameIndex, i + 1);
        EXPECT_EQ(captured[i].detection->handMask.at<uchar>(0, 0), i + 1);
    }
    const test::CodedImages images = test::codedImages(test::smallRig().calibration.cameraSize, 10);
    EXPECT_EQ(cv::norm(captured[0].pair.positive.image, images.positive, cv::NORM_INF), 0.0);
}

TEST_F(FrameLoopTest, EveryNewFrameIsPairedAndItsContactsReachTheSinks) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    pipeline_.touchFrom = 5;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    std::vector<std::uint64_t> expected;
    for (std::uint64_t i = 1; i < 20; ++i)
        expected.push_back(i);
    EXPECT_EQ(pipeline_.processed, expected);
    const std::vector<std::uint64_t> touched = sink.touchedIn();
    ASSERT_FALSE(touched.empty());
    EXPECT_EQ(touched.front(), 5u);
    EXPECT_EQ(touched.size(), 15u);
    EXPECT_TRUE(sink.lastWasEmpty());  // the end of the stream releases the finger
    EXPECT_TRUE(loop.detecting());
    EXPECT_GT(loop.statistics().pipelineMedianMs, 0.0);
}

TEST_F(FrameLoopTest, AFailingStageReleasesEveryContactInThatFrameAndTheLoopGoesOn) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    pipeline_.touchFrom = 3;
    pipeline_.failOn = 9;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    const std::vector<std::uint64_t> touched = sink.touchedIn();
    EXPECT_EQ(std::count(touched.begin(), touched.end(), 9u), 0);   // released in the failing frame itself
    EXPECT_EQ(std::count(touched.begin(), touched.end(), 10u), 1);  // and found again afterwards
    EXPECT_FALSE(loop.failure());                                   // one bad pair does not end the loop
    EXPECT_EQ(loop.statistics().pipelineFailures, 1u);
    EXPECT_GE(pipeline_.resets, 1);
}

TEST_F(FrameLoopTest, ACameraFailureEndsTheLoopWithTheReason) {
    io::ReplaySource source(dir_ / "recording", false);
    std::filesystem::remove(io::Recording::framePath(dir_ / "recording", 5));
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, pipeline_, {&sink}, nullptr, options, {}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    ASSERT_TRUE(loop.failure());
    EXPECT_THAT(*loop.failure(), HasSubstr("camera: "));
    EXPECT_THAT(*loop.failure(), HasSubstr("000005"));
    EXPECT_EQ(loop.statistics().frames, 5u);
    EXPECT_TRUE(sink.lastWasEmpty());
}

}  // namespace
}  // namespace everytouch::service
