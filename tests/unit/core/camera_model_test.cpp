#include "core/camera_model.h"

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace everytouch::core {
namespace {

CameraModel distortedCamera() {
    CameraModel camera;
    camera.matrix << 810, 0, 330, 0, 805, 240, 0, 0, 1;
    camera.distortion << -0.2, 0.12, 0.001, -0.0015, -0.02;
    return camera;
}

TEST(CameraModel, ProjectsLikeOpenCv) {
    const CameraModel camera = distortedCamera();
    const std::vector<cv::Point3d> points = {{0, 0, 500}, {150, -90, 480}, {-170, 120, 520}, {60, 30, 300}};
    cv::Mat matrix, distortion;
    cv::eigen2cv(camera.matrix, matrix);
    cv::eigen2cv(camera.distortion, distortion);
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), matrix, distortion, expected);
    for (size_t index = 0; index < points.size(); ++index) {
        const Eigen::Vector2d projected = camera.project({points[index].x, points[index].y, points[index].z});
        EXPECT_NEAR(projected.x(), expected[index].x, 1e-9);
        EXPECT_NEAR(projected.y(), expected[index].y, 1e-9);
    }
}

TEST(CameraModel, UndistortionInvertsDistortionAcrossTheFrame) {
    const CameraModel camera = distortedCamera();
    for (double x = -0.4; x <= 0.4; x += 0.1) {
        for (double y = -0.3; y <= 0.3; y += 0.1) {
            const Eigen::Vector2d raw = camera.distortNormalised({x, y});
            EXPECT_LT((camera.undistortToNormalised(raw) - Eigen::Vector2d(x, y)).norm(), 1e-12);
            const Eigen::Vector2d ideal = (camera.matrix * Eigen::Vector3d(x, y, 1)).hnormalized();
            EXPECT_LT((camera.undistortPixel(raw) - ideal).norm(), 1e-9);
            EXPECT_LT((camera.distortPixel(ideal) - raw).norm(), 1e-9);
        }
    }
}

TEST(CameraModel, DefaultModelLeavesPixelsAlone) {
    const CameraModel identity;
    EXPECT_EQ(identity.undistortPixel({123.25, 45.5}), Eigen::Vector2d(123.25, 45.5));
}

}  // namespace
}  // namespace everytouch::core
