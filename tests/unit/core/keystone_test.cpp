#include "core/keystone.h"

#include <array>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/test_rig.h"

namespace everytouch::core {
namespace {

using ::testing::HasSubstr;

// The display's outer corners (pixel edges) mapped by `displayToProjector`, grown about the display's centre
// by `growth` (1.01 = 1 % larger).
std::array<Eigen::Vector2d, 4> displayCornersOnPanel(const Eigen::Matrix3d& displayToProjector,
                                                     cv::Size display, double growth = 1.0) {
    const Eigen::Vector2d centre((display.width - 1) / 2.0, (display.height - 1) / 2.0);
    const Eigen::Vector2d half(display.width / 2.0, display.height / 2.0);
    std::array<Eigen::Vector2d, 4> corners;
    const std::array<Eigen::Vector2d, 4> signs = {Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1),
                                                  Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1)};
    for (int index = 0; index < 4; ++index)
        corners[index] =
            applyHomography(displayToProjector, centre + growth * half.cwiseProduct(signs[index]));
    return corners;
}

bool insidePanel(const Eigen::Vector2d& point, cv::Size panel) {
    constexpr double kSlack = 1e-6;
    return point.x() >= -0.5 - kSlack && point.y() >= -0.5 - kSlack &&
           point.x() <= panel.width - 0.5 + kSlack && point.y() <= panel.height - 0.5 + kSlack;
}

void expectUndistortedMaximalDisplay(const Calibration& rig, cv::Size display) {
    const Result<KeystoneFit> fit = fitDisplayToTable(rig, display);
    ASSERT_TRUE(fit.ok()) << fit.failure().message;

    // Inside the lit area.
    for (const Eigen::Vector2d& corner : displayCornersOnPanel(fit->displayToProjector, display))
        EXPECT_TRUE(insidePanel(corner, rig.projectorSize)) << corner.transpose();

    // Undistorted on the table: display pixels land on an axis-aligned grid of square cells.
    Calibration withDisplay = rig;
    withDisplay.displaySize = display;
    withDisplay.displayToProjector = fit->displayToProjector;
    const Eigen::Matrix3d displayToTable = withDisplay.displayToTableHomography();
    const Eigen::Vector2d origin = applyHomography(displayToTable, {0, 0});
    const Eigen::Vector2d alongX = applyHomography(displayToTable, {display.width - 1.0, 0}) - origin;
    const Eigen::Vector2d alongY = applyHomography(displayToTable, {0, display.height - 1.0}) - origin;
    const Eigen::Vector2d farCorner =
        applyHomography(displayToTable, {display.width - 1.0, display.height - 1.0}) - origin;
    EXPECT_LT((farCorner - alongX - alongY).norm(), 1e-9);  // a parallelogram: no perspective left
    EXPECT_NEAR(alongX.dot(alongY), 0.0, 1e-9);             // right angles
    EXPECT_TRUE(std::abs(alongX.x()) < 1e-9 || std::abs(alongX.y()) < 1e-9);  // sides along the table's axes
    EXPECT_NEAR(alongX.norm() / (display.width - 1.0), alongY.norm() / (display.height - 1.0),
                1e-9);  // square px
    const cv::Size2d sizeMm = withDisplay.displaySizeMm();
    EXPECT_NEAR(sizeMm.width / sizeMm.height, static_cast<double>(display.width) / display.height, 1e-9);
    EXPECT_NEAR(sizeMm.width * sizeMm.height, fit->tableRectangleMm.volume(), 1e-6);  // where it says it is

    // Maximal: grown by 1 % it leaves the lit area.
    bool leaves = false;
    for (const Eigen::Vector2d& corner : displayCornersOnPanel(fit->displayToProjector, display, 1.01))
        leaves = leaves || !insidePanel(corner, rig.projectorSize);
    EXPECT_TRUE(leaves);

    // Not mirrored: the display keeps the projector's handedness.
    const Eigen::Vector2d centre =
        applyHomography(fit->displayToProjector, {display.width / 2.0, display.height / 2.0});
    const Eigen::Vector2d right =
        applyHomography(fit->displayToProjector, {display.width / 2.0 + 1, display.height / 2.0});
    const Eigen::Vector2d down =
        applyHomography(fit->displayToProjector, {display.width / 2.0, display.height / 2.0 + 1});
    EXPECT_GT((right - centre).x() * (down - centre).y() - (right - centre).y() * (down - centre).x(), 0.0);
    EXPECT_GT((right - centre).x(), 0.0);  // and its x axis runs along the projector's
}

TEST(Keystone, PaperLikeRigGetsTheLargestUndistortedDisplay) {
    expectUndistortedMaximalDisplay(test::paperLikeCalibration(), {1280, 960});
    const Eigen::Vector2d sizeMm =
        fitDisplayToTable(test::paperLikeCalibration(), {1280, 960})->tableRectangleMm.sizes();
    RecordProperty("display_width_mm", std::to_string(sizeMm.x()));
    RecordProperty("display_height_mm", std::to_string(sizeMm.y()));
}

TEST(Keystone, WideAndTallDisplaysFitToo) {
    expectUndistortedMaximalDisplay(test::paperLikeCalibration(), {1920, 1080});
    expectUndistortedMaximalDisplay(test::paperLikeCalibration(), {600, 1000});
}

TEST(Keystone, FollowsTheTableAxesWhereverTheCardPutThem) {
    // A card laid down at 70 degrees to the projector's rows: the display turns with the table's axes, to the
    // axis nearest the projector's rows.
    Calibration rig = test::paperLikeCalibration();
    rig.tableToProjector =
        rig.tableToProjector * Eigen::AngleAxisd(70 * M_PI / 180, Eigen::Vector3d::UnitZ());
    rig.tableToCamera = rig.tableToCamera * Eigen::AngleAxisd(70 * M_PI / 180, Eigen::Vector3d::UnitZ());
    expectUndistortedMaximalDisplay(rig, {1280, 960});
}

TEST(Keystone, FailsWhenTheImageDoesNotLandOnTheTable) {
    Calibration rig = test::paperLikeCalibration();
    // Tilt the projector up by 60 degrees: its top rows look above the horizon.
    rig.tableToProjector =
        Eigen::AngleAxisd(-60 * M_PI / 180, Eigen::Vector3d::UnitX()) * rig.tableToProjector;
    const Result<KeystoneFit> fit = fitDisplayToTable(rig, {1280, 960});
    ASSERT_FALSE(fit.ok());
    EXPECT_THAT(fit.failure().message, HasSubstr("never reaches the table"));
}

TEST(Keystone, TheDisplayThroughItsFitLandsAsAnUprightRectangle) {
    Calibration rig = test::paperLikeCalibration();
    rig.displaySize = {1280, 960};
    rig.displayToProjector = fitDisplayToTable(rig, rig.displaySize)->displayToProjector;
    const DisplayShape shape = displayShapeOnTable(rig);
    EXPECT_NEAR(shape.leastCornerDeg, 90.0, 1e-6);
    EXPECT_NEAR(shape.largestCornerDeg, 90.0, 1e-6);
    EXPECT_NEAR(shape.topMm, shape.bottomMm, 1e-6);
    EXPECT_NEAR(shape.leftMm, shape.rightMm, 1e-6);
    EXPECT_NEAR(shape.topMm / shape.leftMm, 1280.0 / 960.0, 1e-6);
}

TEST(Keystone, TheWholePanelOfATiltedProjectorLandsAsNoRectangle) {
    Calibration rig = test::paperLikeCalibration();
    rig.tableToProjector =
        Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitX()) * rig.tableToProjector;
    rig.displaySize = rig.projectorSize;
    rig.displayToProjector = Eigen::Matrix3d::Identity();
    const DisplayShape shape = displayShapeOnTable(rig);
    // The whole panel of a projector tilted further throws one side longer than the one opposite.
    EXPECT_GT(std::abs(shape.topMm - shape.bottomMm), 0.02 * shape.topMm);
    EXPECT_LT(shape.leastCornerDeg, 89.0);
    EXPECT_GT(shape.largestCornerDeg, 91.0);
}

}  // namespace
}  // namespace everytouch::core
