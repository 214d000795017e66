#include "service/table_set_up_step.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geometry.h"
#include "support/surface_renderer.h"
#include "support/test_rig.h"

namespace everytouch::service {
namespace {

using ::testing::HasSubstr;

core::Calibration distortedRig() {
    core::Calibration rig = test::paperLikeCalibration();
    rig.cameraDistortion << -0.12, 0.08, 0, 0, 0;
    return rig;
}

// The card's stripe in the white border below the board, where the projector lights the table.
test::DarkRectangle stripeBelowTheBoard(const core::Calibration& rig) {
    const Eigen::Vector2d centre =
        core::applyHomography(rig.tableToProjectorHomography().inverse(), Eigen::Vector2d(320, 420));
    test::DarkRectangle stripe;
    stripe.originMm = centre - Eigen::Vector2d(85.5 / 2, 12.5 / 2);
    return stripe;
}

// Camera frames of the table while the projector shows the set-up board; both frames of a pair alike (the
// code's contribution cancels in the texture anyway).
std::vector<core::FramePair> capturedPairs(const core::Calibration& rig,
                                           std::optional<test::DarkRectangle> card, int count,
                                           double noiseSigmaDn) {
    test::SurfaceScene scene;
    scene.rig = rig;
    if (card)
        scene.rectangles.push_back(*card);
    cv::Mat board;
    core::renderProjectorChessboard(tableSetUpChessboard(), rig.projectorSize, board);
    std::vector<core::FramePair> pairs(count);
    for (int i = 0; i < count; ++i) {
        pairs[i].positive.image = test::renderSurface(scene, board, noiseSigmaDn, 2 * i + 1);
        pairs[i].negative.image = test::renderSurface(scene, board, noiseSigmaDn, 2 * i + 2);
        pairs[i].negative.polarity = core::Polarity::Negative;
    }
    return pairs;
}

TEST(TableSetUpStep, RecoversTheTableAndFitsTheDisplay) {
    const core::Calibration rig = distortedRig();
    const test::DarkRectangle card = stripeBelowTheBoard(rig);
    const EstimateResult result = setUpTableFromPairs(capturedPairs(rig, card, 4, 2.0), rig, {});
    ASSERT_TRUE(result.calibration) << result.problem;
    EXPECT_LT(result.rmsPx, 0.5);
    EXPECT_FALSE(result.calibration->validate()) << *result.calibration->validate();
    // The found table frame is the card's. What the pipeline needs is where table points land in both
    // devices: checked across the lit area against the truth.
    const Eigen::Isometry3d cardToTable(Eigen::Translation3d(card.originMm.x(), card.originMm.y(), 0));
    for (const Eigen::Vector2d& projectorPixel :
         {Eigen::Vector2d(60, 60), Eigen::Vector2d(580, 60), Eigen::Vector2d(580, 420),
          Eigen::Vector2d(60, 420), Eigen::Vector2d(320, 240)}) {
        const Eigen::Vector2d onTable =
            core::applyHomography(rig.tableToProjectorHomography().inverse(), projectorPixel);
        const Eigen::Vector3d onCard = cardToTable.inverse() * Eigen::Vector3d(onTable.x(), onTable.y(), 0);
        const Eigen::Vector2d cameraTruth = core::projectPoint(rig.cameraMatrix, rig.tableToCamera,
                                                               Eigen::Vector3d(onTable.x(), onTable.y(), 0));
        const core::Calibration& found = *result.calibration;
        EXPECT_LT((core::projectPoint(found.projectorMatrix, found.tableToProjector, onCard) - projectorPixel)
                      .norm(),
                  0.5)
            << projectorPixel.transpose();
        EXPECT_LT((core::projectPoint(found.cameraMatrix, found.tableToCamera, onCard) - cameraTruth).norm(),
                  0.5)
            << projectorPixel.transpose();
    }
    EXPECT_EQ(result.calibration->displaySize, rig.displaySize);
}

TEST(TableSetUpStep, SaysWhatIsMissing) {
    const core::Calibration rig = distortedRig();
    EXPECT_THAT(setUpTableFromPairs(capturedPairs(rig, std::nullopt, 1, 0.0), rig, {}).problem,
                HasSubstr("the card: "));
    EXPECT_THAT(
        setUpTableFromPairs(capturedPairs(rig, stripeBelowTheBoard(rig), 1, 0.0), std::nullopt, {}).problem,
        HasSubstr("needs the projector-camera pair's calibration"));
    std::vector<core::FramePair> blank(1);
    blank[0].positive.image = cv::Mat(rig.cameraSize, CV_8UC1, cv::Scalar(180));
    blank[0].negative.image = blank[0].positive.image;
    EXPECT_THAT(setUpTableFromPairs(blank, rig, {}).problem, HasSubstr("the projected chessboard: "));
}

}  // namespace
}  // namespace everytouch::service
