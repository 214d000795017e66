#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/capsule.h"

namespace everytouch::sim {

enum class Finger : int { Thumb = 0, Index, Middle, Ring, Little };
inline constexpr int kFingerCount = 5;

// Joint angles of one finger. For the thumb the first joint is the carpometacarpal joint and the first bone
// the metacarpal; for the others the first joint is the knuckle (MCP).
struct FingerJoints {
    double abductionDeg = 0.0;                  // sideways at the first joint, + towards the thumb
    std::array<double, 3> flexionDeg{0, 0, 0};  // at the three joints, + curls towards the palm
};

// Where a hand is and how it is bent.
struct HandPose {
    // Wrist frame: origin at the centre of the wrist, x towards the fingers, y towards the thumb of a right
    // hand, z out of the back of the hand.
    Eigen::Isometry3d wristToTable = Eigen::Isometry3d::Identity();
    std::array<FingerJoints, kFingerCount> fingers{};
    // Fingers whose tips the person presents to the table (pointing, touching, hovering); curled fingers are
    // not reported as fingertips in the ground truth.
    std::array<bool, kFingerCount> presented{};
    bool left = false;                  // a left hand: the mirror image of a right hand
    double forearmElevationDeg = 15.0;  // the forearm rises behind the wrist, relative to the wrist's x axis
    double scale = 1.0;                 // size relative to an average adult hand

    // Wrist placed at `wrist`, the hand pointing along `yawDeg` (0: table +x, 90: +y) and tilted fingers-down
    // by `pitchDeg`, rolled by `rollDeg` about its own axis.
    void place(const Eigen::Vector3d& wrist, double yawDeg, double pitchDeg, double rollDeg = 0.0);
};

// Joint presets.
FingerJoints curledJoints(Finger finger);
FingerJoints pointingJoints(Finger finger);
FingerJoints relaxedJoints(Finger finger);

// What a capsule of a hand is, for shading and for the ground truth.
enum class HandPart : std::uint8_t { Forearm, Palm, Knuckles, Thenar, Bone, Fingertip };

struct HandCapsule {
    Capsule shape;
    HandPart part = HandPart::Bone;
};

// The posed hand: its capsules in the table frame and each finger's pad.
struct HandModel {
    std::vector<HandCapsule> capsules;
    std::array<Eigen::Vector3d, kFingerCount> pads;  // lowest point of each fingertip, table mm
    std::array<Eigen::Vector3d, kFingerCount> tips;  // farthest point of each fingertip along its bone
};

HandModel buildHand(const HandPose& pose);

// Lowest point of one finger's tip for the pose, table mm (cheaper than building the whole hand).
Eigen::Vector3d fingerPad(const HandPose& pose, Finger finger);

// Bends `finger` (abduction, first and second flexion; the third follows the second) so that its pad lands
// on `target` as closely as the joint limits allow, the height before the place. Returns the remaining
// distance, mm.
double reachPad(HandPose& pose, Finger finger, const Eigen::Vector3d& target);

// Moves the whole hand so that the pad of `finger` lands exactly on `target`.
void movePadTo(HandPose& pose, Finger finger, const Eigen::Vector3d& target);

}  // namespace everytouch::sim
