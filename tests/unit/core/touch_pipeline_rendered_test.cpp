// The whole pipeline on rendered frames: what a user feels of a drag.
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <vector>

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "core/touch_pipeline.h"
#include "sim/simulator.h"
#include "support/simulated_rig_settings.h"

namespace everytouch::core {
namespace {

struct DragScore {
    int drags = 0;           // runs of frames in which a finger lies on the table
    int slideFrames = 0;     // frames in which a finger lies on the table
    int touchingFrames = 0;  // of those, frames with a touching contact
    int touchDowns = 0;      // contacts that went down while a finger lay on the table
};

// The pipeline on two consecutive frames, whichever of them shows O + P.
const PipelineResult& processInOrder(TouchPipeline& pipeline, const Frame& older, const Frame& newer,
                                     const PipelineSettings& settings) {
    const bool olderPositive = older.polarity == Polarity::Positive;
    return pipeline.process(FramePair{olderPositive ? older : newer, olderPositive ? newer : older},
                            settings);
}

DragScore scoreDrags(const std::string& scenario) {
    sim::SimParameters parameters;
    parameters.scenario = scenario;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    TouchPipeline pipeline;
    const PipelineSettings settings = test::simulatedRigSettings(simulator);

    DragScore score;
    Frame older, newer;
    sim::FrameTruth olderTruth, truth;
    std::set<std::uint32_t> down;
    bool wasOnTable = false;
    const auto frames =
        static_cast<std::uint64_t>(simulator.scenario().cycleSeconds() * parameters.frameRate);
    simulator.render(0, older, olderTruth);
    for (std::uint64_t index = 1; index < frames; ++index) {
        simulator.render(index, newer, truth);
        const PipelineResult& result = processInOrder(pipeline, older, newer, settings);
        std::swap(older, newer);

        bool onTable = false;
        for (const sim::FingertipTruth& finger : truth.fingertips)
            onTable = onTable || (finger.presented && finger.touching);
        std::set<std::uint32_t> nowDown;
        for (const Contact& contact : result.contacts)
            if (contact.touching)
                nowDown.insert(contact.id);
        if (onTable) {
            score.drags += wasOnTable ? 0 : 1;
            ++score.slideFrames;
            score.touchingFrames += nowDown.empty() ? 0 : 1;
            for (std::uint32_t id : nowDown)
                score.touchDowns += down.count(id) ? 0 : 1;
        }
        down = nowDown;
        wasOnTable = onTable;
    }
    return score;
}

TEST(TouchPipelineRendered, ADragStaysOneTouch) {
    // The drag scenario's finger slides along a square, a triangle and a circle: each drag should be one
    // touch from its touch-down to its lift, whatever the code on the sliding skin lets the height read.
    const DragScore score = scoreDrags("drag");
    ASSERT_GT(score.slideFrames, 300) << "the test needs a finger sliding on the table";
    EXPECT_GE(static_cast<double>(score.touchingFrames) / score.slideFrames, 0.8)
        << score.touchingFrames << " of " << score.slideFrames << " frames";
    // One touch-down a drag is the goal. 10 in the 3 drags as measured, 17 when a frame without a height
    // leant to the table on its own evidence only: a slide's breaks are runs of frames whose code is too
    // faint on the moving skin (docs/detection.md).
    EXPECT_LE(score.touchDowns, 13) << "touch-downs in " << score.drags << " drags";
}

TEST(TouchPipelineRendered, OnlyAStillSceneKeepsItsMask) {
    // grid35 shows the empty table for about half a second, then a hand comes in and moves on.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    TouchPipeline pipeline;
    const PipelineSettings settings = test::simulatedRigSettings(simulator);
    HandSegmenter segmenter(SegmentationOptions{});
    segmenter.setRig(*settings.calibration, settings.pattern);

    Frame older, newer;
    sim::FrameTruth truth;
    int emptyPairs = 0, stillEmptyPairs = 0, handPairs = 0, stillHandPairs = 0;
    int stillRun = 0, longestStillRun = 0;
    int segmentedHandPixels = -1;  // what the truth showed of the hand at the last pair segmented
    simulator.render(0, older, truth);
    for (std::uint64_t index = 1; index < 160; ++index) {
        simulator.render(index, newer, truth);
        const PipelineResult& result = processInOrder(pipeline, older, newer, settings);
        std::swap(older, newer);
        const int handPixels = cv::countNonZero(truth.handMask & segmenter.judgedRegion());
        if (handPixels == 0) {
            ++emptyPairs;
            stillEmptyPairs += result.sceneStill ? 1 : 0;
        } else {
            ++handPairs;
            stillHandPairs += result.sceneStill ? 1 : 0;
        }
        stillRun = result.sceneStill ? stillRun + 1 : 0;
        longestStillRun = std::max(longestStillRun, stillRun);
        if (!result.sceneStill)
            segmentedHandPixels = handPixels;
        else
            EXPECT_LE(std::abs(handPixels - segmentedHandPixels), 10 + handPixels / 100)
                << "pair " << index << " kept the mask of a hand that moved";
    }
    ASSERT_GT(emptyPairs, 50);
    ASSERT_GT(handPairs, 50);
    // Noise alone makes a pair differ from the reference now and then (as measured, 55 of 76 empty pairs
    // were still); a hand that moves in keeps every pair changed but for its pauses (2 of 83).
    EXPECT_GE(stillEmptyPairs, emptyPairs / 2);
    EXPECT_LE(stillHandPairs, handPairs / 10);
    // A mask is kept for at most 0.1 s, 12 pairs at 120 Hz: a segmentation that lost a hand holding still
    // is taken again by then.
    EXPECT_GT(longestStillRun, 6);
    EXPECT_LE(longestStillRun, 12);
}

TEST(TouchPipelineRendered, AFingerRestingOnTheTableIsNotLostToOnePairsSegmentation) {
    // grid35, seed 21: in pair 10153 the segmentation drops the hand (the code of the region it sees then
    // reads within 4 mm of the table) as the finger comes to rest on its circle for 27 frames. Kept as a
    // still scene's mask, that empty mask had hidden the resting finger, and the tap, to the end.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.seed = 21;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    TouchPipeline pipeline;
    const PipelineSettings settings = test::simulatedRigSettings(simulator);
    Frame older, newer;
    sim::FrameTruth truth;
    simulator.render(10104, older, truth);
    int pairsWithoutFingertipWhileTouching = 0, touchingPairs = 0;
    bool touched = false;
    for (std::uint64_t index = 10105; index <= 10179; ++index) {
        simulator.render(index, newer, truth);
        const PipelineResult& result = processInOrder(pipeline, older, newer, settings);
        std::swap(older, newer);
        const bool touching = std::any_of(truth.fingertips.begin(), truth.fingertips.end(),
                                          [](const sim::FingertipTruth& f) { return f.touching; });
        if (!touching)
            continue;
        ++touchingPairs;
        pairsWithoutFingertipWhileTouching += result.fingertips.empty() ? 1 : 0;
        touched = touched || std::any_of(result.contacts.begin(), result.contacts.end(),
                                         [](const Contact& c) { return c.touching; });
    }
    ASSERT_GT(touchingPairs, 20);
    EXPECT_LE(pairsWithoutFingertipWhileTouching, 1);
    EXPECT_TRUE(touched);
}

struct KnockOutcome {
    std::optional<double> mostBeforePx;
    std::optional<double> seenAfterS;
    std::optional<double> correctedAfterS;
    std::optional<CalibrationCorrection> correction;
    std::optional<double> lastPx;  // the check's reading at the end
    // Contacts that began touching after the knock, before the first pair whose touches were held back and
    // from then on.
    int touchDownsBeforeHold = 0;
    int touchDownsOnceHeld = 0;
    int pairsHeldBack = 0;
};

// By default grid35 from 1.75 s on, a hand over the table, the camera knocked (0.5 degrees, 2 mm) at 2 s: the
// pipeline's check of the calibration reads a fraction of a pixel before and the knock's misregistration
// within half a second after it. With the correction, the pipeline then works with the camera's new pose and
// the check reads a fraction of a pixel again; without it, the misregistration stays.
struct Knock {
    double atS = 2.0;
    double degrees = 0.5;
    double mm = 2.0;
    double fromS = 1.75;  // the pairs processed, session time
    double untilS = 2.6;
    std::uint64_t seed = 1;  // the knock's axis and direction, with everything else the simulator draws
};

KnockOutcome knocked(const Knock& knock, bool correct) {
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.knockS = knock.atS;
    parameters.knockDeg = knock.degrees;
    parameters.knockMm = knock.mm;
    parameters.seed = knock.seed;
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    DetectionOptions options;
    options.correctCalibration = correct;
    TouchPipeline pipeline(options);
    const PipelineSettings settings = test::simulatedRigSettings(simulator);
    Frame older, newer;
    sim::FrameTruth truth;
    const auto frameAt = [&](double seconds) {
        return static_cast<std::uint64_t>(std::llround(seconds * parameters.frameRate));
    };
    simulator.render(frameAt(knock.fromS), older, truth);
    KnockOutcome outcome;
    std::vector<std::uint32_t> touchingIds;
    for (std::uint64_t index = frameAt(knock.fromS) + 1; index < frameAt(knock.untilS); ++index) {
        simulator.render(index, newer, truth);
        const PipelineResult& result = processInOrder(pipeline, older, newer, settings);
        std::swap(older, newer);
        const double seconds = simulator.frameSeconds(index);
        std::vector<std::uint32_t> touching;
        for (const Contact& contact : result.contacts)
            if (contact.touching) {
                touching.push_back(contact.id);
                const bool began =
                    std::find(touchingIds.begin(), touchingIds.end(), contact.id) == touchingIds.end();
                if (began && seconds >= knock.atS)
                    ++(outcome.pairsHeldBack > 0 ? outcome.touchDownsOnceHeld : outcome.touchDownsBeforeHold);
            }
        touchingIds = touching;
        outcome.pairsHeldBack += result.heldBack ? 1 : 0;
        if (result.correction) {
            EXPECT_FALSE(outcome.correction) << "corrected twice";
            outcome.correction = result.correction;
            outcome.correctedAfterS = seconds - knock.atS;
        }
        outcome.lastPx = result.calibrationErrorPx;
        if (!result.calibrationErrorPx)
            continue;
        if (seconds < knock.atS)
            outcome.mostBeforePx = std::max(outcome.mostBeforePx.value_or(0.0), *result.calibrationErrorPx);
        else if (!outcome.seenAfterS && *result.calibrationErrorPx > 1.0)
            outcome.seenAfterS = seconds - knock.atS;
    }
    return outcome;
}

TEST(TouchPipelineRendered, AKnockedCameraIsSeenWithinHalfASecondAndCorrected) {
    const KnockOutcome outcome = knocked(Knock{}, true);
    ASSERT_TRUE(outcome.mostBeforePx) << "nothing was measured before the knock";
    RecordProperty("most_before_px", std::to_string(*outcome.mostBeforePx));
    EXPECT_LT(*outcome.mostBeforePx, 0.2);
    ASSERT_TRUE(outcome.seenAfterS) << "the knock was not seen within 0.6 s";
    RecordProperty("seen_after_s", std::to_string(*outcome.seenAfterS));
    EXPECT_LT(*outcome.seenAfterS, 0.5);
    ASSERT_TRUE(outcome.correction) << "the knock was not corrected within 0.6 s";
    RecordProperty("corrected_after_s", std::to_string(*outcome.correctedAfterS));
    RecordProperty("correction_before_px", std::to_string(outcome.correction->beforePx));
    RecordProperty("correction_after_px", std::to_string(outcome.correction->afterPx));
    EXPECT_GT(outcome.correction->beforePx, 1.0);
    EXPECT_LT(outcome.correction->afterPx, 0.2);
    ASSERT_TRUE(outcome.lastPx) << "the check read nothing after the correction";
    RecordProperty("last_px", std::to_string(*outcome.lastPx));
    EXPECT_LT(*outcome.lastPx, 0.2);
}

TEST(TouchPipelineRendered, WithoutTheCorrectionAKnockedCameraStaysMisregistered) {
    const KnockOutcome outcome = knocked(Knock{}, false);
    EXPECT_TRUE(outcome.seenAfterS);
    EXPECT_FALSE(outcome.correction);
    ASSERT_TRUE(outcome.lastPx);
    EXPECT_GT(*outcome.lastPx, 1.0);
}

TEST(TouchPipelineRendered, AKnockedCamerasTableIsNotTakenForFingersBeforeTheCorrection) {
    // Knocked by 0.25 degrees at 1 s, while the hand is on its way to the first tap (1.7 s): the table's code
    // lies up to 1 projector px off until the correction, and what the segmentation then takes for a hand is
    // the table. Without the hold, 15 false touch-downs between the check's seeing the knock and the
    // correction; the 2 in the first two pairs, before three tiles were measured, are not prevented.
    const KnockOutcome outcome = knocked(Knock{1.0, 0.25, 0.5, 0.75, 1.6}, true);
    ASSERT_TRUE(outcome.correction) << "the knock was not corrected within 0.6 s";
    RecordProperty("corrected_after_s", std::to_string(*outcome.correctedAfterS));
    RecordProperty("pairs_held_back", outcome.pairsHeldBack);
    RecordProperty("touch_downs_before_hold", outcome.touchDownsBeforeHold);
    EXPECT_GT(outcome.pairsHeldBack, 0);
    EXPECT_EQ(outcome.touchDownsOnceHeld, 0);
    ASSERT_TRUE(outcome.lastPx);
    EXPECT_LT(*outcome.lastPx, 0.2);
}

TEST(TouchPipelineRendered, ACameraKnockedBeforeDetectionStartedIsCorrected) {
    // Seed 21's knock puts the code some 10 projector px off. The code's blur, measured on that code, came
    // out at 2.1 camera px instead of 0.92, and the check, predicting through it, found no shift consistent
    // enough to correct, for as long as the daemon ran: the blur is measured once the code lies where the
    // calibration predicts it.
    const KnockOutcome outcome = knocked(Knock{0.0, 0.5, 2.0, 0.0, 0.6, 21}, true);
    ASSERT_TRUE(outcome.correction) << "the knock was not corrected within 0.6 s";
    RecordProperty("corrected_after_s", std::to_string(*outcome.correctedAfterS));
    RecordProperty("correction_before_px", std::to_string(outcome.correction->beforePx));
    EXPECT_GT(outcome.correction->beforePx, 5.0);
    EXPECT_LT(outcome.correction->afterPx, 0.2);
    ASSERT_TRUE(outcome.lastPx) << "the check read nothing after the correction";
    EXPECT_LT(*outcome.lastPx, 0.2);
}

TEST(TouchPipelineRendered, FramesOfAnotherSizeReleaseEveryContactAndSayWhy) {
    // Someone changes the camera's region while a finger touches: the pair that mixes the two sizes and the
    // pairs after it detect nothing and say why; the calibration's size back, detection goes on.
    sim::SimParameters parameters;
    parameters.scenario = "grid35";
    parameters.startS = 1.4;  // the first tap touches from 1.7 s on
    sim::Simulator simulator(parameters, sim::rigPattern(parameters));
    TouchPipeline pipeline;
    const PipelineSettings settings = test::simulatedRigSettings(simulator);
    const auto centreQuarter = [](const Frame& frame) {
        Frame cropped = frame;
        const cv::Size size = frame.image.size();
        cropped.image =
            frame.image(cv::Rect(size.width / 4, size.height / 4, size.width / 2, size.height / 2));
        return cropped;
    };
    const auto process = [&](const Frame& older, const Frame& newer) -> const PipelineResult& {
        return processInOrder(pipeline, older, newer, settings);
    };
    const auto touching = [](const PipelineResult& result) {
        return std::any_of(result.contacts.begin(), result.contacts.end(),
                           [](const Contact& contact) { return contact.touching; });
    };

    Frame older, newer;
    sim::FrameTruth truth;
    const std::uint64_t first = simulator.firstFrame(), last = first + 120;
    simulator.render(first, older, truth);
    std::uint64_t index = first + 1;
    for (; index < last; ++index) {
        simulator.render(index, newer, truth);
        const bool touched = touching(process(older, newer));
        std::swap(older, newer);
        if (touched)
            break;
    }
    ASSERT_LT(index, last) << "no touch from 1.4 to 2.4 s into grid35";

    simulator.render(++index, newer, truth);
    const Frame smaller = centreQuarter(newer);
    const PipelineResult& mixed = process(older, smaller);
    EXPECT_FALSE(mixed.detecting);
    EXPECT_TRUE(mixed.contacts.empty());
    simulator.render(++index, older, truth);
    const PipelineResult& bothSmaller = process(smaller, centreQuarter(older));
    EXPECT_FALSE(bothSmaller.detecting);
    EXPECT_TRUE(bothSmaller.contacts.empty());
    EXPECT_EQ(bothSmaller.idleReason, "the camera's frames are 324x244, the calibration's 648x488");

    simulator.render(++index, newer, truth);
    EXPECT_TRUE(process(older, newer).detecting);
}

}  // namespace
}  // namespace everytouch::core
