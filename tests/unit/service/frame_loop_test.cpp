#include "service/frame_loop.h"

#include <condition_variable>
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
        lastWasEmpty_ = contacts.empty();
    }
    std::vector<std::uint64_t> indices() const {
        std::lock_guard lock(mutex_);
        return indices_;
    }
    bool lastWasEmpty() const {
        std::lock_guard lock(mutex_);
        return lastWasEmpty_;
    }

private:
    std::chrono::milliseconds delay_;
    mutable std::mutex mutex_;
    std::vector<std::uint64_t> indices_;
    bool lastWasEmpty_ = false;
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

class FrameLoopTest : public ::testing::Test {
protected:
    void SetUp() override { test::writeCodedRecording(dir_ / "recording", test::smallRig(), 20, 8333); }

    test::TempDir dir_;
    Notifications notifications_;
};

TEST_F(FrameLoopTest, RunsToTheEndOfTheStreamAndReleasesTheContacts) {
    io::ReplaySource source(dir_ / "recording", false);
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, {&sink}, nullptr, options, PipelineSettings{}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    const LoopStatistics statistics = loop.statistics();
    EXPECT_EQ(statistics.frames, 20u);
    EXPECT_EQ(statistics.pairs, 19u);
    EXPECT_EQ(statistics.dropped, 0u);
    EXPECT_FALSE(loop.failure());
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
    FrameLoop loop(source, {&sink}, nullptr, options, PipelineSettings{}, notifications_.callback());
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
    FrameLoop loop(source, {&slowSink}, nullptr, options, PipelineSettings{}, notifications_.callback());
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    const LoopStatistics statistics = loop.statistics();
    EXPECT_EQ(statistics.frames, 20u);
    EXPECT_GT(statistics.dropped, 0u);
    EXPECT_LT(statistics.pairs, 19u);
}

TEST_F(FrameLoopTest, TheTapDeliversCopiesOfTheNextPairs) {
    io::ReplaySource source(dir_ / "recording", false);
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, {}, nullptr, options, PipelineSettings{}, notifications_.callback());
    std::mutex mutex;
    std::vector<core::FramePair> captured;
    loop.tap().request(3, [&](std::vector<core::FramePair>&& pairs) {
        std::lock_guard lock(mutex);
        captured = std::move(pairs);
    });
    loop.start();
    ASSERT_TRUE(notifications_.waitUntil([&] { return loop.finished(); }, 30s));
    std::lock_guard lock(mutex);
    ASSERT_EQ(captured.size(), 3u);
    for (std::size_t i = 0; i < captured.size(); ++i)
        EXPECT_EQ(captured[i].latest().index, i + 1);
    const test::CodedImages images = test::codedImages(test::smallRig().calibration.cameraSize, 10);
    EXPECT_EQ(cv::norm(captured[0].positive.image, images.positive, cv::NORM_INF), 0.0);
}

TEST_F(FrameLoopTest, ACameraFailureEndsTheLoopWithTheReason) {
    io::ReplaySource source(dir_ / "recording", false);
    std::filesystem::remove(io::Recording::framePath(dir_ / "recording", 5));
    CollectingSink sink;
    LoopOptions options;
    options.overflow = FrameQueue::Overflow::Block;
    FrameLoop loop(source, {&sink}, nullptr, options, PipelineSettings{}, notifications_.callback());
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
