#include "core/code_sampling.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/code_image.h"
#include "core/code_index.h"
#include "core/geometry.h"
#include "core/pattern.h"
#include "support/bit_error_rate.h"
#include "support/synthetic_capture.h"

namespace everytouch::core {
namespace {

cv::Matx33d toMatx(const Eigen::Matrix3d& m) {
    cv::Matx33d result;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            result(r, c) = m(r, c);
    return result;
}

// A random panel-sized pattern, for tests whose subject is not the pattern.
const cv::Mat& randomPattern() {
    static const cv::Mat pattern = [] {
        cv::Mat bits(480, 640, CV_8UC1);
        cv::RNG(9).fill(bits, cv::RNG::UNIFORM, 0, 2);
        return bits;
    }();
    return pattern;
}

// A camera that sees every projector pixel as 2x2 camera pixels and reads every bit perfectly. The offset
// keeps pixel centres away from rounding ties in both directions.
struct PerfectView {
    Eigen::Matrix3d projectorToCamera;
    cv::Mat codeImage;

    PerfectView() {
        projectorToCamera << 2, 0, -100.4, 0, 2, -80.4, 0, 0, 1;
        cv::warpPerspective(randomPattern(), codeImage, toMatx(projectorToCamera), {648, 488},
                            cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(kUnknownBit));
    }
};

TEST(CodeSampling, ReadsTheExactCodewordFromAPerfectView) {
    const PerfectView view;
    const std::uint64_t all = (std::uint64_t{1} << 36) - 1;
    for (const cv::Point anchor : {cv::Point(60, 50), cv::Point(200, 150), cv::Point(370, 280)}) {
        const ObservedCode observed = sampleCode(view.codeImage, view.projectorToCamera, anchor, 6);
        EXPECT_EQ(observed.known, all);
        EXPECT_EQ(observed.bits, codeAt(randomPattern(), anchor, 6));
        EXPECT_EQ(hammingDistance(codeAt(randomPattern(), anchor, 6), observed), 0);
    }
}

TEST(CodeSampling, BitsOutsideTheCameraImageAreUnknownNotZero) {
    const PerfectView view;
    // Columns 47..49 of the window land left of the image (camera x = 2 * 47 - 100.4 < -0.5).
    const ObservedCode observed = sampleCode(view.codeImage, view.projectorToCamera, {52, 150}, 6);
    std::uint64_t expectedKnown = 0;
    for (int row = 0; row < 6; ++row)
        expectedKnown |= std::uint64_t{0b111000} << (6 * row);
    EXPECT_EQ(observed.known, expectedKnown);
    EXPECT_EQ(observed.knownCount(), 18);
    EXPECT_EQ(observed.bits & ~observed.known, 0u);
    EXPECT_EQ(observed.bits, codeAt(randomPattern(), {52, 150}, 6) & expectedKnown);
}

TEST(CodeSampling, AtACameraPointReadsTheWindowThatEndsThere) {
    const PerfectView view;
    const CodeSample sample =
        sampleCodeAtCamera(view.codeImage, view.projectorToCamera.inverse(), Eigen::Vector2d(300, 200), 6);
    EXPECT_EQ(sample.anchor, cv::Point(200, 140));  // (300 + 100.4) / 2, (200 + 80.4) / 2, nearest
    EXPECT_EQ(sample.observed.bits, codeAt(randomPattern(), sample.anchor, 6));
}

// A capture of the code on the table by a rig like the paper's, with a camera lens of the given focal length.
struct Capture {
    Calibration calibration;
    test::SyntheticScene scene;
    cv::Mat codeImage;

    Capture(const cv::Mat& pattern, double lensMm, int delta, double noiseSigmaDn,
            double surfaceHeightMm = 0.0)
        : calibration(test::paperLikeCalibrationWithLens(lensMm)) {
        scene.pattern = pattern;
        scene.content = test::testContent(calibration.projectorSize);
        scene.delta = delta;
        scene.noiseSigmaDn = noiseSigmaDn;
        scene.projectorToCamera = calibration.projectorToCameraHomography(surfaceHeightMm);
        scene.cameraSize = calibration.cameraSize;
        scene.albedo = test::testAlbedo(calibration.cameraSize);
        cv::Mat subtraction, texture, localMean;
        computeSubtractionAndTexture(test::renderCapture(scene), subtraction, texture);
        BinarizationOptions options;
        options.noiseSigmaDn = noiseSigmaDn;
        binarizeSubtraction(subtraction, 3, options, localMean, codeImage);
    }

    // Camera points (fingertip candidates) whose projector window lies on the panel and in view.
    std::vector<Eigen::Vector2d> cameraPoints(int count) const {
        std::mt19937_64 random(11);
        const Eigen::Matrix3d toProjector = calibration.cameraToProjectorHomography(0.0);
        const cv::Rect anchors = codedRegion(scene.pattern.size(), 6);
        const cv::Rect inside(20, 20, calibration.cameraSize.width - 40, calibration.cameraSize.height - 40);
        std::vector<Eigen::Vector2d> points;
        while (static_cast<int>(points.size()) < count) {
            // One draw a statement: the order of a call's arguments is the compiler's.
            const double x = static_cast<double>(inside.x + random() % inside.width);
            const double y = static_cast<double>(inside.y + random() % inside.height);
            const Eigen::Vector2d camera(x, y);
            const Eigen::Vector2d projector = applyHomography(toProjector, camera);
            if (anchors.contains(cv::Point(cvRound(projector.x()), cvRound(projector.y()))))
                points.push_back(camera);
        }
        return points;
    }
};

TEST(CodeSampling, AllWindowsAtOnceAgreeWithSamplingEachWindow) {
    const Capture capture(randomPattern(), 10.0, 10, 2.0);
    const Eigen::Matrix3d h = capture.calibration.projectorToCameraHomography(0.0);
    WindowAgreement agreement;
    matchAllWindows(capture.codeImage, h, capture.scene.pattern, 6, agreement);
    ASSERT_EQ(agreement.mismatches.size(), capture.scene.pattern.size());
    const uchar* buffer = agreement.mismatches.data;
    const cv::Rect anchors = codedRegion(capture.scene.pattern.size(), 6);
    int compared = 0;
    for (int y = anchors.y; y < anchors.br().y; y += 7)
        for (int x = anchors.x; x < anchors.br().x; x += 5) {
            const ObservedCode observed = sampleCode(capture.codeImage, h, {x, y}, 6);
            ASSERT_EQ(agreement.known.at<uchar>(y, x), observed.knownCount()) << x << "," << y;
            ASSERT_EQ(agreement.mismatches.at<uchar>(y, x),
                      hammingDistance(codeAt(capture.scene.pattern, {x, y}, 6), observed))
                << x << "," << y;
            compared += observed.knownCount() > 0;
        }
    EXPECT_GT(compared, 1000);
    matchAllWindows(capture.codeImage, h, capture.scene.pattern, 6, agreement);
    EXPECT_EQ(agreement.mismatches.data, buffer);
}

// Where a camera pixel sees a single projector pixel, S is 2 delta gain albedo on a 1-bit and 0 on a 0-bit,
// and T is what the surface reflects of the compressed content plus ambient light.
TEST(CodeSampling, SyntheticCaptureGivesTheSubtractionAndTextureThePhysicsPredicts) {
    const Calibration calibration =
        test::paperLikeCalibrationWithLens(15.0);  // 1.5 camera px per projector px
    test::SyntheticScene scene;
    scene.pattern = randomPattern();
    scene.content = test::testContent(calibration.projectorSize);
    scene.delta = 10;
    scene.noiseSigmaDn = 0;
    scene.projectorToCamera = calibration.projectorToCameraHomography(0.0);
    scene.cameraSize = calibration.cameraSize;
    scene.albedo = test::testAlbedo(calibration.cameraSize);
    cv::Mat subtraction, texture;
    computeSubtractionAndTexture(test::renderCapture(scene), subtraction, texture);

    const Eigen::Matrix3d toProjector = calibration.cameraToProjectorHomography(0.0);
    auto projectorPixel = [&](double x, double y) {
        const Eigen::Vector2d p = applyHomography(toProjector, Eigen::Vector2d(x, y));
        return cv::Point(cvRound(p.x()), cvRound(p.y()));
    };
    const cv::Rect panel(0, 0, scene.pattern.cols, scene.pattern.rows);
    int checked = 0;
    for (int y = 0; y < subtraction.rows; ++y)
        for (int x = 0; x < subtraction.cols; ++x) {
            const cv::Point p = projectorPixel(x, y);
            if (!panel.contains(p) || projectorPixel(x - 0.5, y - 0.5) != p ||
                projectorPixel(x + 0.5, y - 0.5) != p || projectorPixel(x - 0.5, y + 0.5) != p ||
                projectorPixel(x + 0.5, y + 0.5) != p)
                continue;  // the camera pixel sees more than one projector pixel
            const cv::Vec3f albedo = scene.albedo.at<cv::Vec3f>(y, x);
            const int bit = scene.pattern.at<uchar>(p);
            const float strongest = std::max({albedo[0], albedo[1], albedo[2]});
            ASSERT_NEAR(subtraction.at<short>(y, x), bit * 2 * scene.delta * scene.gain * strongest, 1.01)
                << x << "," << y;
            for (int c = 0; c < 3; ++c) {
                const double compressed =
                    scene.delta + scene.content.at<cv::Vec3b>(p)[c] * (255.0 - 2 * scene.delta) / 255.0;
                ASSERT_NEAR(texture.at<cv::Vec3b>(y, x)[c],
                            albedo[c] * (scene.gain * std::round(compressed) + scene.ambientDn), 1.01)
                    << x << "," << y << " channel " << c;
            }
            ++checked;
        }
    EXPECT_GT(checked, 5000);
}

struct Separation {
    double tableRatio;     // median mismatches / known bits through the table's homography
    double elevatedRatio;  // the same through the homography of a plane 10 mm higher
    double separated;      // fraction of points whose table ratio is below their elevated ratio
};

Separation separation(const Capture& capture, int points) {
    const Eigen::Matrix3d onTable = capture.calibration.cameraToProjectorHomography(0.0);
    const Eigen::Matrix3d elevated = capture.calibration.cameraToProjectorHomography(10.0);
    const cv::Rect anchors = codedRegion(capture.scene.pattern.size(), 6);
    std::vector<double> tableRatios, elevatedRatios;
    int separated = 0;
    for (const Eigen::Vector2d& point : capture.cameraPoints(points)) {
        double ratio[2];
        int i = 0;
        for (const Eigen::Matrix3d* h : {&onTable, &elevated}) {
            const CodeSample sample = sampleCodeAtCamera(capture.codeImage, *h, point, 6);
            const bool onPanel = anchors.contains(sample.anchor);
            const std::uint64_t expected = onPanel ? codeAt(capture.scene.pattern, sample.anchor, 6) : 0;
            const int known = sample.observed.knownCount();
            ratio[i++] =
                onPanel && known > 0 ? double(hammingDistance(expected, sample.observed)) / known : 0.5;
        }
        tableRatios.push_back(ratio[0]);
        elevatedRatios.push_back(ratio[1]);
        separated += ratio[0] < ratio[1];
    }
    auto median = [](std::vector<double> values) {
        std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
        return values[values.size() / 2];
    };
    return {median(tableRatios), median(elevatedRatios), double(separated) / points};
}

// Paper eq. 16-18: through the right homography the observed code is the expected one up to bit errors;
// through the homography of a plane 10 mm higher it is another window's, about half the bits off.
// 4000 points, so that the fractions separated have a sampling error of 0.003-0.005: over 400 they were
// 0.983 or 0.968 depending on the order in which the points' coordinates were drawn.
TEST(Decoding, TheTableHomographyExplainsTheCodeAndAPlaneTenMillimetresHigherDoesNot) {
    const Separation resolving = separation(Capture(test::defaultPattern(), 10.0, 10, 2.0), 4000);
    std::printf("10 mm lens: median ratio table %.3f, 10 mm higher %.3f, separated %.3f\n",
                resolving.tableRatio, resolving.elevatedRatio, resolving.separated);
    EXPECT_LT(resolving.tableRatio, 0.12);
    EXPECT_GT(resolving.elevatedRatio, 0.4);
    EXPECT_GT(resolving.separated, 0.97);

    // The paper-like 6 mm lens sees a projector pixel as 0.6 camera pixels: most camera pixels mix several
    // bits, a quarter of the bits read are wrong, and the two hypotheses separate less clearly.
    const Separation paperLike = separation(Capture(test::defaultPattern(), 6.0, 10, 2.0), 4000);
    std::printf("6 mm lens: median ratio table %.3f, 10 mm higher %.3f, separated %.3f\n",
                paperLike.tableRatio, paperLike.elevatedRatio, paperLike.separated);
    EXPECT_LT(paperLike.tableRatio, 0.35);
    EXPECT_GT(paperLike.elevatedRatio, 0.4);
    EXPECT_GT(paperLike.separated, 0.8);
}

// A hand or a book 10 mm above the table: the code seen at a camera point is found on the panel through the
// code index alone, sampling the camera image with the table's local shape; it lies where the elevated
// plane's homography says, about 2 projector pixels from where the table's does. Noise 1 DN, delta 10.
TEST(Decoding, LocatesTheCodeOnAnElevatedPlaneWithoutItsHomography) {
    const double height = 10.0;
    const Capture capture(test::defaultPattern(), 10.0, 10, 1.0, height);
    const CodeIndex index(capture.scene.pattern, 6);
    const Eigen::Matrix3d onTable = capture.calibration.cameraToProjectorHomography(0.0);
    const Eigen::Matrix3d elevated = capture.calibration.cameraToProjectorHomography(height);
    int found = 0, right = 0;
    double shift = 0, error = 0;
    const int points = 300;
    for (const Eigen::Vector2d& point : capture.cameraPoints(points)) {
        const std::optional<CodeLocation> location = locateCode(capture.codeImage, index, onTable, point);
        if (!location)
            continue;
        ++found;
        const Eigen::Vector2d truth = applyHomography(elevated, point);
        const double miss = (location->projectorPoint - truth).norm();
        if (miss < 1.0) {
            ++right;
            error += miss;
            shift += (truth - applyHomography(onTable, point)).norm();
        }
    }
    std::printf(
        "elevated plane: located %d of %d, %d within 1 px of the truth (mean error %.2f px, shift from "
        "the table's position %.2f px)\n",
        found, points, right, error / right, shift / right);
    // Only reads with at most about one wrong bit are significant (the rest could be chance matches): a third
    // of the points at this noise, and those are right.
    EXPECT_GT(found, 0.3 * points);
    EXPECT_GE(right, 0.98 * found);
    EXPECT_LT(error / right, 0.5);
    EXPECT_GT(shift / right, 1.5);
}

TEST(Decoding, BitErrorRateFallsWithDeltaAndRisesWithNoise) {
    const Calibration calibration = test::paperLikeCalibrationWithLens(10.0);
    test::SyntheticScene scene;
    scene.pattern = test::defaultPattern();
    scene.content = test::testContent(calibration.projectorSize);
    scene.projectorToCamera = calibration.projectorToCameraHomography(0.0);
    scene.cameraSize = calibration.cameraSize;
    scene.albedo = test::testAlbedo(calibration.cameraSize);
    auto figures = [&](int delta, double noise) {
        scene.delta = delta;
        scene.noiseSigmaDn = noise;
        BinarizationOptions options;
        options.noiseSigmaDn = noise;
        return test::measureBitErrors(scene, calibration, options);
    };
    const test::BitErrorFigures weak = figures(6, 1.0);
    const test::BitErrorFigures strong = figures(16, 1.0);
    const test::BitErrorFigures quiet = figures(10, 0.0);
    const test::BitErrorFigures noisy = figures(10, 2.0);
    EXPECT_LT(strong.bitErrorRate, weak.bitErrorRate);
    EXPECT_LT(strong.unknownRate, weak.unknownRate);
    EXPECT_LT(quiet.bitErrorRate, noisy.bitErrorRate);
    EXPECT_LT(quiet.unknownRate, noisy.unknownRate);
    EXPECT_LT(quiet.bitErrorRate, 0.03);
    // Through the wrong plane, about half the known bits disagree.
    EXPECT_NEAR(quiet.elevatedMismatches / quiet.tableKnown, 0.5, 0.05);
}

}  // namespace
}  // namespace everytouch::core
