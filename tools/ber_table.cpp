// everytouch-ber: bit-error rate of the code binarisation on synthetic captures, against the code amplitude
// delta and the camera noise, as a Markdown table (docs/structured-light.md).
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "core/code_image.h"
#include "core/code_sampling.h"
#include "core/geometry.h"
#include "core/pattern.h"
#include "support/synthetic_capture.h"

namespace {

using namespace everytouch;

struct Figures {
    double bitErrorRate = 0;        // wrong bits / known bits, over projector pixels the camera sees
    double unknownRate = 0;         // unknown bits / bits
    double tableMismatches = 0;     // mean Hamming distance of a window through the table's homography
    double tableKnown = 0;          // mean known bits of a window
    double elevatedMismatches = 0;  // mean Hamming distance through the homography of a plane 10 mm higher
};

// Projector pixels whose camera position lies at least `margin` pixels inside the camera image.
cv::Mat visibleProjectorPixels(const core::Calibration& calibration, int margin) {
    const Eigen::Matrix3d h = calibration.projectorToCameraHomography(0.0);
    cv::Mat visible(calibration.projectorSize, CV_8UC1);
    const cv::Rect inside(margin, margin, calibration.cameraSize.width - 2 * margin,
                          calibration.cameraSize.height - 2 * margin);
    for (int y = 0; y < visible.rows; ++y)
        for (int x = 0; x < visible.cols; ++x) {
            const Eigen::Vector2d camera = core::applyHomography(h, {x, y});
            visible.at<uchar>(y, x) = inside.contains(cv::Point2d(camera.x(), camera.y()));
        }
    return visible;
}

Figures measure(const test::SyntheticScene& scene, const core::Calibration& calibration,
                const cv::Mat& visible, const core::BinarizationOptions& binarization) {
    const int window = 6;
    cv::Mat subtraction, texture, localMean, codeImage;
    core::computeSubtractionAndTexture(test::renderCapture(scene), subtraction, texture);
    core::binarizeSubtraction(subtraction, scene.grayCamera ? 1 : 3, binarization, localMean, codeImage);
    core::WindowAgreement onTable, elevated;
    core::matchAllWindows(codeImage, calibration.projectorToCameraHomography(0.0), scene.pattern, window,
                          onTable);
    core::matchAllWindows(codeImage, calibration.projectorToCameraHomography(10.0), scene.pattern, window,
                          elevated);

    Figures figures;
    double bits = 0, known = 0, wrong = 0, windows = 0;
    const cv::Rect anchors = core::codedRegion(scene.pattern.size(), window);
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
            // Windows entirely in view: their top-left pixel is visible too.
            if (anchors.contains({x, y}) && visible.at<uchar>(y - window + 1, x - window + 1)) {
                windows += 1;
                figures.tableMismatches += onTable.mismatches.at<uchar>(y, x);
                figures.tableKnown += onTable.known.at<uchar>(y, x);
                figures.elevatedMismatches += elevated.mismatches.at<uchar>(y, x);
            }
        }
    figures.bitErrorRate = wrong / known;
    figures.unknownRate = 1.0 - known / bits;
    figures.tableMismatches /= windows;
    figures.tableKnown /= windows;
    figures.elevatedMismatches /= windows;
    return figures;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Bit-error rate of the code binarisation on synthetic captures of the paper-like rig"};
    double lensMm = 6.0;
    bool gray = false;
    core::BinarizationOptions binarization;
    app.add_option("--lens-mm", lensMm, "camera focal length, mm (6: the paper-like rig)")
        ->check(CLI::PositiveNumber);
    app.add_flag("--gray", gray, "a gray camera instead of a colour one");
    app.add_option("--neighbourhood", binarization.neighbourhood, "binarisation neighbourhood, camera px");
    app.add_option("--mixture-margin", binarization.mixtureMargin, "binarisation mixture margin");
    app.add_option("--max-error-probability", binarization.maxErrorProbability,
                   "binarisation: unknown above");
    app.add_option("--min-amplitude-sigmas", binarization.minAmplitudeSigmas, "binarisation: unknown below");
    CLI11_PARSE(app, argc, argv);

    const core::Calibration calibration = test::paperLikeCalibrationWithLens(lensMm);
    test::SyntheticScene scene;
    scene.pattern = core::generatePattern({});
    scene.content = test::testContent(calibration.projectorSize);
    scene.projectorToCamera = calibration.projectorToCameraHomography(0.0);
    scene.cameraSize = calibration.cameraSize;
    scene.albedo = test::testAlbedo(calibration.cameraSize);
    scene.grayCamera = gray;
    const cv::Mat visible = visibleProjectorPixels(calibration, binarization.neighbourhood);
    const Eigen::Matrix3d h = calibration.projectorToCameraHomography(0.0);
    const Eigen::Vector2d centre(calibration.projectorSize.width / 2.0,
                                 calibration.projectorSize.height / 2.0);
    const double scale =
        (core::applyHomography(h, centre + Eigen::Vector2d(1, 0)) - core::applyHomography(h, centre)).norm();

    std::printf(
        "lens %.1f mm (%.2f camera px per projector px), %s camera, gain %.2f, ambient %.0f DN, "
        "albedo 0.25..0.9, neighbourhood %d, max error probability %.2f, min amplitude %.1f sigma, mixture "
        "margin %.2f\n\n",
        lensMm, scale, gray ? "gray" : "colour", scene.gain, scene.ambientDn, binarization.neighbourhood,
        binarization.maxErrorProbability, binarization.minAmplitudeSigmas, binarization.mixtureMargin);
    std::printf(
        "| delta | noise sigma DN | BER known bits | unknown bits | window mismatches / known, table | "
        "mismatches at 10 mm |\n| --- | --- | --- | --- | --- | --- |\n");
    for (int delta : {4, 6, 10, 16})
        for (double sigma : {0.0, 1.0, 2.0, 4.0}) {
            scene.delta = delta;
            scene.noiseSigmaDn = sigma;
            binarization.noiseSigmaDn = sigma;
            const Figures f = measure(scene, calibration, visible, binarization);
            std::printf("| %d | %.0f | %.1f %% | %.1f %% | %.1f / %.1f | %.1f |\n", delta, sigma,
                        100 * f.bitErrorRate, 100 * f.unknownRate, f.tableMismatches, f.tableKnown,
                        f.elevatedMismatches);
        }
    return 0;
}
