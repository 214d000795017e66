#include "service/snapshot.h"

#include <fcntl.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "core/camera_model.h"
#include "core/geometry.h"

#include "support/coded_recording.h"
#include "support/test_rig.h"

namespace everytouch::service {
namespace {

using namespace std::chrono_literals;

core::FramePair pairOf(const cv::Mat& positive, const cv::Mat& negative) {
    core::FramePair pair;
    pair.positive.image = positive;
    pair.positive.index = 4;
    pair.negative.image = negative;
    pair.negative.index = 5;
    pair.negative.polarity = core::Polarity::Negative;
    return pair;
}

TEST(Snapshot, NamesAreParsed) {
    EXPECT_EQ(parseSnapshotKind("texture"), SnapshotKind::Texture);
    EXPECT_EQ(parseSnapshotKind("overlay"), SnapshotKind::Overlay);
    EXPECT_EQ(parseSnapshotKind("mask"), SnapshotKind::Mask);
    EXPECT_FALSE(parseSnapshotKind("photo"));
}

TEST(Snapshot, MaskAndImagesComeFromTheDetectionResultNotARecomputation) {
    const test::CodedImages images = test::codedImages({64, 48}, 10);
    const core::FramePair pair = pairOf(images.positive, images.negative);
    core::PipelineResult detection;
    detection.texture = cv::Mat(48, 64, images.positive.type(), cv::Scalar::all(33));
    detection.subtraction = cv::Mat(48, 64, CV_16SC1, cv::Scalar(21));
    detection.handMask = cv::Mat::zeros(48, 64, CV_8UC1);
    detection.handMask(cv::Rect(10, 10, 20, 20)).setTo(255);
    cv::Mat mask, texture, subtraction;
    renderSnapshot(SnapshotKind::Mask, pair, &detection, std::nullopt, mask);
    renderSnapshot(SnapshotKind::Texture, pair, &detection, std::nullopt, texture);
    renderSnapshot(SnapshotKind::Subtraction, pair, &detection, std::nullopt, subtraction);
    EXPECT_EQ(cv::norm(mask, detection.handMask, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(texture, detection.texture, cv::NORM_INF), 0.0);
    EXPECT_EQ(subtraction.at<uchar>(5, 5), 21);
    // Without a detection (the pair never reached the pipeline) the mask is empty, not made up.
    renderSnapshot(SnapshotKind::Mask, pair, nullptr, std::nullopt, mask);
    EXPECT_EQ(cv::countNonZero(mask), 0);
}

TEST(Snapshot, OverlayDrawsTheHandOutlineAndTheFingertips) {
    const cv::Mat gray(120, 160, CV_8UC1, cv::Scalar(128));
    core::PipelineResult detection;
    cv::cvtColor(gray, detection.texture, cv::COLOR_GRAY2BGR);
    detection.subtraction = cv::Mat::zeros(gray.size(), CV_16SC1);
    detection.handMask = cv::Mat::zeros(gray.size(), CV_8UC1);
    detection.handMask(cv::Rect(60, 0, 20, 70)).setTo(255);
    core::FingertipObservation finger;
    finger.fingertip.tip = Eigen::Vector2d(70, 70);
    finger.fingertip.direction = Eigen::Vector2d(0, 1);
    finger.fingertip.widthPx = 20;
    detection.fingertips.push_back(finger);
    cv::Mat overlay;
    renderSnapshot(SnapshotKind::Overlay, pairOf(gray, gray), &detection, std::nullopt, overlay);
    EXPECT_NE(overlay.at<cv::Vec3b>(30, 60), cv::Vec3b(128, 128, 128)) << "no outline on the hand's edge";
    EXPECT_NE(overlay.at<cv::Vec3b>(70, 70), cv::Vec3b(128, 128, 128)) << "no mark on the fingertip";
    EXPECT_EQ(overlay.at<cv::Vec3b>(30, 30), cv::Vec3b(128, 128, 128)) << "drawn away from the hand";
}

TEST(Snapshot, TextureAndSubtractionSeparateSceneAndCode) {
    const test::CodedImages images = test::codedImages({64, 48}, 10);
    const core::FramePair pair = pairOf(images.positive, images.negative);
    cv::Mat camera, texture, subtraction;
    renderSnapshot(SnapshotKind::Camera, pair, nullptr, std::nullopt, camera);
    renderSnapshot(SnapshotKind::Texture, pair, nullptr, std::nullopt, texture);
    renderSnapshot(SnapshotKind::Subtraction, pair, nullptr, std::nullopt, subtraction);
    EXPECT_EQ(cv::norm(camera, images.negative, cv::NORM_INF), 0.0);  // the newer frame
    const cv::Mat table = (images.positive + images.negative) / 2;
    EXPECT_LE(cv::norm(texture, table, cv::NORM_INF), 1.0);
    cv::Mat expectedCode;
    cv::subtract(images.positive, images.negative, expectedCode);
    EXPECT_EQ(cv::norm(subtraction, expectedCode, cv::NORM_INF), 0.0);
    EXPECT_EQ(subtraction.type(), CV_8UC1);
}

TEST(Snapshot, SubtractionTakesTheLargestChannelAndClipsNegatives) {
    cv::Mat positive(2, 2, CV_8UC3, cv::Scalar(100, 100, 100));
    cv::Mat negative(2, 2, CV_8UC3, cv::Scalar(90, 120, 95));
    positive.at<cv::Vec3b>(1, 1) = {50, 50, 50};
    cv::Mat subtraction;
    renderSnapshot(SnapshotKind::Subtraction, pairOf(positive, negative), nullptr, std::nullopt, subtraction);
    EXPECT_EQ(subtraction.at<std::uint8_t>(0, 0), 10);
    EXPECT_EQ(subtraction.at<std::uint8_t>(1, 1), 0);
}

// Where the camera sees the point heightMm straight above the table point a display pixel lands on.
cv::Point cameraPixelOf(const core::Calibration& calibration, cv::Point2d display, double heightMm) {
    const Eigen::Vector2d undistorted =
        core::applyHomography(calibration.cameraToDisplayBelowHomography(heightMm).inverse(),
                              Eigen::Vector2d(display.x, display.y));
    const Eigen::Vector2d raw =
        core::CameraModel{calibration.cameraMatrix, calibration.cameraDistortion}.distortPixel(undistorted);
    return {cvRound(raw.x()), cvRound(raw.y())};
}

TEST(Snapshot, OverlayDrawsTheDisplayOutlineAndTheContactsWhereTheCalibrationPutsThem) {
    core::Calibration calibration = test::paperLikeCalibration();
    calibration.cameraDistortion << -0.12, 0.08, 0.0, 0.0, 0.0;
    const cv::Mat gray(calibration.cameraSize, CV_8UC1, cv::Scalar(128));
    const cv::Point2d centre(calibration.displaySize.width / 2.0, calibration.displaySize.height / 2.0);
    core::Contact touching{.id = 1, .x = centre.x, .y = centre.y, .touching = true};
    core::Contact hovering{.id = 2, .x = centre.x / 2, .y = centre.y, .heightMm = 60.0};
    core::PipelineResult detection;
    cv::cvtColor(gray, detection.texture, cv::COLOR_GRAY2BGR);
    detection.subtraction = cv::Mat::zeros(gray.size(), CV_16SC1);
    detection.contacts = {touching, hovering};
    cv::Mat overlay;
    renderSnapshot(SnapshotKind::Overlay, pairOf(gray, gray), &detection, calibration, overlay);
    ASSERT_EQ(overlay.type(), CV_8UC3);
    ASSERT_EQ(overlay.size(), calibration.cameraSize);

    const auto colourAt = [&](cv::Point at) {
        EXPECT_TRUE(cv::Rect({}, overlay.size()).contains(at)) << at;
        return overlay.at<cv::Vec3b>(at);
    };
    // The paper's camera sees the bottom of the projected display (the top lies beyond its frame). Its
    // outline runs along the outer edges of its pixels, half a pixel beyond the centres of the last ones.
    const double bottom = calibration.displaySize.height - 0.5;
    for (const cv::Point2d corner :
         {cv::Point2d(-0.5, bottom), cv::Point2d(calibration.displaySize.width - 0.5, bottom)}) {
        const cv::Point at = cameraPixelOf(calibration, corner, 0.0);
        EXPECT_GT(colourAt(at)[1], 200) << "no outline at the display corner seen at " << at;
    }
    // Halfway along the bottom edge, where the distortion bends the outline away from the corners' chord.
    const cv::Point middle = cameraPixelOf(calibration, {centre.x, bottom}, 0.0);
    EXPECT_GT(colourAt(middle)[1], 200) << middle;
    EXPECT_EQ(colourAt(cameraPixelOf(calibration, centre, 0.0)), cv::Vec3b(0, 0, 255));
    // The hovering finger's ring is centred where its height puts it, not where the table would.
    const cv::Point hover = cameraPixelOf(calibration, {hovering.x, hovering.y}, hovering.heightMm);
    const cv::Point onTable = cameraPixelOf(calibration, {hovering.x, hovering.y}, 0.0);
    ASSERT_GE(cv::norm(hover - onTable), 4.0) << "the test needs the heights to be told apart";
    EXPECT_EQ(colourAt(hover), cv::Vec3b(128, 128, 128)) << "a ring, not a dot";
    const cv::Vec3b yellow(0, 255, 255);
    const cv::Point offset = onTable - hover;
    const cv::Point across(-offset.y, offset.x);  // the ring's rim on either side, away from the table point
    const double scale = 6.0 / cv::norm(across);
    const cv::Point rim(cvRound(across.x * scale), cvRound(across.y * scale));
    EXPECT_EQ(colourAt(hover + rim), yellow);
    EXPECT_EQ(colourAt(hover - rim), yellow);
}

TEST(Snapshot, OverlaySaysWhenThereIsNoCalibration) {
    const cv::Mat gray(120, 160, CV_8UC1, cv::Scalar(128));
    cv::Mat overlay;
    renderSnapshot(SnapshotKind::Overlay, pairOf(gray, gray), nullptr, std::nullopt, overlay);
    ASSERT_EQ(overlay.type(), CV_8UC3);
    cv::Mat plain;
    cv::cvtColor(gray, plain, cv::COLOR_GRAY2BGR);
    EXPECT_GT(cv::norm(overlay, plain, cv::NORM_L1), 0.0) << "nothing written on the image";
}

}  // namespace
}  // namespace everytouch::service
