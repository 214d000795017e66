#include "io/replay_source.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::io {
namespace {

// Writes a recording of `count` gray frames and, when asked, a mask per frame with a square at x = 30 *
// index.
void writeRecording(const std::filesystem::path& directory, int count, bool withMasks) {
    const RigDescription rig = test::paperLikeRig();
    RecordingWriter writer(directory, rig, false, withMasks);
    for (int i = 0; i < count; ++i) {
        core::Frame frame;
        frame.index = static_cast<std::uint64_t>(10 + i);
        frame.timestampUs = 8333 * i;
        frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
        frame.image = cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(20.0 * i));
        writer.addFrame(frame);
        if (withMasks) {
            cv::Mat mask(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
            mask(cv::Rect(30 * i, 50, 40, 40)).setTo(255);
            writer.addMask(frame.index, mask);
        }
    }
    writer.flush();
}

TEST(ReplaySource, OffersTheMaskOfEachFrame) {
    test::TempDir dir;
    writeRecording(dir / "rec", 3, true);
    ReplaySource source(dir / "rec", false);
    ASSERT_TRUE(source.truthMask());
    EXPECT_TRUE(source.truthMask()->empty()) << "no frame yet";
    for (int i = 0; i < 3; ++i) {
        const std::optional<core::Frame> frame = source.next();
        ASSERT_TRUE(frame);
        const std::optional<cv::Mat> mask = source.truthMask();
        ASSERT_TRUE(mask);
        ASSERT_EQ(mask->size(), frame->image.size());
        EXPECT_EQ(cv::countNonZero(*mask), 40 * 40);
        EXPECT_EQ(mask->at<std::uint8_t>(70, 30 * i + 20), 255) << "frame " << frame->index;
    }
    EXPECT_FALSE(source.next());
}

TEST(ReplaySource, RecordingWithoutMasksOffersNone) {
    test::TempDir dir;
    writeRecording(dir / "rec", 2, false);
    ReplaySource source(dir / "rec", false);
    ASSERT_TRUE(source.next());
    EXPECT_FALSE(source.truthMask());
}

}  // namespace
}  // namespace everytouch::io
