// everytouch-ber: bit-error rate of the code binarisation on synthetic captures, against the code amplitude
// delta and the camera noise, as a Markdown table (docs/structured-light.md).
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "core/code_image.h"
#include "core/geometry.h"
#include "support/bit_error_rate.h"
#include "support/synthetic_capture.h"

using namespace everytouch;

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
    scene.pattern = test::defaultPattern();
    scene.content = test::testContent(calibration.projectorSize);
    scene.projectorToCamera = calibration.projectorToCameraHomography(0.0);
    scene.cameraSize = calibration.cameraSize;
    scene.albedo = test::testAlbedo(calibration.cameraSize);
    scene.grayCamera = gray;
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
            const test::BitErrorFigures f = test::measureBitErrors(scene, calibration, binarization);
            const std::string errorRate =
                f.unknownRate < 1.0 ? cv::format("%.1f %%", 100 * f.bitErrorRate) : std::string("none known");
            std::printf("| %d | %.0f | %s | %.1f %% | %.1f / %.1f | %.1f |\n", delta, sigma,
                        errorRate.c_str(), 100 * f.unknownRate, f.tableMismatches, f.tableKnown,
                        f.elevatedMismatches);
        }
    return 0;
}
