#include "eval/segmentation_evaluation.h"

#include <algorithm>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/fingertips.h"
#include "core/geometry.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch::eval {
namespace {

constexpr int kFrames = 40;
constexpr int kHandFrom = 32;  // after BkSub's background, frames 0-29

// A hand from the image's top edge: a palm and one finger 20 px wide (16 mm on this rig) ending in a round
// tip at (325, 260).
void drawHand(cv::Mat& image, const cv::Scalar& colour) {
    cv::rectangle(image, cv::Rect(250, 0, 150, 150), colour, cv::FILLED);
    cv::rectangle(image, cv::Rect(315, 140, 20, 110), colour, cv::FILLED);
    cv::circle(image, cv::Point(325, 250), 10, colour, cv::FILLED);
}

// Gray table with camera noise; the hand, skin-coloured, in the last frames; masks and the finger's truth.
void writeRecording(const std::filesystem::path& directory) {
    const io::RigDescription rig = test::paperLikeRig();
    io::RecordingWriter writer(directory, rig, true, true);
    cv::RNG rng(11);
    const Eigen::Vector2d pad =
        core::applyHomography(rig.calibration.cameraToDisplayHomography(0.0), {325, 253});
    for (int i = 0; i < kFrames; ++i) {
        core::Frame frame;
        frame.index = static_cast<std::uint64_t>(i);
        frame.timestampUs = i * 8333;
        frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
        cv::Mat scene(rig.calibration.cameraSize, CV_32FC3, cv::Scalar(120, 124, 118));
        cv::Mat mask(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(0));
        if (i >= kHandFrom) {
            drawHand(scene, cv::Scalar(120, 150, 205));
            drawHand(mask, cv::Scalar(255));
            writer.addTruth({{frame.index, 1, pad.x(), pad.y(), 0.0}});
        }
        cv::Mat noise(scene.size(), CV_32FC3);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.5);
        cv::Mat(scene + noise).convertTo(frame.image, CV_8UC3);
        writer.addFrame(frame);
        writer.addMask(frame.index, mask);
    }
    writer.flush();
}

TEST(EvaluateSegmentation, ScoresEveryPairAndTheFingertipsOnEachMask) {
    test::TempDir directory;
    writeRecording(directory / "rec");
    const io::Recording recording = io::Recording::open(directory / "rec");
    const TruthToCamera toCamera(recording.rig().calibration, 16.0);
    std::vector<SegmentationMethod> methods = segmentationMethods(recording, MethodOptions{});
    std::erase_if(methods, [](const SegmentationMethod& m) { return m.name != "SCM" && m.name != "BkSub"; });
    ASSERT_EQ(methods.size(), 2u);

    const core::FingertipOptions options = core::rigFingertipOptions(recording.rig().calibration, 16.0);
    core::FingertipScratch scratch;
    core::Fingertips found;
    const FingertipFinder finder = [&](const cv::Mat& mask, const cv::Mat& judged,
                                       std::vector<Eigen::Vector2d>& pads) {
        core::findFingertips(mask, options, scratch, found, judged);
        pads.clear();
        for (const core::Fingertip& fingertip : found)
            pads.push_back(fingertip.pad);
    };
    const SegmentationReport report = evaluateSegmentation(recording, "rec", methods, finder, toCamera, 16.0);

    EXPECT_EQ(report.pairs, kFrames - 1);
    EXPECT_EQ(report.pairsWithHand, kFrames - kHandFrom);
    EXPECT_EQ(report.handPositions.front(), static_cast<std::size_t>(kHandFrom));
    EXPECT_TRUE(report.fingertipTruth);
    // The finder on the truth masks finds the one finger of every hand pair, near its pad.
    EXPECT_EQ(report.truthMaskFingertips.truth(), kFrames - kHandFrom);
    EXPECT_EQ(report.truthMaskFingertips.matched(), kFrames - kHandFrom);
    EXPECT_LT(*report.truthMaskFingertips.meanErrorPx(), 5.0);

    ASSERT_EQ(report.methods.size(), 2u);
    for (const MethodResult& method : report.methods) {
        ASSERT_FALSE(method.unavailable) << method.name;
        EXPECT_EQ(method.pixels.pairs(), kFrames - 1) << method.name;
        EXPECT_EQ(method.pixels.pairsWithHand(), kFrames - kHandFrom) << method.name;
    }
    // Skin on a gray table, no shadow, no content: both find the hand, background subtraction almost exactly
    // (the pair where the hand appears shows it half, which still differs from the table).
    const MethodResult& bkSub = report.methods[1];
    EXPECT_GT(*bkSub.pixels.total().precision(), 0.99);
    EXPECT_GT(*bkSub.pixels.total().recall(), 0.99);
    EXPECT_EQ(bkSub.fingertips.matched(), kFrames - kHandFrom);
    EXPECT_GT(*report.methods[0].pixels.total().recall(), 0.9);
    // Within the display counts a part of the frame only.
    EXPECT_LE(bkSub.displayPixels.total().truePositive, bkSub.pixels.total().truePositive);
}

TEST(SegmentationMethods, SayWhyTheyCannotRunOnARecording) {
    // Four gray frames: no colour for the skin model, too few pairs for a background.
    test::TempDir directory;
    const io::RigDescription rig = test::paperLikeRig();
    {
        io::RecordingWriter writer(directory / "gray", rig, false, true);
        for (std::uint64_t i = 0; i < 4; ++i) {
            core::Frame frame;
            frame.index = i;
            frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
            frame.image = cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(100));
            writer.addFrame(frame);
            writer.addMask(i, cv::Mat(rig.calibration.cameraSize, CV_8UC1, cv::Scalar(0)));
        }
    }
    const io::Recording recording = io::Recording::open(directory / "gray");
    const std::vector<SegmentationMethod> methods = segmentationMethods(recording, MethodOptions{});
    ASSERT_EQ(methods.size(), 4u);
    EXPECT_FALSE(methods[0].unavailable);
    EXPECT_FALSE(methods[1].unavailable);
    EXPECT_EQ(methods[2].name, "SCM");
    EXPECT_EQ(methods[2].unavailable, "needs colour frames");
    EXPECT_EQ(methods[3].name, "BkSub");
    EXPECT_EQ(methods[3].unavailable, "recording too short for the background");

    // Those that can run are scored; the others are reported as not run.
    const TruthToCamera toCamera(rig.calibration, 16.0);
    const FingertipFinder none = [](const cv::Mat&, const cv::Mat&, std::vector<Eigen::Vector2d>& pads) {
        pads.clear();
    };
    const SegmentationReport report = evaluateSegmentation(recording, "gray", methods, none, toCamera, 16.0);
    EXPECT_EQ(report.pairs, 3);
    EXPECT_EQ(report.channels, 1);
    EXPECT_FALSE(report.fingertipTruth);
    EXPECT_EQ(report.methods[0].pixels.pairs(), 3);
    EXPECT_EQ(report.methods[2].pixels.pairs(), 0);
    EXPECT_EQ(report.methods[3].pixels.pairs(), 0);
}

}  // namespace
}  // namespace everytouch::eval
