#include "support/bit_error_rate.h"

#include <opencv2/core.hpp>

#include "core/code_sampling.h"
#include "core/geometry.h"
#include "core/pattern.h"

namespace everytouch::test {

namespace {

// Projector pixels whose camera position lies at least `margin` pixels inside the camera image.
cv::Mat visibleProjectorPixels(const core::Calibration& calibration, int margin) {
    const Eigen::Matrix3d h = calibration.projectorToCameraHomography(0.0);
    cv::Mat visible(calibration.projectorSize, CV_8UC1);
    const cv::Rect2d inside(margin, margin, calibration.cameraSize.width - 2.0 * margin,
                            calibration.cameraSize.height - 2.0 * margin);
    for (int y = 0; y < visible.rows; ++y)
        for (int x = 0; x < visible.cols; ++x) {
            const Eigen::Vector2d camera = core::applyHomography(h, Eigen::Vector2d(x, y));
            visible.at<uchar>(y, x) = inside.contains({camera.x(), camera.y()});
        }
    return visible;
}

}  // namespace

BitErrorFigures measureBitErrors(const SyntheticScene& scene, const core::Calibration& calibration,
                                 const core::BinarizationOptions& binarization) {
    constexpr int kWindow = 6;
    cv::Mat subtraction, texture, localMean, codeImage;
    core::computeSubtractionAndTexture(renderCapture(scene), subtraction, texture);
    core::binarizeSubtraction(subtraction, scene.grayCamera ? 1 : 3, binarization, localMean, codeImage);
    core::WindowAgreement onTable, elevated;
    core::matchAllWindows(codeImage, calibration.projectorToCameraHomography(0.0), scene.pattern, kWindow,
                          onTable);
    core::matchAllWindows(codeImage, calibration.projectorToCameraHomography(10.0), scene.pattern, kWindow,
                          elevated);

    const cv::Mat visible = visibleProjectorPixels(calibration, binarization.neighbourhood);
    const cv::Rect anchors = core::codedRegion(scene.pattern.size(), kWindow);
    BitErrorFigures figures;
    double bits = 0, known = 0, wrong = 0, windows = 0;
    for (int y = 0; y < visible.rows; ++y)
        for (int x = 0; x < visible.cols; ++x) {
            if (!visible.at<uchar>(y, x))
                continue;
            const uchar seen = onTable.observed.at<uchar>(y, x);
            bits += 1;
            if (seen != core::kUnknownBit) {
                known += 1;
                wrong += seen != scene.pattern.at<uchar>(y, x);
            }
            // A window is in view when its top-left pixel is too (the view is convex).
            if (anchors.contains({x, y}) && visible.at<uchar>(y - kWindow + 1, x - kWindow + 1)) {
                windows += 1;
                figures.tableMismatches += onTable.mismatches.at<uchar>(y, x);
                figures.tableKnown += onTable.known.at<uchar>(y, x);
                figures.elevatedMismatches += elevated.mismatches.at<uchar>(y, x);
            }
        }
    figures.bitErrorRate = known > 0 ? wrong / known : 0.5;
    figures.unknownRate = 1.0 - known / bits;
    figures.tableMismatches /= windows;
    figures.tableKnown /= windows;
    figures.elevatedMismatches /= windows;
    return figures;
}

}  // namespace everytouch::test
