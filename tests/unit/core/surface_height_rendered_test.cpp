// The height of a fingertip's visible surface on rendered frame pairs: a finger that slides on the table.
#include <gtest/gtest.h>

#include <cmath>

#include "core/code_image.h"
#include "core/fingertips.h"
#include "core/geometry.h"
#include "core/hand_segmentation.h"
#include "core/surface_height.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

struct SlideScore {
    int frames = 0;  // pairs in which a touching fingertip moved and was found
    int read = 0;    // of them, those whose height came out within toleranceMm of the truth's
    double rate() const { return frames ? static_cast<double>(read) / frames : 0.0; }
};

const sim::FingertipTruth* presentedFinger(const sim::FrameTruth& truth) {
    for (const sim::FingertipTruth& finger : truth.fingertips)
        if (finger.presented)
            return &finger;
    return nullptr;
}

// Over pairs of the drag scenario in which the index finger slides on the table: how often its fingertip's
// height is read, and read right (the truth's height of what the camera sees at the region's centre).
SlideScore scoreSlidingFingertips(const HeightOptions& heightOptions, double toleranceMm) {
    sim::SimParameters parameters;
    parameters.scenario = "drag";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    const Calibration& calibration = simulator.calibration();
    HandSegmenter segmenter{SegmentationOptions{}};
    segmenter.setRig(calibration, simulator.pattern());
    SurfaceHeight height(heightOptions);
    height.setRig(calibration, simulator.pattern());
    const FingertipOptions fingertipOptions = rigFingertipOptions(calibration);
    FingertipScratch scratch;
    Fingertips fingertips;
    HeightEvidence evidence;

    SlideScore score;
    Frame older, newer;
    sim::FrameTruth olderTruth, truth;
    cv::Mat subtraction, texture, mask;
    const auto frames =
        static_cast<std::uint64_t>(simulator.scenario().cycleSeconds() * parameters.frameRate);
    constexpr std::uint64_t kEvery = 12;  // frames between samples: the slides' length over about 60 samples
    for (std::uint64_t index = 0; index + 1 < frames; index += kEvery) {
        simulator.render(index + 1, newer, truth);
        const sim::FingertipTruth* finger = presentedFinger(truth);
        if (!finger || !finger->touching)
            continue;  // the older frame is rendered only when it can matter: rendering is the test's cost
        simulator.render(index, older, olderTruth);
        const sim::FingertipTruth* olderFinger = presentedFinger(olderTruth);
        if (!olderFinger || !olderFinger->touching || (finger->pad - olderFinger->pad).norm() < 0.2)
            continue;
        const bool olderPositive = older.polarity == Polarity::Positive;
        const FramePair pair{olderPositive ? older : newer, olderPositive ? newer : older};
        computeSubtractionAndTexture(pair, subtraction, texture);
        segmenter.segment(texture, subtraction, mask);
        findFingertips(mask, fingertipOptions, scratch, fingertips, segmenter.judgedRegion());
        const Eigen::Vector2d truePad(finger->camera.x, finger->camera.y);
        const Fingertip* found = nullptr;
        for (const Fingertip& tip : fingertips)
            if ((tip.pad - truePad).norm() < 0.5 * fingertipOptions.fingerWidthPx)
                found = &tip;
        if (!found)
            continue;
        ++score.frames;
        height.measureFingertip(pair, mask, found->tip, found->direction, found->widthPx, evidence);
        const HeightEstimate estimate = height.estimate(evidence);
        const Eigen::Vector2d centre =
            found->tip - heightOptions.centreBehindWidths * found->widthPx * found->direction;
        const float trueHeight = truth.visibleHeightMm.at<float>(static_cast<int>(std::lround(centre.y())),
                                                                 static_cast<int>(std::lround(centre.x())));
        score.read += estimate.valid && std::abs(estimate.heightMm - trueHeight) <= toleranceMm;
    }
    return score;
}

TEST(SurfaceHeightRendered, ASlidingFingertipsHeightIsRead) {
    // A finger sliding at 60 mm/s moves half a millimetre between the two frames of a pair: its shading's
    // trace in the difference outweighs the faint code on skin unless the texture's gradient explains it.
    const SlideScore score = scoreSlidingFingertips(HeightOptions{}, 4.0);
    ASSERT_GE(score.frames, 30) << "the test needs sliding fingertips in view";
    // 0.53 of them read within 4 mm as measured; 0.15 with explainMotion off (the same test, that option
    // false).
    EXPECT_GE(score.rate(), 0.45) << score.read << " of " << score.frames << " frames";
}

}  // namespace
}  // namespace everytouch::core
