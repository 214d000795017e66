// The code segmentation on rendered frames: what the code alone cannot tell, colour does.
#include <string>

#include <gtest/gtest.h>

#include "core/code_image.h"
#include "core/geometry.h"
#include "core/hand_segmentation.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

struct DiskScore {
    int truth = 0, found = 0;  // hand pixels of the truth near touching pads, and how many the mask has
    double recall() const { return truth ? static_cast<double>(found) / truth : 0.0; }
};

// The hand's pixels within `radiusMm` of every touching pad, as the truth and the segmentation see them, over
// frames sampled across the scenario's cycle.
DiskScore scoreTouchingEnds(const std::string& scenario, const SegmentationOptions& options,
                            double radiusMm) {
    sim::SimParameters parameters;
    parameters.scenario = scenario;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    const Calibration& calibration = simulator.calibration();
    HandSegmenter segmenter(options);
    segmenter.setRig(calibration, simulator.pattern());
    const double radiusPx = radiusMm * segmenter.pixelsPerMm();

    DiskScore score;
    Frame older, newer;
    sim::FrameTruth truth, olderTruth;
    cv::Mat subtraction, texture, mask;
    const double cycle = simulator.scenario().cycleSeconds();
    constexpr int kSamples = 240;
    for (int i = 0; i < kSamples; ++i) {
        const auto index = static_cast<std::uint64_t>(cycle * i / kSamples * parameters.frameRate);
        simulator.render(index, older, olderTruth);
        simulator.render(index + 1, newer, truth);
        bool touching = false;
        for (const sim::FingertipTruth& finger : truth.fingertips)
            touching = touching || (finger.presented && finger.touching);
        if (!touching)
            continue;
        const bool olderPositive = older.polarity == Polarity::Positive;
        computeSubtractionAndTexture(FramePair{olderPositive ? older : newer, olderPositive ? newer : older},
                                     subtraction, texture);
        segmenter.segment(texture, subtraction, mask);
        for (const sim::FingertipTruth& finger : truth.fingertips) {
            if (!finger.presented || !finger.touching)
                continue;
            const Eigen::Vector2d pad =
                projectPoint(calibration.cameraMatrix, calibration.tableToCamera, finger.pad);
            const cv::Rect disk =
                cv::Rect(static_cast<int>(pad.x() - radiusPx), static_cast<int>(pad.y() - radiusPx),
                         static_cast<int>(2 * radiusPx + 2), static_cast<int>(2 * radiusPx + 2)) &
                cv::Rect(0, 0, mask.cols, mask.rows);
            for (int y = disk.y; y < disk.y + disk.height; ++y)
                for (int x = disk.x; x < disk.x + disk.width; ++x)
                    if ((Eigen::Vector2d(x, y) - pad).norm() <= radiusPx && truth.handMask.at<uchar>(y, x)) {
                        ++score.truth;
                        score.found += mask.at<uchar>(y, x) != 0;
                    }
        }
    }
    return score;
}

TEST(HandSegmentation, TouchingFingertipsKeepTheirEnds) {
    // The last millimetres of a touching finger show the table's code; their skin colour keeps them in the
    // hand, and with them the pad the touch is reported at.
    const DiskScore score = scoreTouchingEnds("grid35", SegmentationOptions{}, 6.0);
    ASSERT_GT(score.truth, 1000) << "the test needs touching fingers in view";
    // By the code alone 0.55 of them; 0.80 as measured with colour asked.
    EXPECT_GE(score.recall(), 0.75) << score.found << " of " << score.truth << " pixels";
}

TEST(HandSegmentation, AFingerSlidingFlatOnTheTableKeepsItsWidth) {
    // A sliding finger lies low along its whole last phalanx, whose blocks then show the table's code well
    // inside the finger, where the table beyond the reach lies up to a finger's width away: their colour
    // still keeps them.
    const DiskScore score = scoreTouchingEnds("drag", SegmentationOptions{}, 15.0);
    ASSERT_GT(score.truth, 10000) << "the test needs a sliding finger in view";
    // 0.84 when the table's colour was sampled only just beyond the reach (none found inside such a finger);
    // 0.91 as measured.
    EXPECT_GE(score.recall(), 0.88) << score.found << " of " << score.truth << " pixels";
}

}  // namespace
}  // namespace everytouch::core
