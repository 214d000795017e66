#include "sim/hand.h"

#include <algorithm>
#include <cmath>

namespace everytouch::sim {

namespace {

constexpr double kDegree = M_PI / 180.0;

// One finger of an average adult right hand in the wrist frame, mm (bone lengths include the soft tip).
struct FingerAnatomy {
    Eigen::Vector3d root;                          // first joint
    double restYawDeg, restPitchDeg, restRollDeg;  // direction of the straight finger
    std::array<double, 3> length;                  // bones, first to last
    std::array<double, 3> width;                   // side to side
    std::array<double, 3> thickness;               // back to pad
    double lastJointCoupling;                      // third flexion = coupling x second flexion
    double abductionLimitDeg[2], firstFlexionLimitDeg[2], secondFlexionLimitDeg[2];
};

const std::array<FingerAnatomy, kFingerCount>& anatomy() {
    static const std::array<FingerAnatomy, kFingerCount> fingers{{
        {{24, 20, -10},
         40,
         25,
         70,
         {44, 32, 27},
         {21, 20, 18.5},
         {17, 16, 14},
         0.8,
         {-20, 60},
         {-20, 60},
         {-10, 80}},
        {{92, 25, 0},
         4,
         0,
         0,
         {42, 25, 21},
         {18, 16.5, 15.5},
         {14, 12.5, 11},
         0.7,
         {-25, 25},
         {-10, 95},
         {0, 110}},
        {{96, 6, 1},
         0,
         0,
         0,
         {46, 28, 22},
         {18.5, 17, 16},
         {14.5, 13, 11.5},
         0.7,
         {-25, 25},
         {-10, 95},
         {0, 110}},
        {{91, -12, 0},
         -4,
         0,
         0,
         {43, 27, 21},
         {17.5, 16, 15},
         {14, 12.5, 11},
         0.7,
         {-25, 25},
         {-10, 95},
         {0, 110}},
        {{80, -29, -2},
         -9,
         0,
         0,
         {34, 20, 19},
         {15.5, 14, 13},
         {12.5, 11, 10},
         0.7,
         {-25, 25},
         {-10, 95},
         {0, 110}},
    }};
    return fingers;
}

Eigen::Matrix3d rotZ(double degrees) {
    return Eigen::AngleAxisd(degrees * kDegree, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}
Eigen::Matrix3d rotY(double degrees) {
    return Eigen::AngleAxisd(degrees * kDegree, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d rotX(double degrees) {
    return Eigen::AngleAxisd(degrees * kDegree, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

// Wrist frame of a right hand -> table, including the mirror of a left hand and the hand's scale.
Eigen::Affine3d wristFrameToTable(const HandPose& pose) {
    Eigen::Affine3d transform(pose.wristToTable);
    transform.linear() =
        transform.linear() * Eigen::Vector3d(1.0, pose.left ? -1.0 : 1.0, 1.0).asDiagonal() * pose.scale;
    return transform;
}

Capsule toTable(const Capsule& local, const Eigen::Affine3d& transform) {
    Capsule capsule;
    capsule.origin = transform * local.origin;
    capsule.axes = transform.linear() * local.axes;
    capsule.length = local.length;
    return capsule;
}

// The three bones of a finger in the wrist frame of a right hand of scale 1.
std::array<Capsule, 3> fingerBones(const FingerJoints& joints, Finger finger) {
    const FingerAnatomy& a = anatomy()[static_cast<int>(finger)];
    const double third = joints.flexionDeg[2];
    Eigen::Matrix3d frame = rotZ(a.restYawDeg) * rotY(a.restPitchDeg) * rotX(a.restRollDeg) *
                            rotZ(joints.abductionDeg) * rotY(joints.flexionDeg[0]);
    std::array<Capsule, 3> bones;
    Eigen::Vector3d joint = a.root;
    for (int i = 0; i < 3; ++i) {
        if (i == 1)
            frame = frame * rotY(joints.flexionDeg[1]);
        if (i == 2)
            frame = frame * rotY(third);
        const double cap = a.thickness[i] / 2.0;
        // The last bone's axis stops short of the tip by its cap, so the tip of the flesh is at `length`.
        const double axisLength = i == 2 ? a.length[i] - cap : a.length[i];
        const Eigen::Vector3d next = joint + frame.col(0) * axisLength;
        bones[i] = Capsule::bone(joint, next, frame.col(1), a.width[i] / 2.0, a.thickness[i] / 2.0, cap);
        joint = next;
    }
    return bones;
}

}  // namespace

void HandPose::place(const Eigen::Vector3d& wrist, double yawDeg, double pitchDeg, double rollDeg) {
    wristToTable = Eigen::Isometry3d::Identity();
    wristToTable.translation() = wrist;
    wristToTable.linear() = rotZ(yawDeg) * rotY(pitchDeg) * rotX(rollDeg);
}

FingerJoints curledJoints(Finger finger) {
    if (finger == Finger::Thumb)
        return {-15.0, {35.0, 45.0, 30.0}};
    return {0.0, {85.0, 100.0, 60.0}};
}

FingerJoints pointingJoints(Finger finger) {
    if (finger == Finger::Index)
        return {0.0, {0.0, 12.0, 8.0}};
    return curledJoints(finger);
}

FingerJoints relaxedJoints(Finger finger) {
    constexpr std::array<double, kFingerCount> spread{25.0, 6.0, 0.0, -6.0, -12.0};
    const int i = static_cast<int>(finger);
    if (finger == Finger::Thumb)
        return {spread[i], {10.0, 15.0, 15.0}};
    return {spread[i], {15.0, 20.0, 14.0}};
}

HandModel buildHand(const HandPose& pose) {
    const Eigen::Affine3d transform = wristFrameToTable(pose);
    HandModel model;
    auto add = [&](const Capsule& local, HandPart part) {
        model.capsules.push_back({toTable(local, transform), part});
    };
    const double elevation = pose.forearmElevationDeg * kDegree;
    const Eigen::Vector3d elbowward(-std::cos(elevation), 0.0, std::sin(elevation));
    const Eigen::Vector3d wristJoint(6.0, 0.0, -3.0);
    add(Capsule::bone(wristJoint, wristJoint + elbowward * 300.0, Eigen::Vector3d::UnitY(), 30.0, 22.0, 22.0),
        HandPart::Forearm);
    add(Capsule::ellipsoid({50.0, 0.0, -4.0}, Eigen::Matrix3d::Identity(), {50.0, 40.0, 14.0}),
        HandPart::Palm);
    add(Capsule::bone({88.0, 26.0, -3.0}, {78.0, -27.0, -4.0}, Eigen::Vector3d::UnitX(), 12.0, 11.5, 11.0),
        HandPart::Knuckles);
    add(Capsule::ellipsoid({38.0, 24.0, -10.0}, rotZ(35.0), {30.0, 15.0, 13.0}), HandPart::Thenar);
    for (int f = 0; f < kFingerCount; ++f) {
        const std::array<Capsule, 3> bones = fingerBones(pose.fingers[f], static_cast<Finger>(f));
        add(bones[0], HandPart::Bone);
        add(bones[1], HandPart::Bone);
        add(bones[2], HandPart::Fingertip);
        const Capsule& tip = model.capsules.back().shape;
        model.pads[f] = tip.supportPoint(-Eigen::Vector3d::UnitZ());
        model.tips[f] = tip.supportPoint(tip.axes.col(0).normalized());
    }
    return model;
}

Eigen::Vector3d fingerPad(const HandPose& pose, Finger finger) {
    const Capsule tip =
        toTable(fingerBones(pose.fingers[static_cast<int>(finger)], finger)[2], wristFrameToTable(pose));
    return tip.supportPoint(-Eigen::Vector3d::UnitZ());
}

double reachPad(HandPose& pose, Finger finger, const Eigen::Vector3d& target) {
    const FingerAnatomy& a = anatomy()[static_cast<int>(finger)];
    FingerJoints& joints = pose.fingers[static_cast<int>(finger)];
    auto clampJoints = [&](Eigen::Vector3d& q) {
        q[0] = std::clamp(q[0], a.abductionLimitDeg[0], a.abductionLimitDeg[1]);
        q[1] = std::clamp(q[1], a.firstFlexionLimitDeg[0], a.firstFlexionLimitDeg[1]);
        q[2] = std::clamp(q[2], a.secondFlexionLimitDeg[0], a.secondFlexionLimitDeg[1]);
    };
    auto apply = [&](const Eigen::Vector3d& q) {
        joints.abductionDeg = q[0];
        joints.flexionDeg = {q[1], q[2], q[2] * a.lastJointCoupling};
    };
    // Height matters most: a finger that cannot reach the target's place still touches (or hovers) at the
    // target's height.
    const Eigen::Vector3d weight(1.0, 1.0, 10.0);
    auto residual = [&](const Eigen::Vector3d& q) {
        apply(q);
        return Eigen::Vector3d((fingerPad(pose, finger) - target).cwiseProduct(weight));
    };
    Eigen::Vector3d q(joints.abductionDeg, joints.flexionDeg[0], joints.flexionDeg[1]);
    clampJoints(q);
    Eigen::Vector3d r = residual(q);
    double damping = 1e-3;
    for (int iteration = 0; iteration < 60 && r.norm() > 1e-7; ++iteration) {
        Eigen::Matrix3d jacobian;
        constexpr double kStepDeg = 1e-3;
        for (int i = 0; i < 3; ++i) {
            Eigen::Vector3d shifted = q;
            shifted[i] += kStepDeg;
            jacobian.col(i) = (residual(shifted) - r) / kStepDeg;
        }
        const Eigen::Matrix3d normal = jacobian.transpose() * jacobian;
        Eigen::Vector3d candidate = q - (normal + damping * Eigen::Matrix3d(normal.diagonal().asDiagonal()) +
                                         1e-9 * Eigen::Matrix3d::Identity())
                                            .ldlt()
                                            .solve(jacobian.transpose() * r);
        clampJoints(candidate);
        const Eigen::Vector3d candidateResidual = residual(candidate);
        if (candidateResidual.norm() < r.norm()) {
            q = candidate;
            r = candidateResidual;
            damping = std::max(damping / 3.0, 1e-6);
        } else {
            damping *= 4.0;
            if (damping > 1e6)
                break;
        }
    }
    apply(q);
    return (fingerPad(pose, finger) - target).norm();
}

void movePadTo(HandPose& pose, Finger finger, const Eigen::Vector3d& target) {
    pose.wristToTable.translation() += target - fingerPad(pose, finger);
}

}  // namespace everytouch::sim
