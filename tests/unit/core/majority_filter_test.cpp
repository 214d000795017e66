#include "core/majority_filter.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace everytouch::core {
namespace {

TEST(VoteByMajority, RemovesSpecksAndFillsPinholesButKeepsABroadShape) {
    cv::Mat mask = cv::Mat::zeros(60, 80, CV_8UC1);
    cv::rectangle(mask, cv::Rect(20, 10, 30, 40), cv::Scalar(255), cv::FILLED);
    mask.at<uchar>(30, 35) = 0;   // a pinhole in the shape
    mask.at<uchar>(5, 70) = 255;  // a speck on the table
    MajorityScratch scratch;
    voteByMajority(mask, cv::Rect(0, 0, 80, 60), 2, scratch);
    EXPECT_EQ(mask.at<uchar>(30, 35), 255);
    EXPECT_EQ(mask.at<uchar>(5, 70), 0);
    // A straight edge stays where it was; the rectangle's corners round off by a pixel or two only.
    EXPECT_EQ(mask.at<uchar>(30, 20), 255);
    EXPECT_EQ(mask.at<uchar>(30, 19), 0);
    EXPECT_EQ(mask.at<uchar>(10, 35), 255);
    EXPECT_EQ(mask.at<uchar>(9, 35), 0);
    EXPECT_NEAR(cv::countNonZero(mask), 30 * 40, 12);
}

TEST(VoteByMajority, CutsAFringeNarrowerThanTheRadius) {
    cv::Mat mask = cv::Mat::zeros(40, 40, CV_8UC1);
    cv::rectangle(mask, cv::Rect(10, 10, 20, 20), cv::Scalar(255), cv::FILLED);
    cv::line(mask, cv::Point(30, 20), cv::Point(39, 20), cv::Scalar(255));  // a one-pixel sliver
    MajorityScratch scratch;
    voteByMajority(mask, cv::Rect(0, 0, 40, 40), 3, scratch);
    EXPECT_EQ(cv::countNonZero(mask(cv::Rect(32, 15, 8, 10))), 0);
    EXPECT_EQ(mask.at<uchar>(20, 20), 255);
}

TEST(VoteByMajority, LeavesPixelsOutsideTheRegionAlone) {
    cv::Mat mask = cv::Mat::zeros(30, 30, CV_8UC1);
    mask.at<uchar>(5, 5) = 255;
    mask.at<uchar>(25, 25) = 255;
    MajorityScratch scratch;
    voteByMajority(mask, cv::Rect(15, 15, 15, 15), 1, scratch);
    EXPECT_EQ(mask.at<uchar>(5, 5), 255);
    EXPECT_EQ(mask.at<uchar>(25, 25), 0);
}

TEST(VoteByMajority, RadiusZeroChangesNothingAndANegativeOneIsRefused) {
    cv::Mat mask = cv::Mat::zeros(10, 10, CV_8UC1);
    mask.at<uchar>(4, 4) = 255;
    MajorityScratch scratch;
    voteByMajority(mask, cv::Rect(0, 0, 10, 10), 0, scratch);
    EXPECT_EQ(cv::countNonZero(mask), 1);
    EXPECT_THROW(voteByMajority(mask, cv::Rect(0, 0, 10, 10), -1, scratch), std::invalid_argument);
}

}  // namespace
}  // namespace everytouch::core
