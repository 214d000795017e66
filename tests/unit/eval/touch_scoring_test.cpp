#include "eval/touch_scoring.h"

#include <sstream>

#include <gtest/gtest.h>

#include "eval/touch_report.h"

#include "support/test_rig.h"

namespace everytouch::eval {
namespace {

constexpr double kRadiusPx = 20.0;

core::FingerTruth finger(std::uint32_t id, double x, double y, double heightMm) {
    core::FingerTruth truth;
    truth.id = id;
    truth.x = x;
    truth.y = y;
    truth.heightMm = heightMm;
    return truth;
}

core::Contact contact(std::uint32_t id, double x, double y, bool touching, double heightMm = 0.0) {
    core::Contact detected;
    detected.id = id;
    detected.x = x;
    detected.y = y;
    detected.touching = touching;
    detected.heightMm = heightMm;
    return detected;
}

// A tap at (x, 100): hovering at 12 and 4 mm, touching for four frames, lifting to 6 mm.
TruthFrames tap(std::uint32_t id, double x) {
    return {{finger(id, x, 100, 12)}, {finger(id, x, 100, 4)}, {finger(id, x, 100, 0)},
            {finger(id, x, 100, 0)},  {finger(id, x, 100, 0)}, {finger(id, x, 100, 0)},
            {finger(id, x, 100, 6)}};
}

// A detector that reports every true finger exactly, with the truth's height.
DetectedFrames perfect(const TruthFrames& truth) {
    DetectedFrames detected;
    for (const std::vector<core::FingerTruth>& frame : truth) {
        core::Contacts contacts;
        for (const core::FingerTruth& f : frame)
            contacts.push_back(contact(f.id + 10, f.x, f.y, f.heightMm == 0.0, f.heightMm));
        detected.push_back(contacts);
    }
    return detected;
}

TouchScoringOptions options() {
    TouchScoringOptions options;
    options.matchRadiusPx = kRadiusPx;
    return options;
}

TEST(ScoreTouches, APerfectDetectorScoresNoErrorAndNoRejection) {
    const TruthFrames truth = tap(1, 100);
    const TouchScore score = scoreTouches(truth, perfect(truth), options());
    ASSERT_EQ(score.trials.size(), 1u);
    EXPECT_EQ(score.frr(), 0.0);
    EXPECT_EQ(score.far(), 0.0);
    EXPECT_EQ(score.touchDowns, 1);
    EXPECT_EQ(score.downErrorPx.value(), 0.0);
    EXPECT_EQ(score.touchingErrorPx.value(), 0.0);
    EXPECT_EQ(score.touchingErrorPx.count, 4);
    EXPECT_EQ(score.latencyFrames.value(), 0.0);
    EXPECT_EQ(score.hoverErrorMm.value(), 0.0);
    EXPECT_EQ(score.hoverErrorMm.count, 3);
    EXPECT_EQ(score.idSwaps, 0);
    EXPECT_EQ(score.highHoverFrames, 1);
    EXPECT_EQ(score.highHoverTouchFrames, 0);
}

TEST(ScoreTouches, AMissedTapIsRejected) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    for (core::Contacts& contacts : detected)
        for (core::Contact& c : contacts)
            c.touching = false;
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.rejected(), 1);
    EXPECT_EQ(score.frr(), 1.0);
    EXPECT_FALSE(score.downErrorPx.value());
}

TEST(ScoreTouches, ATouchTooFarFromTheFingerDoesNotCount) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    for (core::Contacts& contacts : detected)
        for (core::Contact& c : contacts)
            c.x += kRadiusPx + 1;
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.rejected(), 1);
    // Its touch-down explains nothing: a false acceptance as well.
    EXPECT_EQ(score.phantoms.size(), 1u);
}

TEST(ScoreTouches, APhantomTouchIsAFalseAcceptance) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[0].push_back(contact(50, 400, 300, true));
    detected[1].push_back(contact(50, 400, 300, true));
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.frr(), 0.0);
    EXPECT_EQ(score.touchDowns, 2);
    ASSERT_EQ(score.phantoms.size(), 1u);
    EXPECT_EQ(score.phantoms[0].position, 0u);
    EXPECT_EQ(score.far(), 1.0);
}

TEST(ScoreTouches, ATouchDownWhileThePadIsWithinTheTouchHeightIsEarlyNotFalse) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[1][0].touching = true;  // at 4 mm, a frame before the pad lands
    TouchScoringOptions withinFour = options();
    withinFour.touchHeightMm = 4.0;
    const TouchScore early = scoreTouches(truth, detected, withinFour);
    EXPECT_EQ(early.touchDowns, 1);
    EXPECT_TRUE(early.phantoms.empty());
    EXPECT_EQ(early.latencyFrames.value(), 0.0);

    TouchScoringOptions withinThree = options();
    withinThree.touchHeightMm = 3.0;
    const TouchScore tooEarly = scoreTouches(truth, detected, withinThree);
    ASSERT_EQ(tooEarly.phantoms.size(), 1u);
    EXPECT_EQ(tooEarly.phantoms[0].position, 1u);
}

TEST(ScoreTouches, ATouchAtEightMillimetresIsCounted) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[0][0].touching = true;  // the finger is 12 mm up
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.highHoverTouchFrames, 1);
    EXPECT_EQ(score.phantoms.size(), 1u);
}

TEST(ScoreTouches, ALateTouchGivesItsLatencyAndError) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[2][0].touching = false;
    detected[3][0].touching = false;
    detected[4][0].x += 3;
    detected[4][0].y += 4;
    const TouchScore score = scoreTouches(truth, detected, options());
    ASSERT_EQ(score.trials.size(), 1u);
    EXPECT_TRUE(score.trials[0].found);
    EXPECT_EQ(score.trials[0].touchDown, 4u);
    EXPECT_EQ(score.latencyFrames.value(), 2.0);
    EXPECT_EQ(score.maxLatencyFrames, 2);
    EXPECT_DOUBLE_EQ(*score.downErrorPx.value(), 5.0);
    EXPECT_DOUBLE_EQ(*score.touchingErrorPx.value(), 5.0 / 2);
}

TEST(ScoreTouches, AnIdSwitchWhileTouchingIsASwap) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[4][0].id = 99;
    detected[5][0].id = 99;
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.idSwaps, 1);
    // The new id's touch-down lies on a true touching finger: no false acceptance.
    EXPECT_EQ(score.touchDowns, 2);
    EXPECT_TRUE(score.phantoms.empty());
}

TEST(ScoreTouches, HoverErrorGoesToItsBand) {
    const TruthFrames truth = tap(1, 100);
    DetectedFrames detected = perfect(truth);
    detected[1][0].heightMm = 5.5;  // truth 4 mm: band 2-5
    detected[6][0].heightMm = 6.5;  // truth 6 mm: band 5-10
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_DOUBLE_EQ(*score.hoverBandErrorMm[0].value(), 1.5);
    EXPECT_DOUBLE_EQ(*score.hoverBandErrorMm[1].value(), 0.5);
    EXPECT_DOUBLE_EQ(*score.hoverErrorMm.value(), 2.0 / 3);
    EXPECT_FALSE(score.hoverBandErrorMm[3].value());
}

TEST(ScoreTouches, DragDeviationIsTheDistanceToTheTruePath) {
    // A drag along y = 100 from x = 100 to 160; the contact runs 2 px beside it and lags a frame behind.
    TruthFrames truth;
    DetectedFrames detected;
    for (int i = 0; i < 7; ++i) {
        truth.push_back({finger(1, 100 + 10 * i, 100, 0)});
        detected.push_back({contact(7, 100 + 10 * std::max(0, i - 1), 102, true)});
    }
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.dragTrials, 1);
    EXPECT_DOUBLE_EQ(*score.dragDeviationPx.value(), 2.0);
    EXPECT_GT(*score.touchingErrorPx.value(), 2.0);
}

TEST(ScoreTouches, EachContactServesOneFinger) {
    // Two fingers touching side by side, one contact between them: one trial is found, the other rejected.
    TruthFrames truth{{finger(1, 100, 100, 0), finger(2, 115, 100, 0)}};
    DetectedFrames detected{{contact(3, 109, 100, true)}};
    const TouchScore score = scoreTouches(truth, detected, options());
    EXPECT_EQ(score.rejected(), 1);
    EXPECT_TRUE(score.trials[1].found);
}

TEST(TouchTrace, GivesEachFingerItsMatchedContactOrEmptyFields) {
    TruthFrames truth = {{finger(1, 100, 100, 4), finger(2, 300, 100, 0)}, {finger(1, 100, 100, 0)}};
    DetectedFrames detected = {{contact(7, 103, 104, true, 1.5), contact(8, 500, 100, true)}, {}};
    std::ostringstream out;
    writeTouchTrace(out, truth, detected, kRadiusPx);
    EXPECT_EQ(out.str(),
              "position,finger,truth_height_mm,truth_x,truth_y,contact_id,height_mm,touching,x,y\n"
              "0,1,4.00,100.00,100.00,7,1.50,1,103.00,104.00\n"
              "0,2,0.00,300.00,100.00,,,,,\n"
              "1,1,0.00,100.00,100.00,,,,,\n");
}

TEST(MatchRadius, ConvertsMillimetresWithTheDisplaysScale) {
    // A millimetre on the table spans between the display's horizontal and vertical pixel scales.
    const core::Calibration calibration = test::paperLikeCalibration();
    const cv::Size2d sizeMm = calibration.displaySizeMm();
    const double across = calibration.displaySize.width / sizeMm.width;
    const double down = calibration.displaySize.height / sizeMm.height;
    const double perMm = matchRadiusPx(calibration, 1.0);
    EXPECT_GE(perMm, std::min(across, down));
    EXPECT_LE(perMm, std::max(across, down));
    EXPECT_NEAR(matchRadiusPx(calibration, 8.0), 8.0 * perMm, 1e-9);
}

TEST(TouchScoringOptions, ValidateNamesTheRadius) {
    TouchScoringOptions bad;
    ASSERT_TRUE(bad.validate());
    EXPECT_NE(bad.validate()->find("radius"), std::string::npos);
    EXPECT_FALSE(options().validate());
}

}  // namespace
}  // namespace everytouch::eval
