#include "core/table_rectangle.h"

#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/surface_renderer.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;

// The stripe lying on the table slightly turned, under the projector's white. (The paper-like rig lights the
// table between about y = 120 and 350 mm, and the camera sees up to y = 330 mm there.)
test::SurfaceScene stripeOnTable() {
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    test::DarkRectangle stripe;
    stripe.originMm = {110, 200};
    stripe.angleRad = 0.12;
    scene.rectangles.push_back(stripe);
    return scene;
}

cv::Mat whiteProjection(const core::Calibration& rig) {
    return cv::Mat(rig.projectorSize, CV_8UC1, cv::Scalar(255));
}

// Where the truth puts the rectangle's corners (table (0,0), (w,0), (w,h), (0,h) of the rectangle's own
// frame), undistorted camera pixels.
std::array<Eigen::Vector2d, 4> trueCorners(const test::SurfaceScene& scene,
                                           const test::DarkRectangle& rectangle) {
    const Eigen::Rotation2Dd turn(rectangle.angleRad);
    const double w = rectangle.sizeMm.width, h = rectangle.sizeMm.height;
    std::array<Eigen::Vector2d, 4> corners;
    const std::array<Eigen::Vector2d, 4> local = {Eigen::Vector2d(0, 0), Eigen::Vector2d(w, 0),
                                                  Eigen::Vector2d(w, h), Eigen::Vector2d(0, h)};
    for (int index = 0; index < 4; ++index)
        corners[index] =
            applyHomography(scene.rig.tableToCameraHomography(), rectangle.originMm + turn * local[index]);
    return corners;
}

double worstCornerError(const TableRectangleDetection& detection,
                        const std::array<Eigen::Vector2d, 4>& truth) {
    double worst = 0;
    for (int index = 0; index < 4; ++index)
        worst = std::max(worst, (detection.corners[index] - truth[index]).norm());
    return worst;
}

class StripeOnTable : public ::testing::TestWithParam<double> {};

// Corners within a fraction of a pixel: 0.05 px without noise (what is left is the renderer's 4 x 4
// supersampling of the edges), 0.2 px with sigma = 2 DN (the stripe's short edges are only about 16 px long,
// so few edge points average the noise there).
TEST_P(StripeOnTable, FindsTheCornersToAFractionOfAPixel) {
    const double noiseSigmaDn = GetParam();
    const test::SurfaceScene scene = stripeOnTable();
    const cv::Mat capture = test::renderSurface(scene, whiteProjection(scene.rig), noiseSigmaDn);
    const Result<TableRectangleDetection> detection = findTableRectangle(capture, {});
    ASSERT_TRUE(detection.ok()) << detection.failure().message;
    const double worst = worstCornerError(detection.value(), trueCorners(scene, scene.rectangles[0]));
    RecordProperty("worst_corner_error_px", std::to_string(worst));
    EXPECT_LT(worst, noiseSigmaDn > 0 ? 0.2 : 0.05);
    EXPECT_GT(detection->contrastDn, 100);
    // The homography takes the table's stripe corners to the corners found.
    EXPECT_LT((applyHomography(detection->tableToCamera, {85.5, 12.5}) - detection->corners[2]).norm(), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(NoiseFreeAndNoisy, StripeOnTable, ::testing::Values(0.0, 2.0));

TEST(TableRectangle, IgnoresDarkThingsOfOtherShapes) {
    test::SurfaceScene scene = stripeOnTable();
    test::DarkRectangle square, line, cardSized;
    square.originMm = {40, 260};
    square.sizeMm = {40, 40};
    line.originMm = {40, 140};
    line.sizeMm = {200, 3};
    cardSized.originMm = {150, 250};
    cardSized.sizeMm = {85.6, 54};
    cardSized.albedo = 0.3;
    scene.rectangles.insert(scene.rectangles.end(), {square, line, cardSized});
    const cv::Mat capture = test::renderSurface(scene, whiteProjection(scene.rig), 2.0);
    const Result<TableRectangleDetection> detection = findTableRectangle(capture, {});
    ASSERT_TRUE(detection.ok()) << detection.failure().message;
    EXPECT_LT(worstCornerError(detection.value(), trueCorners(scene, scene.rectangles[0])), 0.2);
}

TEST(TableRectangle, FindsAWholeDarkCardGivenItsSize) {
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    test::DarkRectangle card;
    card.originMm = {110, 190};
    card.sizeMm = {85.6, 54};
    card.angleRad = -0.2;
    scene.rectangles.push_back(card);
    const cv::Mat capture = test::renderSurface(scene, whiteProjection(scene.rig), 2.0);
    TableRectangleOptions options;
    options.sizeMm = card.sizeMm;
    const Result<TableRectangleDetection> detection = findTableRectangle(capture, options);
    ASSERT_TRUE(detection.ok()) << detection.failure().message;
    EXPECT_LT(worstCornerError(detection.value(), trueCorners(scene, card)), 0.2);
}

TEST(TableRectangle, ReportsUndistortedPixelsOfTheCameraModel) {
    test::SurfaceScene scene = stripeOnTable();
    scene.rig.cameraDistortion << -0.2, 0.1, 0, 0, 0;
    const cv::Mat capture = test::renderSurface(scene, whiteProjection(scene.rig));
    const Result<TableRectangleDetection> detection =
        findTableRectangle(capture, {}, CameraModel{scene.rig.cameraMatrix, scene.rig.cameraDistortion});
    ASSERT_TRUE(detection.ok()) << detection.failure().message;
    EXPECT_LT(worstCornerError(detection.value(), trueCorners(scene, scene.rectangles[0])), 0.05);
}

TEST(TableRectangle, TableWithoutTheRectangleFailsWithAMessage) {
    test::SurfaceScene scene;
    scene.rig = test::paperLikeCalibration();
    const cv::Mat capture = test::renderSurface(scene, whiteProjection(scene.rig), 2.0);
    const Result<TableRectangleDetection> detection = findTableRectangle(capture, {});
    ASSERT_FALSE(detection.ok());
    EXPECT_THAT(detection.failure().message, HasSubstr("no dark rectangle of 85.5 x 12.5 mm"));
}

TEST(TableRectangle, OptionsThatDoNotValidateAreAProgrammingError) {
    TableRectangleOptions options;
    options.sizeMm = {12.5, 85.5};
    EXPECT_THAT(options.validate(), ::testing::Optional(HasSubstr("longer side first")));
    EXPECT_THROW((void)findTableRectangle(cv::Mat(48, 64, CV_8UC1, cv::Scalar(200)), options),
                 std::invalid_argument);
}

TEST(TableRectangle, AFrameThatIsNeitherGrayNorBgrFails) {
    const Result<TableRectangleDetection> detection = findTableRectangle(cv::Mat(48, 64, CV_32FC1), {});
    ASSERT_FALSE(detection.ok());
    EXPECT_THAT(detection.failure().message, HasSubstr("8-bit gray or BGR"));
}

}  // namespace
}  // namespace everytouch::core
