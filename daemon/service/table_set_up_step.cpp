#include "service/table_set_up_step.h"

#include <cstdio>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/gray_frame.h"
#include "core/keystone.h"
#include "core/plane_view.h"
#include "core/projector_camera_pair.h"
#include "core/table_rectangle.h"
#include "core/table_setup.h"
#include "service/pose_capture.h"

namespace everytouch::service {

namespace {

// The scene without the code, averaged over the pairs: the noise of n pairs drops by sqrt(n).
cv::Mat averageTexture(const std::vector<core::FramePair>& pairs) {
    cv::Mat subtraction, texture, sum;
    for (const core::FramePair& pair : pairs) {
        core::computeSubtractionAndTexture(pair, subtraction, texture);
        if (sum.empty())
            sum = cv::Mat::zeros(texture.size(), CV_MAKETYPE(CV_32F, texture.channels()));
        cv::accumulate(texture, sum);
    }
    cv::Mat average;
    sum.convertTo(average, CV_8U, 1.0 / static_cast<double>(pairs.size()));
    return average;
}

// Waits, pair by pair, until the scene differs from `previous` (the scene the step before measured last,
// 8-bit gray) and holds still, and gives the still spell's average texture (gray); fails when that does not
// happen within the options' view time-out. The change is judged against that scene, not against the first
// pair seen here: the board may have gone while the step before was still estimating.
core::Result<cv::Mat> awaitNewStillScene(const StepContext& context, const cv::Mat& previous) {
    const PoseCaptureOptions options;
    StillnessTracker stillness{options};
    cv::Mat subtraction, texture, gray, still;
    bool looked = false;  // the current still spell was compared with `previous` already
    std::optional<std::int64_t> startUs;
    while (true) {
        const std::optional<std::vector<core::FramePair>> pairs = context.capture(1);
        if (!pairs || pairs->empty())
            return core::Failure{"it got no camera frames"};
        const core::FramePair& pair = pairs->front();
        core::computeSubtractionAndTexture(pair, subtraction, texture);
        if (const core::Status frame = core::grayFrame(texture, gray); !frame.ok())
            return core::Failure{"the camera frames: " + frame.failure().message};
        const std::int64_t nowUs = pair.latest().timestampUs;
        if (!startUs)
            startUs = nowUs;
        const StillnessTracker::State state = stillness.offer(gray, nowUs);
        if (state == StillnessTracker::State::Changed)
            looked = false;
        if (state == StillnessTracker::State::Still && !looked) {
            looked = true;
            stillness.average(still);
            if (still.size() != previous.size() ||
                changedFraction(previous, still, options.changeSigmas) >= options.maxChangedFraction)
                return still;
        }
        if ((nowUs - *startUs) * 1e-6 > context.options.viewTimeoutS)
            return core::Failure{"the scene did not change and hold still again within " +
                                 std::to_string(static_cast<int>(context.options.viewTimeoutS)) + " s"};
    }
}

}  // namespace

core::ChessboardOptions tableSetUpChessboard() {
    core::ChessboardOptions options;
    options.squarePx = 40;
    return options;
}

core::TableRectangleOptions cardRectangle(const CalibrationOptions& options) {
    core::TableRectangleOptions card;
    card.sizeMm = {options.cardWidthMm, options.cardHeightMm};
    return card;
}

core::Status checkDetectorOptions(const CalibrationOptions& options, cv::Size projectorSize) {
    if (const std::optional<std::string> problem = tableSetUpChessboard().validate(projectorSize))
        return core::Failure{"the projected chessboard: " + *problem};
    if (const std::optional<std::string> problem = cardRectangle(options).validate())
        return core::Failure{"the card: " + *problem};
    return {};
}

EstimateResult setUpTableStep(const StepContext& context) {
    if (!context.current)
        return core::Failure{
            "it needs the projector-camera pair's calibration (both lenses and their pose), and "
            "there is none; run the projector step first"};
    if (const core::Status usable = checkDetectorOptions(context.options, context.projectorSize);
        !usable.ok())
        return usable.failure();
    cv::Mat board;
    core::renderProjectorChessboard(tableSetUpChessboard(), context.projectorSize, board);
    context.show(board);
    const std::string prompt =
        "The projector shows a chessboard: keep the table clear and lay the card flat in the white border "
        "below the board";
    if (!context.previousScene.empty()) {
        // The scene may still show the previous step's last pose: wait until it differs from that and holds
        // still, and use what it showed while still.
        context.progress(0.0, "Take the board away. " + prompt);
        const core::Result<cv::Mat> texture = awaitNewStillScene(context, context.previousScene);
        if (!texture.ok())
            return texture.failure();
        context.progress(0.5, "Estimating the table's pose from the chessboard and the card");
        return setUpTableFromTexture(texture.value(), *context.current, context.options);
    }
    context.progress(0.0, prompt);
    const std::optional<std::vector<core::FramePair>> pairs = context.capture(context.options.pairsPerStep);
    if (!pairs)
        return core::Failure{"it got no camera frames"};
    context.progress(0.5, "Estimating the table's pose from the chessboard and the card");
    return setUpTableFromPairs(*pairs, context.current, context.options);
}

EstimateResult setUpTableFromPairs(const std::vector<core::FramePair>& pairs,
                                   const std::optional<core::Calibration>& current,
                                   const CalibrationOptions& options) {
    if (!current)
        return core::Failure{
            "it needs the projector-camera pair's calibration (both lenses and their pose), and "
            "there is none"};
    if (pairs.empty())
        return core::Failure{"no frames"};
    return setUpTableFromTexture(averageTexture(pairs), *current, options);
}

EstimateResult setUpTableFromTexture(const cv::Mat& texture, const core::Calibration& current,
                                     const CalibrationOptions& options) {
    if (const core::Status usable = checkDetectorOptions(options, current.projectorSize); !usable.ok())
        return usable.failure();
    const core::ProjectorCameraPair pair = core::pairOf(current);

    const core::Result<core::ChessboardDetection> board =
        core::detectProjectedChessboard(texture, tableSetUpChessboard(), current.projectorSize);
    if (!board.ok())
        return core::Failure{"the projected chessboard: " + board.failure().message};
    const core::Result<core::TableRectangleDetection> card =
        core::findTableRectangle(texture, cardRectangle(options), pair.camera);
    if (!card.ok())
        return core::Failure{"the card: " + card.failure().message};

    core::PlaneView table;
    table.cameraPoints = board->cameraCorners;
    table.projectorPoints = board->projectorCorners;
    std::array<Eigen::Vector2d, 4> rawCorners;
    for (std::size_t corner = 0; corner < rawCorners.size(); ++corner)
        rawCorners[corner] = pair.camera.distortPixel(card->corners[corner]);
    table.rectangleCorners = rawCorners;
    EstimateResult estimate =
        calibrationOverTable(pair, table, cardRectangle(options).sizeMm, current.displaySize);
    if (!estimate.ok())
        return estimate;
    if (const core::Status gray = core::grayFrame(texture, estimate->scene); !gray.ok())
        return core::Failure{"the camera frames: " + gray.failure().message};
    return estimate;
}

EstimateResult calibrationOverTable(const core::ProjectorCameraPair& pair, const core::PlaneView& table,
                                    cv::Size2d cardSizeMm, cv::Size displaySize) {
    core::TableSetupOptions setUpOptions;
    setUpOptions.rectangleSizeMm = cardSizeMm;
    const core::Result<core::TableSetup> setUp = core::setUpTable(pair, table, setUpOptions);
    if (!setUp.ok())
        return setUp.failure();

    Estimate estimate{setUp->calibration, setUp->rmsPx.all, cv::Mat()};
    estimate.calibration.displaySize = displaySize;
    const core::Result<core::KeystoneFit> keystone =
        core::fitDisplayToTable(estimate.calibration, displaySize);
    if (!keystone.ok())
        return core::Failure{"fitting the display into the lit area: " + keystone.failure().message};
    estimate.calibration.displayToProjector = keystone->displayToProjector;
    return estimate;
}

}  // namespace everytouch::service
