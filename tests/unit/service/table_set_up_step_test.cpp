#include "service/table_set_up_step.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/code_image.h"
#include "core/geometry.h"
#include "core/gray_frame.h"
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
    ASSERT_TRUE(result.ok()) << result.failure().message;
    EXPECT_LT(result->rmsPx, 0.5);
    EXPECT_FALSE(result->calibration.validate()) << *result->calibration.validate();
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
        const core::Calibration& found = result->calibration;
        EXPECT_LT((core::projectPoint(found.projectorMatrix, found.tableToProjector, onCard) - projectorPixel)
                      .norm(),
                  0.5)
            << projectorPixel.transpose();
        EXPECT_LT((core::projectPoint(found.cameraMatrix, found.tableToCamera, onCard) - cameraTruth).norm(),
                  0.5)
            << projectorPixel.transpose();
    }
    EXPECT_EQ(result->calibration.displaySize, rig.displaySize);
}

TEST(TableSetUpStep, SaysWhatIsMissing) {
    const core::Calibration rig = distortedRig();
    EXPECT_THAT(setUpTableFromPairs(capturedPairs(rig, std::nullopt, 1, 0.0), rig, {}).failure().message,
                HasSubstr("the card: "));
    EXPECT_THAT(setUpTableFromPairs(capturedPairs(rig, stripeBelowTheBoard(rig), 1, 0.0), std::nullopt, {})
                    .failure()
                    .message,
                HasSubstr("needs the projector-camera pair's calibration"));
    std::vector<core::FramePair> blank(1);
    blank[0].positive.image = cv::Mat(rig.cameraSize, CV_8UC1, cv::Scalar(180));
    blank[0].negative.image = blank[0].positive.image;
    EXPECT_THAT(setUpTableFromPairs(blank, rig, {}).failure().message,
                HasSubstr("the projected chessboard: "));
}

TEST(TableSetUpStep, RefusesOptionsTheDetectorsCannotWorkWith) {
    const core::Calibration rig = distortedRig();
    CalibrationOptions upright;
    upright.cardWidthMm = 12.5;
    upright.cardHeightMm = 85.5;
    EXPECT_EQ(checkDetectorOptions(upright, rig.projectorSize).failure().message,
              "the card: rectangle size_mm: give the longer side first");
    EXPECT_EQ(setUpTableFromPairs(capturedPairs(rig, stripeBelowTheBoard(rig), 1, 0.0), rig, upright)
                  .failure()
                  .message,
              "the card: rectangle size_mm: give the longer side first");
    EXPECT_THAT(checkDetectorOptions({}, {320, 240}).failure().message,
                HasSubstr("the projected chessboard: chessboard square_px"));
    EXPECT_TRUE(checkDetectorOptions({}, rig.projectorSize).ok());
}

}  // namespace
}  // namespace everytouch::service

namespace everytouch::service {
namespace {

// A stream of pairs: `seconds` of each scene in turn, 30 pairs per second, each scene's pairs alternating
// between two renderings so that the noise changes.
std::vector<core::FramePair> sceneStream(
    const std::vector<std::pair<std::vector<core::FramePair>, double>>& scenes) {
    std::vector<core::FramePair> stream;
    for (const auto& [renderings, seconds] : scenes)
        for (int i = 0; i < seconds * 30; ++i) {
            core::FramePair pair = renderings[static_cast<std::size_t>(i) % renderings.size()];
            pair.positive.timestampUs = static_cast<std::int64_t>(stream.size()) * 33'333;
            pair.negative.timestampUs = pair.positive.timestampUs + 16'666;
            pair.positive.index = 2 * stream.size();
            pair.negative.index = pair.positive.index + 1;
            stream.push_back(pair);
        }
    return stream;
}

// The scene a pair shows without the code, in gray: what a step leaves as its Estimate::scene.
cv::Mat grayTexture(const core::FramePair& pair) {
    cv::Mat subtraction, texture, gray;
    core::computeSubtractionAndTexture(pair, subtraction, texture);
    EXPECT_TRUE(core::grayFrame(texture, gray).ok());
    return gray;
}

EstimateResult runAfterAnotherStep(const std::vector<core::FramePair>& stream, const core::Calibration& rig,
                                   double viewTimeoutS, const cv::Mat& previousScene) {
    CalibrationOptions options;
    options.pairsPerStep = 4;
    options.viewTimeoutS = viewTimeoutS;
    const std::optional<core::Calibration> current = rig;
    std::size_t next = 0;
    const StepContext context{options,
                              current,
                              rig.projectorSize,
                              [&](std::size_t count) -> std::optional<std::vector<core::FramePair>> {
                                  if (next + count > stream.size())
                                      return std::nullopt;
                                  next += count;
                                  return std::vector<core::FramePair>(
                                      stream.begin() + static_cast<std::ptrdiff_t>(next - count),
                                      stream.begin() + static_cast<std::ptrdiff_t>(next));
                              },
                              [](const cv::Mat&) {},
                              [](double, const std::string&) {},
                              previousScene};
    return setUpTableStep(context);
}

TEST(TableSetUpStep, AfterAnotherStepWaitsUntilTheBoardIsTakenAway) {
    const core::Calibration rig = distortedRig();
    const Eigen::Vector3d middle(160, 230, 0);
    const Eigen::Isometry3d tilt = Eigen::Translation3d(middle + Eigen::Vector3d(0, 0, 50)) *
                                   Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                   Eigen::Translation3d(-middle);
    // The board of the previous step's last pose, without the card: the set-up fails on it.
    const std::vector<core::FramePair> board =
        capturedPairs(test::onSurface(rig, tilt), std::nullopt, 1, 2.0);
    const std::vector<core::FramePair> table = capturedPairs(rig, stripeBelowTheBoard(rig), 2, 2.0);
    const cv::Mat lastPose = grayTexture(board.front());
    const EstimateResult result =
        runAfterAnotherStep(sceneStream({{board, 1.0}, {table, 2.0}}), rig, 10.0, lastPose);
    ASSERT_TRUE(result.ok()) << result.failure().message;
    EXPECT_LT(result->rmsPx, 0.5);
    EXPECT_EQ(result->scene.size(), rig.cameraSize);
    EXPECT_EQ(result->scene.type(), CV_8UC1);

    const EstimateResult waited = runAfterAnotherStep(sceneStream({{board, 3.0}}), rig, 2.0, lastPose);
    ASSERT_FALSE(waited.ok());
    EXPECT_EQ(waited.failure().message, "the scene did not change and hold still again within 2 s");
}

TEST(TableSetUpStep, AfterAnotherStepTakesABoardGoneBeforeItBegan) {
    // The user took the board away while the step before was still estimating: the first pair this step
    // sees already shows the table.
    const core::Calibration rig = distortedRig();
    const Eigen::Vector3d middle(160, 230, 0);
    const Eigen::Isometry3d tilt = Eigen::Translation3d(middle + Eigen::Vector3d(0, 0, 50)) *
                                   Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                   Eigen::Translation3d(-middle);
    const cv::Mat lastPose =
        grayTexture(capturedPairs(test::onSurface(rig, tilt), std::nullopt, 1, 2.0).front());
    const std::vector<core::FramePair> table = capturedPairs(rig, stripeBelowTheBoard(rig), 2, 2.0);
    const EstimateResult result = runAfterAnotherStep(sceneStream({{table, 2.0}}), rig, 10.0, lastPose);
    ASSERT_TRUE(result.ok()) << result.failure().message;
    EXPECT_LT(result->rmsPx, 0.5);
}

}  // namespace
}  // namespace everytouch::service
