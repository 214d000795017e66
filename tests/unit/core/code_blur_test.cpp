// The code's blur read from rendered pairs of the simulated rig, whose camera is focused more or less well.
#include <cmath>
#include <optional>

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "core/code_blur.h"
#include "core/code_image.h"
#include "core/hand_segmentation.h"
#include "sim/simulator.h"

namespace everytouch::core {
namespace {

struct Measured {
    std::optional<double> blur;          // from a pair of the two polarities
    std::optional<double> swappedBlur;   // from the same pair taken the other way round
    std::optional<double> samePolarity;  // from two frames of the same polarity: no code
};

// grid35 at frame 60: the hand is in view, over part of the table.
Measured measure(double cameraDefocusPx, double projectorDefocusPx = 0.5) {
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.cameraDefocusPx = cameraDefocusPx;
    parameters.projectorDefocusPx = projectorDefocusPx;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    Frame frames[3];
    sim::FrameTruth truth;
    for (int i = 0; i < 3; ++i)
        simulator.render(60 + i, frames[i], truth);

    HandSegmenter segmenter{SegmentationOptions{}};
    segmenter.setRig(simulator.calibration(), simulator.pattern());
    CodeBlurMeter meter;
    meter.setRig(simulator.calibration(), simulator.pattern(), segmenter.judgedRegion());
    EXPECT_TRUE(meter.hasRig());
    cv::Mat subtraction, texture;
    const auto blurOf = [&](const Frame& positive, const Frame& negative) {
        computeSubtractionAndTexture(FramePair{positive, negative}, subtraction, texture);
        return meter.measure(subtraction);
    };
    const bool firstPositive = frames[0].polarity == Polarity::Positive;
    const Frame& positive = firstPositive ? frames[0] : frames[1];
    const Frame& negative = firstPositive ? frames[1] : frames[0];
    return {blurOf(positive, negative), blurOf(negative, positive), blurOf(frames[0], frames[2])};
}

// The default rig's camera, measured once for the tests that use it.
const Measured& defaultRig() {
    static const Measured measured = measure(0.5);
    return measured;
}

TEST(CodeBlur, FollowsTheCamerasFocusInQuadrature) {
    const Measured sharp = measure(0.0), soft = measure(1.2), softer = measure(2.0);
    ASSERT_TRUE(sharp.blur && soft.blur && softer.blur);
    // Gaussian blurs add in quadrature: what the lens adds is what the measurement grows by.
    EXPECT_NEAR(std::sqrt(*soft.blur * *soft.blur - *sharp.blur * *sharp.blur), 1.2, 0.15);
    EXPECT_NEAR(std::sqrt(*softer.blur * *softer.blur - *sharp.blur * *sharp.blur), 2.0, 0.15);
    // A sharp lens still shows the projector's blur and the demosaicing's: not zero, under one pixel.
    EXPECT_GT(*sharp.blur, 0.3);
    EXPECT_LT(*sharp.blur, 1.0);
}

TEST(CodeBlur, SeesAProjectorOutOfFocus) {
    const Measured &focused = defaultRig(), defocused = measure(0.5, 1.5);
    ASSERT_TRUE(focused.blur && defocused.blur);
    EXPECT_GT(*defocused.blur, *focused.blur + 0.4);
}

TEST(CodeBlur, IsTheSameForAPairTakenTheWrongWayRound) {
    const Measured& measured = defaultRig();
    ASSERT_TRUE(measured.blur && measured.swappedBlur);
    // S is the largest of the channels' differences, so the negated code is not quite S negated.
    EXPECT_NEAR(*measured.blur, *measured.swappedBlur, 0.02);
}

TEST(CodeBlur, GivesNothingWithoutCode) {
    EXPECT_FALSE(defaultRig().samePolarity);
    CodeBlurMeter meter;
    EXPECT_FALSE(meter.hasRig());
}

}  // namespace
}  // namespace everytouch::core
