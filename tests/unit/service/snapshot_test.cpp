#include "service/snapshot.h"

#include <fcntl.h>
#include <unistd.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "support/coded_recording.h"

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
    EXPECT_FALSE(parseSnapshotKind("mask"));
    EXPECT_TRUE(snapshotNeedsDetection("mask"));
    EXPECT_TRUE(snapshotNeedsDetection("overlay"));
    EXPECT_FALSE(snapshotNeedsDetection("photo"));
}

TEST(Snapshot, TextureAndSubtractionSeparateSceneAndCode) {
    const test::CodedImages images = test::codedImages({64, 48}, 10);
    const core::FramePair pair = pairOf(images.positive, images.negative);
    cv::Mat camera, texture, subtraction;
    renderSnapshot(SnapshotKind::Camera, pair, camera);
    renderSnapshot(SnapshotKind::Texture, pair, texture);
    renderSnapshot(SnapshotKind::Subtraction, pair, subtraction);
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
    renderSnapshot(SnapshotKind::Subtraction, pairOf(positive, negative), subtraction);
    EXPECT_EQ(subtraction.at<std::uint8_t>(0, 0), 10);
    EXPECT_EQ(subtraction.at<std::uint8_t>(1, 1), 0);
}

TEST(Snapshot, PngGoesThroughAPipe) {
    const cv::Mat image = test::codedImages({40, 30}, 10).positive;
    const std::vector<unsigned char> png = encodePng(image);
    int ends[2];
    ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
    ASSERT_EQ(writeAllWithin(ends[1], png, 1000ms), 0);
    ::close(ends[1]);
    std::vector<unsigned char> received(png.size() + 1);
    ASSERT_EQ(::read(ends[0], received.data(), received.size()), static_cast<ssize_t>(png.size()));
    ::close(ends[0]);
    received.resize(png.size());
    EXPECT_EQ(cv::norm(cv::imdecode(received, cv::IMREAD_UNCHANGED), image, cv::NORM_INF), 0.0);
}

TEST(Snapshot, AReaderThatNeverReadsTimesOutInsteadOfBlocking) {
    const std::vector<unsigned char> big(1 << 20, 7);  // more than a pipe holds
    int ends[2];
    ASSERT_EQ(::pipe2(ends, O_CLOEXEC), 0);
    EXPECT_EQ(writeAllWithin(ends[1], big, 100ms), -ETIMEDOUT);
    EXPECT_EQ(writeAllWithin(ends[0], big, 100ms), -EBADF);
    ::close(ends[0]);
    ::close(ends[1]);
}

}  // namespace
}  // namespace everytouch::service
