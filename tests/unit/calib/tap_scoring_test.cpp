#include "tap_scoring.h"

#include <cmath>

#include <gtest/gtest.h>

namespace everytouch::calib {
namespace {

// The paper's display: 640 x 480 px, 320 x 240 mm on the table (0.5 mm a pixel).
DaemonClient::Display paperDisplay() {
    return {640, 480, 320.0, 240.0};
}

TouchDown at(double x, double y, std::uint32_t id = 1, double seconds = 0.0) {
    return {seconds, id, {x, y}};
}

ContactReading contact(std::uint32_t id, double x, double y, bool touching) {
    ContactReading reading;
    reading.id = id;
    reading.x = x;
    reading.y = y;
    reading.touching = touching;
    reading.heightMm = touching ? 0.0 : 10.0;
    return reading;
}

TEST(AccuracyTargets, AreThePapersGridOnTheDisplayScaledToTheTable) {
    const TapTargets targets = accuracyTargets(paperDisplay());
    ASSERT_EQ(targets.centres.size(), 35u);
    EXPECT_DOUBLE_EQ(targets.centres.front().x, 80.0);
    EXPECT_DOUBLE_EQ(targets.centres.front().y, 80.0);
    EXPECT_DOUBLE_EQ(targets.centres[6].x, 560.0);  // the first row's last circle
    EXPECT_DOUBLE_EQ(targets.centres[7].y, 160.0);  // the second row
    EXPECT_DOUBLE_EQ(targets.centres.back().x, 560.0);
    EXPECT_DOUBLE_EQ(targets.centres.back().y, 400.0);
    EXPECT_DOUBLE_EQ(targets.radiusPx, 21.6);  // the circle the simulated projector draws (22 px)
    EXPECT_DOUBLE_EQ(targets.mmPerPxAcross, 0.5);
    EXPECT_DOUBLE_EQ(targets.mmPerPxDown, 0.5);
}

TEST(ScoreTaps, OneTapOnEachCircleScoresTheMeanDistanceToTheCentres) {
    const TapTargets targets = accuracyTargets(paperDisplay());
    std::vector<TouchDown> touchDowns;
    // Every circle tapped 3 px right of its centre and 4 px below it: 5 px, 2.5 mm.
    for (const core::DisplayPoint& centre : targets.centres)
        touchDowns.push_back(at(centre.x + 3, centre.y + 4));
    const TapScore score = scoreTaps(targets, touchDowns);
    EXPECT_TRUE(score.complete());
    EXPECT_EQ(score.tapped(), 35);
    EXPECT_DOUBLE_EQ(*score.epsilonPx(), 5.0);
    EXPECT_DOUBLE_EQ(*score.epsilonMm(), 2.5);
    EXPECT_EQ(score.frr(), 0.0);
    EXPECT_EQ(score.far(), 0.0);
    EXPECT_EQ(score.touchDowns, 35);
    EXPECT_EQ(score.repeats, 0);
}

TEST(ScoreTaps, ATouchDownOutsideEveryCircleIsFalseAndItsCircleRejected) {
    const TapTargets targets = accuracyTargets(paperDisplay());
    std::vector<TouchDown> touchDowns;
    for (std::size_t i = 1; i < targets.centres.size(); ++i)
        touchDowns.push_back(at(targets.centres[i].x, targets.centres[i].y));
    // Beside the first circle, just outside its radius (21.6 px), and between two circles.
    touchDowns.push_back(at(80.0 + 22.0, 80.0));
    touchDowns.push_back(at(120.0, 120.0));
    const TapScore score = scoreTaps(targets, touchDowns);
    EXPECT_FALSE(score.complete());
    EXPECT_FALSE(score.circles[0].tap.has_value());
    EXPECT_EQ(score.tapped(), 34);
    EXPECT_DOUBLE_EQ(score.frr(), 1.0 / 35.0);
    ASSERT_EQ(score.falseTouchDowns.size(), 2u);
    EXPECT_DOUBLE_EQ(score.falseTouchDowns[0].point.x, 102.0);
    EXPECT_DOUBLE_EQ(score.far(), 2.0 / 35.0);
    EXPECT_DOUBLE_EQ(*score.epsilonPx(), 0.0);  // the false touch-downs do not count in epsilon
    EXPECT_EQ(score.touchDowns, 36);
}

TEST(ScoreTaps, TheFirstTouchDownOnACircleIsItsTapAndLaterOnesAreRepeats) {
    const TapTargets targets = accuracyTargets(paperDisplay());
    const TapScore score =
        scoreTaps(targets, {at(80.0, 86.0, 1, 1.0), at(80.0, 80.0, 2, 2.0), at(81.0, 80.0, 3, 3.0)});
    const CircleOutcome& first = score.circles[0];
    ASSERT_TRUE(first.tap.has_value());
    EXPECT_EQ(first.tap->id, 1u);
    EXPECT_DOUBLE_EQ(first.errorPx, 6.0);
    EXPECT_DOUBLE_EQ(first.errorMm, 3.0);
    EXPECT_EQ(first.repeats, 2);
    EXPECT_EQ(score.repeats, 2);
    EXPECT_TRUE(score.falseTouchDowns.empty());  // a finger on a target is not a false touch
    EXPECT_EQ(score.far(), 0.0);
    EXPECT_DOUBLE_EQ(*score.epsilonPx(), 6.0);
    EXPECT_DOUBLE_EQ(score.frr(), 34.0 / 35.0);
}

TEST(ScoreTaps, ATouchDownGoesToTheNearestCircleWhoseRadiusHoldsIt) {
    TapTargets targets;
    targets.centres = {{100, 100}, {110, 100}};
    targets.radiusPx = 20.0;
    targets.mmPerPxAcross = targets.mmPerPxDown = 1.0;
    const TapScore score = scoreTaps(targets, {at(107, 100)});
    EXPECT_FALSE(score.circles[0].tap.has_value());
    ASSERT_TRUE(score.circles[1].tap.has_value());
    EXPECT_DOUBLE_EQ(score.circles[1].errorPx, 3.0);
}

TEST(ScoreTaps, ErrorsInMmFollowEachAxisScale) {
    TapTargets targets;
    targets.centres = {{100, 100}};
    targets.radiusPx = 20.0;
    targets.mmPerPxAcross = 0.5;
    targets.mmPerPxDown = 0.25;
    const TapScore score = scoreTaps(targets, {at(106, 108)});
    EXPECT_DOUBLE_EQ(score.circles[0].errorPx, 10.0);
    EXPECT_DOUBLE_EQ(score.circles[0].errorMm, std::hypot(3.0, 2.0));
}

TEST(ScoreTaps, WithoutTouchDownsEveryCircleIsRejectedAndEpsilonUndefined) {
    const TapScore score = scoreTaps(accuracyTargets(paperDisplay()), {});
    EXPECT_EQ(score.tapped(), 0);
    EXPECT_FALSE(score.epsilonPx().has_value());
    EXPECT_FALSE(score.epsilonMm().has_value());
    EXPECT_EQ(score.frr(), 1.0);
    EXPECT_EQ(score.far(), 0.0);
}

TEST(TouchDownFinder, ReportsAContactWhenItGoesToTouchingOrAppearsTouching) {
    TouchDownFinder finder;
    EXPECT_TRUE(finder.next(0.0, {contact(1, 10, 10, false)}).empty());  // hovering
    EXPECT_TRUE(finder.next(0.05, {contact(1, 10, 11, false)}).empty());
    std::vector<TouchDown> found = finder.next(0.1, {contact(1, 11, 12, true), contact(2, 50, 50, true)});
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(found[0].id, 1u);
    EXPECT_DOUBLE_EQ(found[0].point.x, 11.0);
    EXPECT_DOUBLE_EQ(found[0].point.y, 12.0);
    EXPECT_DOUBLE_EQ(found[0].seconds, 0.1);
    EXPECT_EQ(found[1].id, 2u);
    // Still touching, moving: no new touch-down.
    EXPECT_TRUE(finder.next(0.2, {contact(1, 13, 12, true), contact(2, 50, 51, true)}).empty());
    // Contact 1 lifts to hover, contact 2 is gone; then both touch again.
    EXPECT_TRUE(finder.next(0.3, {contact(1, 13, 12, false)}).empty());
    found = finder.next(0.4, {contact(1, 13, 12, true), contact(2, 50, 51, true)});
    ASSERT_EQ(found.size(), 2u);
    EXPECT_DOUBLE_EQ(found[1].seconds, 0.4);
    // Everything lifted: an empty signal.
    EXPECT_TRUE(finder.next(0.5, {}).empty());
    EXPECT_EQ(finder.next(0.6, {contact(2, 50, 51, true)}).size(), 1u);
}

TEST(TouchDownFinder, AContactTouchingInTheFirstSignalTouchedDownBeforeItAndIsNotReported) {
    TouchDownFinder finder;
    EXPECT_TRUE(finder.next(0.0, {contact(1, 10, 10, true), contact(2, 50, 50, false)}).empty());
    EXPECT_TRUE(finder.next(0.1, {contact(1, 10, 10, true), contact(2, 50, 50, false)}).empty());
    const std::vector<TouchDown> found =
        finder.next(0.2, {contact(1, 10, 10, true), contact(2, 50, 50, true)});
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].id, 2u);
}

}  // namespace
}  // namespace everytouch::calib
