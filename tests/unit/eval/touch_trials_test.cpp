#include "eval/touch_trials.h"

#include <gtest/gtest.h>

namespace everytouch::eval {
namespace {

core::FingerTruth finger(std::uint32_t id, double heightMm) {
    core::FingerTruth truth;
    truth.id = id;
    truth.x = 100;
    truth.y = 100;
    truth.heightMm = heightMm;
    return truth;
}

TEST(TouchTrials, ATrialIsAMaximalRunOfTouchingFramesPerFinger) {
    // Finger 1 touches in frames 1-2 and again in 4; finger 2 touches in 2-5 (the end of the recording).
    TruthFrames truth{{finger(1, 5)},
                      {finger(1, 0)},
                      {finger(1, 0), finger(2, 0)},
                      {finger(1, 3), finger(2, 0)},
                      {finger(1, 0), finger(2, 0)},
                      {finger(2, 0)}};
    const std::vector<TouchTrial> trials = touchTrials(truth);
    ASSERT_EQ(trials.size(), 3u);
    EXPECT_EQ(trials[0].finger, 1u);
    EXPECT_EQ(trials[0].first, 1u);
    EXPECT_EQ(trials[0].last, 2u);
    EXPECT_EQ(trials[1].finger, 2u);
    EXPECT_EQ(trials[1].first, 2u);
    EXPECT_EQ(trials[1].last, 5u);
    EXPECT_EQ(trials[2].finger, 1u);
    EXPECT_EQ(trials[2].first, 4u);
    EXPECT_EQ(trials[2].last, 4u);
}

TEST(TouchTrials, AFrameWithoutTheFingerEndsItsTrial) {
    TruthFrames truth{{finger(1, 0)}, {}, {finger(1, 0)}};
    EXPECT_EQ(touchTrials(truth).size(), 2u);
}

}  // namespace
}  // namespace everytouch::eval
