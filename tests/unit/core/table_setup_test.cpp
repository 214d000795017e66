#include "core/table_setup.h"

#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/plane_view_capture.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;

// The paper-like rig with a lens that bends straight lines by a few pixels at the frame's edges.
Calibration distortedRig() {
    Calibration rig = test::paperLikeCalibration();
    rig.cameraDistortion << -0.12, 0.08, 0, 0, 0;
    return rig;
}

// The stripe on the table where the projector lights it, its x axis along increasing camera columns.
test::DarkRectangle stripe() {
    test::DarkRectangle rectangle;
    rectangle.originMm = {110, 200};
    rectangle.angleRad = 0.12;
    return rectangle;
}

// The table frame the set-up should find: the rectangle's own frame.
Eigen::Isometry3d rectangleToCamera(const Calibration& rig, const test::DarkRectangle& rectangle) {
    return rig.tableToCamera * Eigen::Translation3d(rectangle.originMm.x(), rectangle.originMm.y(), 0) *
           Eigen::AngleAxisd(rectangle.angleRad, Eigen::Vector3d::UnitZ());
}

double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle() * 180.0 / M_PI;
}

TEST(TableSetup, ExactCorrespondencesGiveTheExactTable) {
    const Calibration rig = distortedRig();
    const ProjectorCameraPair pair = pairOf(rig);
    const test::DarkRectangle rectangle = stripe();
    PlaneView view;
    for (double x = 100; x <= 540; x += 40) {
        for (double y = 60; y <= 420; y += 40) {
            const Eigen::Vector2d projector(x, y);
            const Eigen::Vector3d onTable =
                (rig.tableToProjectorHomography().inverse() * projector.homogeneous())
                    .hnormalized()
                    .homogeneous()
                    .cwiseProduct(Eigen::Vector3d(1, 1, 0));
            view.projectorPoints.push_back(projector);
            view.cameraPoints.push_back(pair.camera.project(rig.tableToCamera * onTable));
        }
    }
    const Eigen::Isometry3d truth = rectangleToCamera(rig, rectangle);
    std::array<Eigen::Vector2d, 4> corners;
    const std::array<Eigen::Vector3d, 4> local = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(85.5, 0, 0),
                                                  Eigen::Vector3d(85.5, 12.5, 0),
                                                  Eigen::Vector3d(0, 12.5, 0)};
    for (int corner = 0; corner < 4; ++corner)
        corners[corner] = pair.camera.project(truth * local[corner]);
    view.rectangleCorners = corners;

    const Result<TableSetup> setup = setUpTable(pair, view, {});
    ASSERT_TRUE(setup.ok()) << setup.failure().message;
    EXPECT_LT(setup->rmsPx.all, 1e-6);
    EXPECT_LT(rotationErrorDeg(setup->calibration.tableToCamera, truth), 1e-6);
    EXPECT_LT((setup->calibration.tableToCamera.translation() - truth.translation()).norm(), 1e-6);
    EXPECT_EQ(setup->calibration.validate(),
              std::optional<std::string>("display_size: width and height must be positive"));
}

class RenderedTable : public ::testing::TestWithParam<double> {};

// One chessboard frame and one frame with the stripe, rendered through the distorted rig, found by the
// detectors: RMS < 0.1 px noise-free and < 0.5 px with sigma = 2 DN.
TEST_P(RenderedTable, RecoversTheTableFrameFromTheStripe) {
    const double noiseSigmaDn = GetParam();
    const Calibration rig = distortedRig();
    const ProjectorCameraPair pair = pairOf(rig);
    const Result<PlaneView> captured = test::captureView(rig, stripe(), noiseSigmaDn, 7, pair.camera);
    ASSERT_TRUE(captured.ok()) << captured.failure().message;

    const Result<TableSetup> setup = setUpTable(pair, captured.value(), {});
    ASSERT_TRUE(setup.ok()) << setup.failure().message;
    const Eigen::Isometry3d truth = rectangleToCamera(rig, stripe());
    const double rotationDeg = rotationErrorDeg(setup->calibration.tableToCamera, truth);
    const double translationMm =
        (setup->calibration.tableToCamera.translation() - truth.translation()).norm();
    RecordProperty("rms_px", std::to_string(setup->rmsPx.all));
    RecordProperty("rotation_error_deg", std::to_string(rotationDeg));
    RecordProperty("translation_error_mm", std::to_string(translationMm));
    EXPECT_LT(setup->rmsPx.all, noiseSigmaDn > 0 ? 0.5 : 0.1);
    EXPECT_LT(rotationDeg, 0.2);
    EXPECT_LT(translationMm, 0.5);
    // What the pipeline uses: table millimetres -> projector pixels, checked across the lit area.
    const Eigen::Isometry3d truthToProjector = rig.tableToProjector * rig.tableToCamera.inverse() * truth;
    for (const Eigen::Vector2d& pointMm : {Eigen::Vector2d(0, 0), Eigen::Vector2d(85.5, 12.5),
                                           Eigen::Vector2d(-60, 100), Eigen::Vector2d(150, -60)}) {
        const Eigen::Vector3d onTable(pointMm.x(), pointMm.y(), 0);
        const Eigen::Vector2d expected = projectPoint(rig.projectorMatrix, truthToProjector, onTable);
        const Eigen::Vector2d found =
            projectPoint(setup->calibration.projectorMatrix, setup->calibration.tableToProjector, onTable);
        EXPECT_LT((found - expected).norm(), 0.5) << pointMm.transpose();
    }
}

INSTANTIATE_TEST_SUITE_P(NoiseFreeAndNoisy, RenderedTable, ::testing::Values(0.0, 2.0));

TEST(TableSetup, WithoutTheRectangleSaysSo) {
    const Calibration rig = distortedRig();
    const Result<PlaneView> captured = test::captureView(rig, std::nullopt, 0.0, 1);
    ASSERT_TRUE(captured.ok()) << captured.failure().message;
    const Result<TableSetup> setup = setUpTable(pairOf(rig), captured.value(), {});
    ASSERT_FALSE(setup.ok());
    EXPECT_THAT(setup.failure().message, HasSubstr("rectangle was not found"));
}

TEST(TableSetup, OptionsThatDoNotValidateAreAProgrammingError) {
    TableSetupOptions options;
    options.maxRmsPx = 0.0;
    EXPECT_THROW((void)setUpTable(pairOf(distortedRig()), PlaneView{}, options), std::invalid_argument);
}

TEST(TableSetup, APairThatNoLongerFitsFailsOnTheReprojectionError) {
    // The projector was knocked 2 degrees since the pair was calibrated.
    const Calibration rig = distortedRig();
    const Result<PlaneView> captured = test::captureView(rig, stripe(), 0.0, 1, pairOf(rig).camera);
    ASSERT_TRUE(captured.ok()) << captured.failure().message;
    ProjectorCameraPair knocked = pairOf(rig);
    knocked.cameraToProjector.prerotate(Eigen::AngleAxisd(2 * M_PI / 180, Eigen::Vector3d::UnitY()));
    const Result<TableSetup> setup = setUpTable(knocked, captured.value(), {});
    ASSERT_FALSE(setup.ok());
    EXPECT_THAT(setup.failure().message, HasSubstr("RMS reprojection error"));
}

}  // namespace
}  // namespace everytouch::core
