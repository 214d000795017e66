#include "core/embedding.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace everytouch::core {
namespace {

TEST(Embedding, DifferenceIsTwiceDeltaOnOnesAndZeroElsewhereEvenOnBlackAndWhite) {
    cv::Mat content(48, 64, CV_8UC3);
    content.colRange(0, 16).setTo(cv::Scalar::all(0));
    content.colRange(16, 32).setTo(cv::Scalar::all(255));
    cv::randu(content.colRange(32, 64), 0, 256);
    cv::Mat bits(content.size(), CV_8UC1);
    cv::randu(bits, 0, 2);
    cv::Mat positive, negative;
    const int delta = 10;
    embedCode(content, bits, delta, positive, negative);

    cv::Mat difference;
    cv::subtract(positive, negative, difference, cv::noArray(), CV_16SC3);
    for (int y = 0; y < content.rows; ++y)
        for (int x = 0; x < content.cols; ++x)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(difference.at<cv::Vec3s>(y, x)[c], bits.at<uchar>(y, x) ? 2 * delta : 0)
                    << "at " << x << "," << y;
}

TEST(Embedding, AverageIsTheContentCompressedIntoTheCodeFreeRange) {
    cv::Mat content(1, 256, CV_8UC1);
    for (int level = 0; level < 256; ++level)
        content.at<uchar>(level) = static_cast<uchar>(level);
    cv::Mat bits(content.size(), CV_8UC1, cv::Scalar(1));
    cv::Mat positive, negative;
    const int delta = 12;
    embedCode(content, bits, delta, positive, negative);
    for (int level = 0; level < 256; ++level) {
        const double average = (positive.at<uchar>(level) + negative.at<uchar>(level)) / 2.0;
        EXPECT_NEAR(average, delta + level * (255.0 - 2 * delta) / 255.0, 0.5);
    }
    double lowest, highest;
    cv::minMaxLoc(negative, &lowest, nullptr);
    cv::minMaxLoc(positive, nullptr, &highest);
    EXPECT_EQ(lowest, 0.0);
    EXPECT_EQ(highest, 255.0);
}

}  // namespace
}  // namespace everytouch::core
