#include "service/projector_step.h"

#include <cstdio>

#include "core/pair_calibration.h"
#include "core/projector_camera_pair.h"
#include "service/pose_capture.h"
#include "service/table_set_up_step.h"

namespace everytouch::service {

namespace {

std::string poseLabel(std::size_t pose, unsigned views) {
    return "Pose " + std::to_string(pose) + " of " + std::to_string(views);
}

// What the user does for the next pose (counted from 1).
std::string instruction(std::size_t pose, unsigned views) {
    if (pose == 1)
        return poseLabel(pose, views) +
               ": lay the card on the table in the white border of the projected chessboard, keep the table "
               "clear and hold still";
    return poseLabel(pose, views) +
           ": tilt the board another way, lay the card on it, hold it in the light of the whole chessboard "
           "and hold still";
}

// The camera as far as it is known: the current calibration's, or a pinhole with the principal point at the
// centre and a focal length of the image width (a typical lens, as the pair calibration starts from).
core::CameraModel knownCamera(const std::optional<core::Calibration>& current, cv::Size cameraSize) {
    if (current && current->cameraSize == cameraSize)
        return core::pairOf(*current).camera;
    core::CameraModel camera;
    const double focal = cameraSize.width;
    camera.matrix << focal, 0, (cameraSize.width - 1) / 2.0, 0, focal, (cameraSize.height - 1) / 2.0, 0, 0, 1;
    return camera;
}

std::string formatSeconds(double seconds) {
    char text[32];
    std::snprintf(text, sizeof text, "%.0f", seconds);
    return text;
}

}  // namespace

EstimateResult calibrateProjectorCameraPairStep(const StepContext& context) {
    const PoseCaptureOptions captureOptions;
    const CalibrationOptions& options = context.options;
    const cv::Size2d cardSizeMm = cardRectangle(options).sizeMm;
    if (const core::Status usable = checkDetectorOptions(options, context.projectorSize); !usable.ok())
        return usable.failure();
    cv::Mat board;
    core::renderProjectorChessboard(tableSetUpChessboard(), context.projectorSize, board);
    context.show(board);
    const double viewShare = 1.0 / (options.views + 1.0);  // the last share is the estimation
    context.progress(0.0, instruction(1, options.views));

    std::optional<PoseCapture> capture;
    cv::Size cameraSize;
    std::int64_t lastViewUs = 0;
    std::string lastProblem;
    while (!capture || capture->views().size() < options.views) {
        std::optional<std::vector<core::FramePair>> pairs = context.capture(1);
        if (!pairs || pairs->empty())
            return core::Failure{"it got no camera frames"};
        const core::FramePair& pair = pairs->front();
        const std::int64_t nowUs = pair.latest().timestampUs;
        if (!capture) {
            cameraSize = pair.latest().image.size();
            capture.emplace(captureOptions, tableSetUpChessboard(), context.projectorSize, cardSizeMm,
                            knownCamera(context.current, cameraSize));
            lastViewUs = nowUs;
        }
        const std::size_t pose = capture->views().size() + 1;
        switch (capture->offer(pair)) {
            case PoseCapture::Event::Captured:
                lastViewUs = nowUs;
                lastProblem.clear();
                if (pose < options.views)
                    context.progress(
                        viewShare * static_cast<double>(pose),
                        poseLabel(pose, options.views) + " taken. " + instruction(pose + 1, options.views));
                continue;
            case PoseCapture::Event::Refused:
                if (capture->problem() != lastProblem) {
                    lastProblem = capture->problem();
                    context.progress(viewShare * static_cast<double>(pose - 1),
                                     poseLabel(pose, options.views) + " not taken: " + lastProblem + ". " +
                                         instruction(pose, options.views));
                }
                break;
            case PoseCapture::Event::Moving:
            case PoseCapture::Event::Settling:
            case PoseCapture::Event::Waiting:
                break;
        }
        if ((nowUs - lastViewUs) * 1e-6 > options.viewTimeoutS)
            return core::Failure{"no pose " + std::to_string(pose) + " of " + std::to_string(options.views) +
                                 " was taken within " + formatSeconds(options.viewTimeoutS) + " s (" +
                                 (lastProblem.empty()
                                      ? std::string("the scene never held still with something new in view")
                                      : "last seen: " + lastProblem) +
                                 ")"};
    }

    context.progress(viewShare * options.views, poseLabel(options.views, options.views) +
                                                    " taken. Estimating the projector-camera pair from " +
                                                    std::to_string(options.views) + " poses");
    core::PairCalibrationOptions pairOptions;
    pairOptions.cameraSize = cameraSize;
    pairOptions.projectorSize = context.projectorSize;
    pairOptions.rectangleSizeMm = cardSizeMm;
    const core::Result<core::PairCalibration> pair =
        core::calibrateProjectorCameraPair(capture->views(), pairOptions);
    if (!pair.ok())
        return pair.failure();

    EstimateResult result =
        calibrationOverTable(pair->pair, capture->views().front(), cardSizeMm,
                             context.current ? context.current->displaySize : context.projectorSize);
    if (!result.ok())
        return core::Failure{"the table in pose 1: " + result.failure().message};
    result->rmsPx = pair->rmsPx.all;
    result->scene = capture->lastViewTexture();
    return result;
}

}  // namespace everytouch::service
