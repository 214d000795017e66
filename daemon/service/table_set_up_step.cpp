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

// Waits, pair by pair, until the scene has changed and then held still, and gives the still spell's average
// texture (gray); the problem when it does not within the options' view time-out.
std::optional<std::string> awaitNewStillScene(const StepContext& context, cv::Mat& stillTexture) {
    StillnessTracker stillness{PoseCaptureOptions()};
    cv::Mat subtraction, texture, gray;
    bool changed = false;
    std::optional<std::int64_t> startUs;
    while (true) {
        const std::optional<std::vector<core::FramePair>> pairs = context.capture(1);
        if (!pairs || pairs->empty())
            return "it got no camera frames";
        const core::FramePair& pair = pairs->front();
        core::computeSubtractionAndTexture(pair, subtraction, texture);
        if (const std::optional<std::string> problem = core::grayFrame(texture, gray))
            return "the camera frames: " + *problem;
        const std::int64_t nowUs = pair.latest().timestampUs;
        const StillnessTracker::State state = stillness.offer(gray, nowUs);
        if (!startUs) {
            startUs = nowUs;
            continue;
        }
        changed = changed || state == StillnessTracker::State::Changed;
        if (changed && state == StillnessTracker::State::Still) {
            stillness.average(stillTexture);
            return std::nullopt;
        }
        if ((nowUs - *startUs) * 1e-6 > context.options.viewTimeoutS)
            return "the scene did not change and hold still again within " +
                   std::to_string(static_cast<int>(context.options.viewTimeoutS)) + " s";
    }
}

}  // namespace

core::ChessboardOptions tableSetUpChessboard() {
    core::ChessboardOptions options;
    options.squarePx = 40;
    return options;
}

EstimateResult setUpTableStep(const StepContext& context) {
    if (!context.current)
        return EstimateResult::failed(
            "it needs the projector-camera pair's calibration (both lenses and their pose), and "
            "there is none; run the projector step first");
    cv::Mat board;
    core::renderProjectorChessboard(tableSetUpChessboard(), context.projectorSize, board);
    context.show(board);
    const std::string prompt =
        "The projector shows a chessboard: keep the table clear and lay the card flat in the white border "
        "below the board";
    if (context.followsAnotherStep) {
        // The scene still shows the previous step's last pose: wait until it has changed and holds still,
        // and use what it showed while still.
        context.progress(0.0, "Take the board away. " + prompt);
        cv::Mat texture;
        if (const std::optional<std::string> problem = awaitNewStillScene(context, texture))
            return EstimateResult::failed(*problem);
        context.progress(0.5, "Estimating the table's pose from the chessboard and the card");
        return setUpTableFromTexture(texture, *context.current, context.options);
    }
    context.progress(0.0, prompt);
    const std::optional<std::vector<core::FramePair>> pairs = context.capture(context.options.pairsPerStep);
    if (!pairs)
        return EstimateResult::failed("it got no camera frames");
    context.progress(0.5, "Estimating the table's pose from the chessboard and the card");
    return setUpTableFromPairs(*pairs, context.current, context.options);
}

EstimateResult setUpTableFromPairs(const std::vector<core::FramePair>& pairs,
                                   const std::optional<core::Calibration>& current,
                                   const CalibrationOptions& options) {
    if (!current)
        return EstimateResult::failed(
            "it needs the projector-camera pair's calibration (both lenses and their pose), and "
            "there is none");
    if (pairs.empty())
        return EstimateResult::failed("no frames");
    return setUpTableFromTexture(averageTexture(pairs), *current, options);
}

EstimateResult setUpTableFromTexture(const cv::Mat& texture, const core::Calibration& current,
                                     const CalibrationOptions& options) {
    const core::ProjectorCameraPair pair = core::pairOf(current);

    const core::ChessboardDetection board =
        core::detectProjectedChessboard(texture, tableSetUpChessboard(), current.projectorSize);
    if (!board.success)
        return EstimateResult::failed("the projected chessboard: " + board.message);
    core::TableRectangleOptions cardOptions;
    cardOptions.sizeMm = {options.cardWidthMm, options.cardHeightMm};
    const core::TableRectangleDetection card = core::findTableRectangle(texture, cardOptions, pair.camera);
    if (!card.success)
        return EstimateResult::failed("the card: " + card.message);

    core::PlaneView table;
    table.cameraPoints = board.cameraCorners;
    table.projectorPoints = board.projectorCorners;
    std::array<Eigen::Vector2d, 4> rawCorners;
    for (std::size_t corner = 0; corner < rawCorners.size(); ++corner)
        rawCorners[corner] = pair.camera.distortPixel(card.corners[corner]);
    table.rectangleCorners = rawCorners;
    return calibrationOverTable(pair, table, cardOptions.sizeMm, current.displaySize);
}

EstimateResult calibrationOverTable(const core::ProjectorCameraPair& pair, const core::PlaneView& table,
                                    cv::Size2d cardSizeMm, cv::Size displaySize) {
    core::TableSetupOptions setUpOptions;
    setUpOptions.rectangleSizeMm = cardSizeMm;
    const core::TableSetup setUp = core::setUpTable(pair, table, setUpOptions);
    if (!setUp.success)
        return EstimateResult::failed(setUp.message);

    EstimateResult result;
    result.calibration = setUp.calibration;
    result.calibration->displaySize = displaySize;
    const core::KeystoneFit keystone = core::fitDisplayToTable(*result.calibration, displaySize);
    if (!keystone.success)
        return EstimateResult::failed("fitting the display into the lit area: " + keystone.message);
    result.calibration->displayToProjector = keystone.displayToProjector;
    result.rmsPx = setUp.rmsPx.all;
    return result;
}

}  // namespace everytouch::service
