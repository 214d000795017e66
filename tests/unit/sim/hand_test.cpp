#include "sim/hand.h"

#include <gtest/gtest.h>

#include "sim/capsule.h"

namespace everytouch::sim {
namespace {

TEST(Capsule, RayHitsTheEllipticCrossSectionWhereExpected) {
    // A bone along x, 16 mm wide (y) and 12 mm thick (z), seen from 100 mm above.
    const Capsule bone = Capsule::bone({0, 0, 0}, {40, 0, 0}, {0, 1, 0}, 8.0, 6.0, 6.0);
    const CapsuleHit hit(bone, {20, 0, 100});
    EXPECT_NEAR(hit.intersect({0, 0, -1}), 94.0, 1e-3);  // top of the bone, 6 mm up
    EXPECT_GT(hit.intersect(Eigen::Vector3f(0, 7.9f, -100) / 100.0f), 0.0f);
    EXPECT_LT(hit.intersect(Eigen::Vector3f(0, 8.1f, -100) / 100.0f), 0.0f);  // just outside it
    const Eigen::Vector3f normal = hit.normal({0, 0, -1}, 94.0f);
    EXPECT_NEAR(normal.z(), 1.0f, 1e-5);
    // Beyond the end the cap is an ellipsoid of axial radius 6: it reaches x = 46, not 48.
    const CapsuleHit fromAbove(bone, {45, 0, 100});
    EXPECT_GT(fromAbove.intersect({0, 0, -1}), 0.0f);
    const CapsuleHit pastEnd(bone, {46.5, 0, 100});
    EXPECT_LT(pastEnd.intersect({0, 0, -1}), 0.0f);
}

TEST(Capsule, SupportPointIsTheLowestPoint) {
    const Capsule tilted = Capsule::bone({0, 0, 20}, {20, 0, 0}, {0, 1, 0}, 7.5, 5.5, 5.5);
    const Eigen::Vector3d lowest = tilted.supportPoint(-Eigen::Vector3d::UnitZ());
    // A 45-degree bone with equal cap and thickness radii: its lowest point is straight below the axis' end.
    EXPECT_NEAR(lowest.z(), -5.5, 1e-9);
    EXPECT_NEAR(lowest.x(), 20.0, 1e-9);
    EXPECT_NEAR(lowest.y(), 0.0, 1e-9);
}

TEST(Hand, MovePadToPutsThePadExactlyOnTheTarget) {
    HandPose pose;
    for (int f = 0; f < kFingerCount; ++f)
        pose.fingers[f] = pointingJoints(static_cast<Finger>(f));
    pose.place({0, 0, 0}, -90.0, 30.0);
    const Eigen::Vector3d target(12.0, -30.0, 0.0);
    movePadTo(pose, Finger::Index, target);
    EXPECT_LT((fingerPad(pose, Finger::Index) - target).norm(), 1e-9);
    const HandModel model = buildHand(pose);
    EXPECT_LT((model.pads[1] - target).norm(), 1e-9);
    // Nothing of the hand goes through the table.
    for (const HandCapsule& capsule : model.capsules)
        EXPECT_GT(capsule.shape.supportPoint(-Eigen::Vector3d::UnitZ()).z(), -1e-6);
}

TEST(Hand, ReachPadBendsTheFingerOntoATargetWithinReach) {
    HandPose pose;
    for (int f = 0; f < kFingerCount; ++f)
        pose.fingers[f] = relaxedJoints(static_cast<Finger>(f));
    pose.place({0, 0, 60}, 0.0, 10.0);
    for (Finger finger : {Finger::Thumb, Finger::Index, Finger::Middle, Finger::Ring, Finger::Little}) {
        // A target the finger can reach: where another bend of it puts the pad.
        HandPose bent = pose;
        FingerJoints& joints = bent.fingers[static_cast<int>(finger)];
        joints.abductionDeg += 6.0;
        joints.flexionDeg[0] += 12.0;
        joints.flexionDeg[1] += 15.0;
        joints.flexionDeg[2] = joints.flexionDeg[1] * (finger == Finger::Thumb ? 0.8 : 0.7);
        const Eigen::Vector3d target = fingerPad(bent, finger);
        ASSERT_GT((fingerPad(pose, finger) - target).norm(), 5.0);
        EXPECT_LT(reachPad(pose, finger, target), 1e-4) << static_cast<int>(finger);
        EXPECT_LT((fingerPad(pose, finger) - target).norm(), 1e-4);
    }
}

TEST(Hand, FingersHaveRealisticSize) {
    HandPose pose;
    pose.place({0, 0, 100}, 0.0, 0.0);
    const HandModel model = buildHand(pose);
    int fingertips = 0;
    for (const HandCapsule& capsule : model.capsules) {
        if (capsule.part != HandPart::Bone && capsule.part != HandPart::Fingertip)
            continue;
        const double width = 2.0 * capsule.shape.axes.col(1).norm();
        const double thickness = 2.0 * capsule.shape.axes.col(2).norm();
        EXPECT_GE(width, 12.0);
        EXPECT_LE(width, 22.0);
        EXPECT_GE(thickness, 9.5);
        EXPECT_LE(thickness, 17.5);
        fingertips += capsule.part == HandPart::Fingertip;
    }
    EXPECT_EQ(fingertips, kFingerCount);
    // A straight middle finger reaches about 185 mm from the wrist.
    EXPECT_NEAR((model.tips[2] - Eigen::Vector3d(0, 0, 100)).norm(), 190.0, 15.0);
}

TEST(Hand, LeftHandIsTheMirrorImage) {
    HandPose right, left;
    right.place({0, 0, 50}, 0.0, 0.0);
    left = right;
    left.left = true;
    const Eigen::Vector3d thumbRight = fingerPad(right, Finger::Thumb);
    const Eigen::Vector3d thumbLeft = fingerPad(left, Finger::Thumb);
    EXPECT_NEAR(thumbLeft.x(), thumbRight.x(), 1e-9);
    EXPECT_NEAR(thumbLeft.y(), -thumbRight.y(), 1e-9);
    EXPECT_NEAR(thumbLeft.z(), thumbRight.z(), 1e-9);
}

}  // namespace
}  // namespace everytouch::sim
