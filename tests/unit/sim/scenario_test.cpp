// Every scenario runs, and its ground truth is consistent with the rendered scene.
#include "sim/scenario.h"

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "sim/simulator.h"
#include "support/random_pattern.h"

namespace everytouch::sim {
namespace {

struct Tally {
    int touches = 0;             // presented fingertips touching, over all sampled frames
    int presented = 0;           // presented fingertips
    double lowestHoverMm = 1e9;  // lowest presented fingertip that does not touch
    int handFrames = 0;          // frames with hand pixels
};

Tally play(const std::string& name, std::uint64_t seed) {
    SimParameters p;
    p.scenario = name;
    p.seed = seed;
    Simulator simulator(p, test::randomPattern(p.projectorSize, static_cast<unsigned>(seed)));
    const double cycle = simulator.scenario().cycleSeconds();
    Tally tally;
    core::Frame frame;
    FrameTruth truth;
    constexpr int kSamples = 40;
    for (int i = 0; i < kSamples; ++i) {
        const auto index = static_cast<std::uint64_t>(cycle * (i + 0.5) / kSamples * p.frameRate);
        simulator.render(index, frame, truth);
        EXPECT_EQ(frame.image.size(), p.cameraSize);
        EXPECT_EQ(frame.polarity, index % 2 ? core::Polarity::Negative : core::Polarity::Positive);
        // No hand goes through the table.
        for (const HandPose& hand : simulator.scenario().at(simulator.frameSeconds(index)).hands)
            for (const HandCapsule& capsule : buildHand(hand).capsules)
                EXPECT_GT(capsule.shape.supportPoint(-Eigen::Vector3d::UnitZ()).z(), -kContactToleranceMm)
                    << name << " at " << simulator.frameSeconds(index) << " s";
        tally.handFrames += cv::countNonZero(truth.handMask) > 0;
        for (const FingertipTruth& tip : truth.fingertips) {
            EXPECT_GE(tip.heightMm, 0.0);
            EXPECT_EQ(tip.touching, tip.heightMm == 0.0);
            EXPECT_EQ(tip.touching, tip.pad.z() < kContactToleranceMm);
            if (!tip.presented)
                continue;
            ++tally.presented;
            tally.touches += tip.touching;
            if (!tip.touching)
                tally.lowestHoverMm = std::min(tally.lowestHoverMm, tip.heightMm);
            // A touching fingertip seen from above covers its own contact point.
            const cv::Rect image(0, 0, p.cameraSize.width, p.cameraSize.height);
            const cv::Point contact(static_cast<int>(tip.camera.x), static_cast<int>(tip.camera.y));
            if (tip.touching && image.contains(contact)) {
                const cv::Rect near = cv::Rect(contact - cv::Point(4, 4), cv::Size(9, 9)) & image;
                EXPECT_GT(cv::countNonZero(truth.handMask(near)), 0) << name << " finger " << tip.id;
            }
        }
    }
    return tally;
}

TEST(Scenario, UnknownNameListsTheKnownOnes) {
    SimParameters p;
    p.scenario = "juggle";
    try {
        Simulator simulator(p, test::randomPattern(p.projectorSize, 1));
        FAIL() << "no exception";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("grid35, drag, multitouch, hover, palm, idle, demo"),
                  std::string::npos);
    }
}

TEST(Scenario, Grid35TapsWithApproachesAndHovers) {
    const Tally tally = play("grid35", 3);
    EXPECT_GT(tally.touches, 0);
    EXPECT_GT(tally.presented, tally.touches);
}

TEST(Scenario, DragKeepsTheFingerDownAlongTheShapes) {
    const Tally tally = play("drag", 3);
    EXPECT_GT(tally.touches, tally.presented / 2);
}

TEST(Scenario, MultitouchPutsSeveralFingersDown) {
    const Tally tally = play("multitouch", 3);
    EXPECT_GT(tally.touches, 40);
}

TEST(Scenario, HoverNeverTouchesAndPassesLow) {
    const Tally tally = play("hover", 3);
    EXPECT_EQ(tally.touches, 0);
    EXPECT_GT(tally.presented, 0);
    EXPECT_GE(tally.lowestHoverMm, 2.0 - 1e-9);
    EXPECT_LT(tally.lowestHoverMm, 10.0);
}

TEST(Scenario, PalmRestsWhileAFingerTaps) {
    const Tally tally = play("palm", 3);
    EXPECT_GT(tally.touches, 0);
    EXPECT_GT(tally.presented, tally.touches);
}

TEST(Scenario, IdleHasNoHand) {
    const Tally tally = play("idle", 3);
    EXPECT_EQ(tally.presented, 0);
    EXPECT_EQ(tally.handFrames, 0);
}

TEST(Scenario, DemoMixesTheOthers) {
    const Tally tally = play("demo", 3);
    EXPECT_GT(tally.touches, 0);
    EXPECT_GT(tally.handFrames, 0);
    EXPECT_LT(tally.handFrames, 40);
}

TEST(Simulator, FramesAreAPureFunctionOfParametersSeedAndTime) {
    SimParameters p;
    p.scenario = "grid35";
    p.seed = 9;
    const cv::Mat pattern = test::randomPattern(p.projectorSize, 9);
    Simulator first(p, pattern), second(p, pattern);
    core::Frame a, b;
    FrameTruth truthA, truthB;
    second.render(700, b, truthB);  // a different history before the same frame
    first.render(301, a, truthA);
    second.render(301, b, truthB);
    EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(truthA.handMask, truthB.handMask, cv::NORM_INF), 0.0);
    ASSERT_EQ(truthA.fingertips.size(), truthB.fingertips.size());
    for (size_t i = 0; i < truthA.fingertips.size(); ++i)
        EXPECT_EQ(truthA.fingertips[i].pad, truthB.fingertips[i].pad);
    EXPECT_EQ(a.timestampUs, 2508333);  // 301 / 120 s, rounded to the microsecond

    p.seed = 10;
    Simulator other(p, pattern);
    core::Frame c;
    FrameTruth truthC;
    other.render(301, c, truthC);
    EXPECT_GT(cv::norm(a.image, c.image, cv::NORM_L1) / a.image.total(), 1.0);
}

TEST(Simulator, MovingHandsAreBlurredOverTheExposureStillOnesAreNot) {
    SimParameters p;
    p.scenario = "grid35";
    p.seed = 6;
    const cv::Mat pattern = test::randomPattern(p.projectorSize, 6);
    Simulator blurred(p, pattern);
    p.motionSamples = 1;
    Simulator sharp(p, pattern);
    int moving = 0, still = 0;
    core::Frame a, b;
    FrameTruth truthA, truthB;
    // The first taps: the hand comes in, travels between circles, and rests on them. Noise depends only on
    // the seed and the frame, so any difference is motion blur.
    for (std::uint64_t index = 120; index < 600; index += 7) {
        blurred.render(index, a, truthA);
        sharp.render(index, b, truthB);
        EXPECT_EQ(cv::norm(truthA.handMask, truthB.handMask, cv::NORM_INF), 0.0);
        ASSERT_EQ(truthA.fingertips.size(), truthB.fingertips.size());
        EXPECT_EQ(truthA.fingertips[1].pad, truthB.fingertips[1].pad);
        const double difference = cv::norm(a.image, b.image, cv::NORM_L1);
        if (difference == 0.0) {
            ++still;
        } else {
            ++moving;
            EXPECT_FALSE(truthA.fingertips[1].touching) << "a touching finger rests during the exposure";
        }
    }
    // Only the fastest moves between circles travel more than a pixel in one exposure.
    EXPECT_GT(moving, 0);
    EXPECT_GT(still, 10 * moving);
}

// The exposure is metered as each sensor records: a monochrome pixel takes the light of all three colours, so
// metering its brightest colour alone clipped the whole white display at 255, where no code survives.
TEST(Simulator, EverySensorIsExposedSoThatTheWhiteTableDoesNotClip) {
    for (const CameraColour colour : {CameraColour::Bayer, CameraColour::Rgb, CameraColour::Mono}) {
        SimParameters p;
        p.scenario = "grid35";
        p.cameraColour = colour;
        Simulator simulator(p, test::randomPattern(p.projectorSize, 1));
        core::Frame frame;
        FrameTruth truth;
        simulator.render(0, frame, truth);
        double brightest = 0.0;
        cv::minMaxLoc(frame.image.reshape(1), nullptr, &brightest);
        const double clipped = cv::countNonZero(frame.image.reshape(1) >= 255) /
                               static_cast<double>(frame.image.total() * frame.image.channels());
        EXPECT_LT(clipped, 0.001) << "sensor " << static_cast<int>(colour);
        EXPECT_GT(brightest, 0.6 * 255) << "sensor " << static_cast<int>(colour);
    }
}

TEST(Simulator, AmbientLightChangesMidSession) {
    SimParameters p;
    p.scenario = "idle";
    p.ambientLux = 150.0;
    p.ambientChangeLux = 3.0;
    p.ambientChangeAtS = 1.0;
    Simulator simulator(p, test::randomPattern(p.projectorSize, 1));
    core::Frame before, after;
    FrameTruth truth;
    simulator.render(100, before, truth);
    EXPECT_EQ(truth.ambientLux, 150.0);
    simulator.render(140, after, truth);
    EXPECT_EQ(truth.ambientLux, 3.0);
    // Same exposure, less light: the table outside the projection gets much darker.
    const cv::Rect corner(0, 0, 40, 40);
    EXPECT_LT(cv::mean(after.image(corner))[1], 0.2 * cv::mean(before.image(corner))[1]);
}

TEST(Simulator, MeteringPutsWhiteContentAtTheTargetLevel) {
    SimParameters p;
    p.scenario = "idle";
    p.content = "white";
    p.vignettingPower = 0.0;
    Simulator simulator(p, test::randomPattern(p.projectorSize, 1));
    core::Frame frame;
    FrameTruth truth;
    simulator.render(0, frame, truth);
    const cv::Rect centre(p.cameraSize.width / 2 - 20, p.cameraSize.height / 2 - 20, 40, 40);
    cv::Scalar mean = cv::mean(frame.image(centre));
    const double target = p.autoExposureLevel * 255.0;
    // White content is compressed to 255 - delta and the code adds +-delta: on average the level is 245.
    EXPECT_NEAR(std::max({mean[0], mean[1], mean[2]}), target, 0.1 * target);
}

}  // namespace
}  // namespace everytouch::sim
