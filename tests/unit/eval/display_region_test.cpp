#include "eval/display_region.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/geometry.h"
#include "support/test_rig.h"

namespace everytouch::eval {
namespace {

TEST(DisplayRegion, IsTheDisplaysQuadrilateralInTheCamera) {
    const core::Calibration calibration = test::paperLikeCalibration();
    const cv::Mat region = displayRegion(calibration);
    ASSERT_EQ(region.size(), calibration.cameraSize);
    ASSERT_EQ(region.type(), CV_8UC1);
    const Eigen::Matrix3d displayToCamera =
        calibration.tableToCameraHomography() * calibration.displayToTableHomography();
    const double w = calibration.displaySize.width, h = calibration.displaySize.height;
    std::vector<cv::Point2f> corners;
    for (const Eigen::Vector2d& corner :
         {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0), Eigen::Vector2d(w, h), Eigen::Vector2d(0, h)}) {
        const Eigen::Vector2d camera = core::applyHomography(displayToCamera, corner);
        corners.emplace_back(static_cast<float>(camera.x()), static_cast<float>(camera.y()));
    }
    // Where the display leaves the camera's view, the region ends at the frame.
    const std::vector<cv::Point2f> frame{
        {0, 0},
        {static_cast<float>(calibration.cameraSize.width), 0},
        {static_cast<float>(calibration.cameraSize.width), static_cast<float>(calibration.cameraSize.height)},
        {0, static_cast<float>(calibration.cameraSize.height)}};
    std::vector<cv::Point2f> visible;
    const double area = cv::intersectConvexConvex(corners, frame, visible);
    EXPECT_NEAR(cv::countNonZero(region), area, 0.01 * area);
    const Eigen::Vector2d centre = core::applyHomography(displayToCamera, {w / 2, h / 2});
    EXPECT_EQ(region.at<uchar>(cvRound(centre.y()), cvRound(centre.x())), 255);
}

TEST(DisplayRegion, FollowsTheLensDistortion) {
    const core::Calibration straight = test::paperLikeCalibration();
    const core::Calibration bent = test::distortedPaperLikeCalibration();
    // Same rig apart from the lens: the outlines differ by the distortion near the edges, a few pixels.
    const cv::Mat difference = displayRegion(straight) != displayRegion(bent);
    EXPECT_GT(cv::countNonZero(difference), 100);
    EXPECT_LT(cv::countNonZero(difference), 0.1 * cv::countNonZero(displayRegion(straight)));
}

}  // namespace
}  // namespace everytouch::eval
