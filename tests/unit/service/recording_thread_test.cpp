#include "service/recording_thread.h"

#include <atomic>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "io/recording.h"
#include "support/coded_recording.h"
#include "support/temp_dir.h"

namespace everytouch::service {
namespace {

// Noise compresses badly: each frame takes the writer a while.
core::Frame noiseFrame(std::uint64_t index, const cv::Size& size) {
    core::Frame frame;
    frame.index = index;
    frame.timestampUs = static_cast<std::int64_t>(index) * 8333;
    frame.polarity = index % 2 == 0 ? core::Polarity::Positive : core::Polarity::Negative;
    frame.image.create(size, CV_8UC3);
    cv::randu(frame.image, 0, 256);
    return frame;
}

class RecordingThreadTest : public ::testing::Test {
protected:
    test::TempDir dir_;
    io::RigDescription rig_ = test::smallRig();
    FramePool images_{4};
    std::atomic<int> stops_{0};
    std::function<void(const std::string&)> onStop_ = [this](const std::string&) { ++stops_; };
};

TEST_F(RecordingThreadTest, ASourceThatCanWaitIsRecordedWholeWithItsTruthAndMasks) {
    io::RecordingWriter writer(dir_ / "rec", rig_, true, true);
    {
        RecordingThread recording(writer, 2, QueueOverflow::Block, images_, onStop_);
        cv::Mat mask(rig_.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
        for (std::uint64_t index = 0; index < 30; ++index) {
            // The simulator draws its mask again for every frame, in the same buffer.
            mask = cv::Scalar(0);
            mask.row(static_cast<int>(index)) = cv::Scalar(255);
            recording.add(noiseFrame(index, rig_.calibration.cameraSize),
                          std::vector<core::FingerTruth>{{index, 3, 1.0 * index, 2.0, 0.0}}, mask);
        }
        recording.finish();
        EXPECT_EQ(recording.dropped(), 0u);
    }
    EXPECT_EQ(stops_, 0);
    const io::Recording recorded = io::Recording::open(dir_ / "rec");
    ASSERT_EQ(recorded.frames().size(), 30u);
    ASSERT_EQ(recorded.truth().size(), 30u);
    ASSERT_TRUE(recorded.hasMasks());
    for (std::size_t position = 0; position < 30; ++position) {
        EXPECT_EQ(recorded.frames()[position].index, position);
        EXPECT_EQ(recorded.truth()[position].x, 1.0 * position);
        // Each frame's own mask, not the buffer as the last frame left it.
        const cv::Mat loaded = recorded.loadMask(position);
        EXPECT_EQ(cv::countNonZero(loaded.row(static_cast<int>(position))), loaded.cols);
        EXPECT_EQ(cv::countNonZero(loaded), loaded.cols);
    }
}

TEST_F(RecordingThreadTest, ACameraIsNotHeldUpByTheDiskButFramesLeftOutAreCounted) {
    io::RecordingWriter writer(dir_ / "rec", rig_, false);
    constexpr std::uint64_t kFrames = 200;
    std::uint64_t dropped = 0;
    {
        RecordingThread recording(writer, 1, QueueOverflow::DropOldest, images_, onStop_);
        // Far faster than frames can be encoded and written.
        for (std::uint64_t index = 0; index < kFrames; ++index)
            recording.add(noiseFrame(index, rig_.calibration.cameraSize), std::nullopt, std::nullopt);
        recording.finish();
        dropped = recording.dropped();
    }
    EXPECT_EQ(stops_, 0);
    EXPECT_GT(dropped, 0u);
    const io::Recording recorded = io::Recording::open(dir_ / "rec");
    EXPECT_EQ(recorded.frames().size() + dropped, kFrames);
    // What is recorded is in order, the last frame among it: a queue that is full drops its oldest frame.
    for (std::size_t position = 1; position < recorded.frames().size(); ++position)
        EXPECT_LT(recorded.frames()[position - 1].index, recorded.frames()[position].index);
    EXPECT_EQ(recorded.frames().back().index, kFrames - 1);
}

TEST_F(RecordingThreadTest, SeveralEncodersWriteEachFramesOwnImageInTheOrderTheyWereTaken) {
    io::RecordingWriter writer(dir_ / "rec", rig_, true, true);
    constexpr int kFrames = 24;
    std::vector<cv::Mat> given;
    {
        RecordingThread recording(writer, 4, QueueOverflow::Block, images_, onStop_, 3);
        cv::Mat mask(rig_.calibration.cameraSize, CV_8UC1);
        for (int index = 0; index < kFrames; ++index) {
            // Noise takes an encoder far longer than a flat frame, so later frames are encoded first.
            core::Frame frame = noiseFrame(static_cast<std::uint64_t>(index), rig_.calibration.cameraSize);
            if (index % 3 != 0)
                frame.image = cv::Scalar(index, 2 * index, 3 * index);
            given.push_back(frame.image.clone());
            mask = cv::Scalar(index % 2 == 0 ? 255 : 0);
            recording.add(
                frame, std::vector<core::FingerTruth>{{static_cast<std::uint64_t>(index), 1, 0, 0, 0}}, mask);
        }
        recording.finish();
        EXPECT_EQ(recording.dropped(), 0u);
    }
    EXPECT_EQ(stops_, 0);
    const io::Recording recorded = io::Recording::open(dir_ / "rec");
    ASSERT_EQ(recorded.frames().size(), static_cast<std::size_t>(kFrames));
    for (int position = 0; position < kFrames; ++position) {
        EXPECT_EQ(recorded.frames()[position].index, static_cast<std::uint64_t>(position));
        EXPECT_EQ(recorded.truth()[position].frameIndex, static_cast<std::uint64_t>(position));
        EXPECT_EQ(cv::norm(recorded.loadFrame(position).image, given[position], cv::NORM_INF), 0.0)
            << position;
        EXPECT_EQ(cv::countNonZero(recorded.loadMask(position)) > 0, position % 2 == 0) << position;
    }
}

TEST_F(RecordingThreadTest, AMaskTheWriterRefusesStopsTheRecordingAndKeepsTheFramesBefore) {
    io::RecordingWriter writer(dir_ / "rec", rig_, false, true);
    {
        RecordingThread recording(writer, 2, QueueOverflow::Block, images_, onStop_);
        const cv::Mat good(rig_.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
        const cv::Mat wrongSize(rig_.calibration.cameraSize.height + 1, rig_.calibration.cameraSize.width,
                                CV_8UC1, cv::Scalar(0));
        recording.add(noiseFrame(0, rig_.calibration.cameraSize), std::nullopt, good);
        recording.add(noiseFrame(1, rig_.calibration.cameraSize), std::nullopt, wrongSize);
        recording.add(noiseFrame(2, rig_.calibration.cameraSize), std::nullopt, good);
        recording.finish();
    }
    EXPECT_EQ(stops_, 1);
    const io::Recording recorded = io::Recording::open(dir_ / "rec");
    ASSERT_EQ(recorded.frames().size(), 1u);
    EXPECT_EQ(recorded.frames()[0].index, 0u);
    EXPECT_THROW(RecordingThread(writer, 2, QueueOverflow::Block, images_, onStop_, 0),
                 std::invalid_argument);
}

TEST_F(RecordingThreadTest, AFramesImageGoesBackToThePoolWhenTheLastOfItsHoldersIsDone) {
    io::RecordingWriter writer(dir_ / "rec", rig_, false);
    RecordingThread recording(writer, 2, QueueOverflow::Block, images_, onStop_);
    core::Frame frame = noiseFrame(0, rig_.calibration.cameraSize);
    const uchar* memory = frame.image.data;
    recording.add(frame, std::nullopt, std::nullopt);
    recording.finish();
    // Written while the pipeline still held the image: the recording let go of it, and the pipeline keeps it
    // for the camera.
    EXPECT_EQ(images_.spares(), 0u);
    images_.giveBack(std::move(frame.image));
    ASSERT_EQ(images_.spares(), 1u);
    EXPECT_EQ(images_.take().data, memory);
}

}  // namespace
}  // namespace everytouch::service
