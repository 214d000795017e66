#include "eval/recording_pairs.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::eval {
namespace {

// Six frames, the fourth repeating the third's polarity (a dropped frame): pairs end at frames 1, 2 and 4, 5.
// Frame i is uniformly 10 i, its mask a bar i pixels wide, and frames 2 and 5 have one truth finger each.
class RecordingPairsTest : public ::testing::Test {
protected:
    void SetUp() override {
        const io::RigDescription rig = test::paperLikeRig();
        io::RecordingWriter writer(directory_ / "rec", rig, true, true);
        const int polarities[] = {1, -1, 1, 1, -1, 1};
        for (std::uint64_t i = 0; i < 6; ++i) {
            core::Frame frame;
            frame.index = 100 + i;
            frame.timestampUs = static_cast<std::int64_t>(i) * 8333;
            frame.polarity = static_cast<core::Polarity>(polarities[i]);
            frame.image = cv::Mat(rig.calibration.cameraSize, CV_8UC3, cv::Scalar::all(10.0 * i));
            writer.addFrame(frame);
            cv::Mat mask(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
            mask.colRange(0, static_cast<int>(i)).setTo(255);
            writer.addMask(frame.index, mask);
            if (i == 2 || i == 5)
                writer.addTruth({{frame.index, static_cast<std::uint32_t>(i), 640.0, 480.0, 0.0}});
        }
        writer.flush();
    }

    test::TempDir directory_;
};

TEST_F(RecordingPairsTest, PairsAsTheDaemonDoesAndTakesTheNewerFramesTruth) {
    const io::Recording recording = io::Recording::open(directory_ / "rec");
    const TruthToCamera toCamera(recording.rig().calibration, 16.0);
    RecordingPairs pairs(recording, toCamera);
    PairWithTruth pair;
    std::vector<std::size_t> positions;
    while (pairs.next(pair)) {
        positions.push_back(pair.position);
        const int newer = static_cast<int>(pair.position);
        // T averages the two frames, 10 (newer - 1) and 10 newer.
        EXPECT_EQ(pair.texture.at<cv::Vec3b>(7, 9)[1], 10 * newer - 5) << "pair ending at " << newer;
        EXPECT_EQ(cv::countNonZero(pair.truthMask), newer * pair.truthMask.rows);
        EXPECT_EQ(pair.fingers.size(), newer == 2 || newer == 5 ? 1u : 0u);
        if (!pair.fingers.empty()) {
            EXPECT_EQ(pair.fingers[0].id, static_cast<std::uint32_t>(newer));
            EXPECT_GT(pair.fingers[0].fingerWidthPx, 10.0);
        }

        PairWithTruth again;
        ASSERT_TRUE(pairs.at(pair.position, again));
        EXPECT_EQ(cv::norm(again.texture, pair.texture, cv::NORM_INF), 0.0);
        EXPECT_EQ(again.fingers.size(), pair.fingers.size());
    }
    EXPECT_EQ(positions, (std::vector<std::size_t>{1, 2, 4, 5}));
    EXPECT_FALSE(pairs.at(0, pair));
    EXPECT_FALSE(pairs.at(3, pair));  // repeats its predecessor's polarity
}

}  // namespace
}  // namespace everytouch::eval
