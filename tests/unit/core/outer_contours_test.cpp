#include "core/outer_contours.h"

#include <algorithm>
#include <set>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace everytouch::core {
namespace {

using PixelSet = std::set<std::pair<int, int>>;

PixelSet pixelsOf(const cv::Point* points, int size) {
    PixelSet set;
    for (int i = 0; i < size; ++i)
        set.insert({points[i].x, points[i].y});
    return set;
}

// Blobs, rings, thin lines, islands inside holes and regions cut by the image's edge.
cv::Mat randomMask(unsigned seed) {
    cv::RNG rng(seed);
    cv::Mat mask = cv::Mat::zeros(120, 160, CV_8UC1);
    for (int i = 0; i < 12; ++i) {
        const cv::Point centre(rng.uniform(-10, 170), rng.uniform(-10, 130));
        const cv::Size axes(rng.uniform(1, 25), rng.uniform(1, 25));
        const int thickness = rng.uniform(0, 3) == 0 ? rng.uniform(1, 4) : cv::FILLED;
        cv::ellipse(mask, centre, axes, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(rng.uniform(1, 256)),
                    thickness);
        if (rng.uniform(0, 2) == 0)
            cv::line(mask, {rng.uniform(0, 160), rng.uniform(0, 120)},
                     {rng.uniform(0, 160), rng.uniform(0, 120)}, cv::Scalar(0), rng.uniform(1, 4));
    }
    return mask;
}

TEST(OuterContours, TraceTheSameBoundariesAsOpenCv) {
    OuterContours traced;
    for (unsigned seed = 1; seed <= 200; ++seed) {
        const cv::Mat mask = randomMask(seed);
        findOuterContours(mask, 0.0, traced);
        // OpenCV's outer boundaries: those whose parent is a hole or none (every second level).
        std::vector<std::vector<cv::Point>> expected;
        std::vector<cv::Vec4i> hierarchy;
        cv::Mat copy = mask.clone();
        cv::findContours(copy, expected, hierarchy, cv::RETR_TREE, cv::CHAIN_APPROX_NONE);
        std::multiset<PixelSet> wanted, got;
        for (size_t i = 0; i < expected.size(); ++i) {
            int depth = 0;
            for (int parent = hierarchy[i][3]; parent >= 0; parent = hierarchy[parent][3])
                ++depth;
            if (depth % 2 == 0 && cv::contourArea(expected[i]) > 0.0)
                wanted.insert(pixelsOf(expected[i].data(), static_cast<int>(expected[i].size())));
        }
        for (const ContourSpan& span : traced.contours) {
            EXPECT_GT(span.area, 0.0);
            got.insert(pixelsOf(traced.points.data() + span.begin, span.size));
        }
        EXPECT_EQ(got, wanted) << "seed " << seed;
        EXPECT_EQ(cv::countNonZero(traced.visited), 0) << "seed " << seed;
    }
}

TEST(OuterContours, RunClockwiseWithTheAreaTheyEnclose) {
    cv::Mat mask = cv::Mat::zeros(40, 50, CV_8UC1);
    mask(cv::Rect(10, 5, 20, 10)).setTo(255);
    mask(cv::Rect(15, 8, 5, 3)).setTo(0);  // a hole: not a region
    OuterContours traced;
    findOuterContours(mask, 0.0, traced);
    ASSERT_EQ(traced.contours.size(), 1u);
    const ContourSpan& span = traced.contours[0];
    EXPECT_EQ(span.size, 2 * (19 + 9));
    EXPECT_DOUBLE_EQ(span.area, 19.0 * 9.0);  // through the boundary pixels' centres
    // From the top-left pixel along the top edge: the region on the right of the way travelled.
    EXPECT_EQ(traced.points[span.begin], cv::Point(10, 5));
    EXPECT_EQ(traced.points[span.begin + 1], cv::Point(11, 5));
    EXPECT_EQ(traced.points[span.begin + span.size - 1], cv::Point(10, 6));
}

TEST(OuterContours, DropSmallRegionsAndFollowTheImageEdge) {
    cv::Mat mask = cv::Mat::zeros(30, 30, CV_8UC1);
    mask(cv::Rect(0, 0, 30, 6)).setTo(255);  // along the top edge
    mask(cv::Rect(10, 20, 3, 3)).setTo(1);   // any nonzero value is inside
    mask.at<uchar>(27, 27) = 255;            // a lone pixel
    OuterContours traced;
    findOuterContours(mask, 0.0, traced);
    ASSERT_EQ(traced.contours.size(), 2u);  // the lone pixel encloses nothing
    EXPECT_DOUBLE_EQ(traced.contours[0].area, 29.0 * 5.0);
    EXPECT_DOUBLE_EQ(traced.contours[1].area, 4.0);
    findOuterContours(mask, 5.0, traced);
    ASSERT_EQ(traced.contours.size(), 1u);
    EXPECT_EQ(traced.points[traced.contours[0].begin], cv::Point(0, 0));
}

TEST(OuterContours, RejectAMaskOfAnotherType) {
    OuterContours traced;
    EXPECT_THROW(findOuterContours(cv::Mat::zeros(4, 4, CV_16UC1), 0.0, traced), std::invalid_argument);
}

}  // namespace
}  // namespace everytouch::core
